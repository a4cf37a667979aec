// The EXR reader: every channel of the file read back as floats; then, for a file it accepted,
// OpenEXR's own deep check as the tests run it on captured frames.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.h"
#include "siviflow/image_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static siviflow::fuzzing::FuzzInputFile input("input.exr");
  const std::string& path = input.write(data, size);
  siviflow::ExrImage image;
  if (siviflow::read_exr(path, &image).ok()) (void)siviflow::check_exr_file(path);
  return 0;
}
