// A walk over an EXR file's headers as OpenEXR's reader takes them, before OpenEXR opens the file.
#pragma once

#include <cstdint>
#include <string>

#include "siviflow/status.h"

namespace siviflow {

// OpenEXR sizes some attribute values from the file before reading them (an unknown type's from
// its size field, a preview's from its width and height, each string of a string vector from its
// own length), so a few bytes that claim 2 GiB make it allocate and clear 2 GiB. Walks every
// header of the file (`file_bytes` long) taking each value's bytes as OpenEXR does, and refuses a
// value that runs past the end of the file. `what` begins every message.
Status check_exr_headers(const std::string& path, const std::string& what, int64_t file_bytes);

}  // namespace siviflow
