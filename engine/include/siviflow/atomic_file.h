// Whole-file atomic replacement, shared by every file SiViFlow writes (EXR, PNG, CSV).
#pragma once

#include <cstddef>
#include <string>

#include "siviflow/status.h"

namespace siviflow {

// Writes `size` bytes to a new temporary file in the folder of `path` (O_CREAT|O_EXCL), checks
// every write, fsyncs, closes, renames it over `path` and fsyncs the folder. On failure the
// temporary is removed and `path` is left as it was. An existing `path` that is not a regular
// file (directory, FIFO, device, symlink) is refused without being touched.
Status write_file_atomically(const std::string& path, const void* data, size_t size);

// The checks write_file_atomically starts with (folder exists, target absent or a regular
// file), so that callers can fail before encoding.
Status check_output_path(const std::string& path);

// strerror text of `error_number`, thread-safe.
std::string errno_message(int error_number);

}  // namespace siviflow
