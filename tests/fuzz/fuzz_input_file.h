// The glTF importer and the EXR reader take a path, as a host's files come: a fuzz input is
// written to one file in a folder of its own, so the real reading path (regular-file checks,
// size caps, the folder that external references are confined to) is what gets fuzzed.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace siviflow::fuzzing {

class FuzzInputFile {
 public:
  explicit FuzzInputFile(const std::string& name) {
    std::string folder = (std::filesystem::temp_directory_path() / "siviflow_fuzz_XXXXXX").string();
    if (::mkdtemp(folder.data()) == nullptr) std::abort();  // no folder: nothing can be fuzzed
    folder_ = folder;
    path_ = (folder_ / name).string();
  }
  ~FuzzInputFile() {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }
  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;

  // Replaces the file's contents with the input; returns its path.
  const std::string& write(const uint8_t* data, size_t size) {
    std::FILE* file = std::fopen(path_.c_str(), "wb");
    if (file == nullptr) std::abort();
    if (size > 0 && std::fwrite(data, 1, size, file) != size) std::abort();
    std::fclose(file);
    return path_;
  }

 private:
  std::filesystem::path folder_;
  std::string path_;
};

}  // namespace siviflow::fuzzing
