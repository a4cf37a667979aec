// The EXR reader: the header checks, then every channel of the file read back as floats.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.h"
#include "siviflow/image_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static siviflow::fuzzing::FuzzInputFile input("input.exr");
  const std::string& path = input.write(data, size);
  siviflow::ExrImage image;
  (void)siviflow::read_exr(path, &image);
  return 0;
}
