// The scene file: the JSON text checked field by field; relative paths are only joined to the
// temporary folder as text (the scene loader does not open the glTF files it names).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "siviflow/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string folder = std::filesystem::temp_directory_path().string();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  siviflow::SceneFile scene;
  (void)siviflow::parse_scene_file(text, "fuzz.json", folder, &scene);
  return 0;
}
