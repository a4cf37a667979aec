// glTF import: the bytes as a .gltf (JSON) or, when they start with the GLB magic, a .glb; the
// object loader, the river-mesh loader, and the base-colour decoders for every image it keeps.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input_file.h"
#include "scene/base_color_texture.h"
#include "scene/gltf_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static siviflow::fuzzing::FuzzInputFile input("input.gltf");
  const std::string& path = input.write(data, size);

  siviflow::GltfObject object;
  if (siviflow::load_gltf_object(path, &object).ok()) {
    for (const siviflow::GltfImage& image : object.images) {
      siviflow::BaseColorTexture texture;
      (void)siviflow::decode_base_color(image, "image", &texture);
    }
  }
  siviflow::TriangleMesh mesh;
  (void)siviflow::load_river_mesh(path, "", &mesh);
  return 0;
}
