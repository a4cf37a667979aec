// Base-colour textures: the PNG/JPEG extent read from the header as the glTF importer does, then
// the decode (libpng, libjpeg-turbo) and the mip chain, as a base-colour image of a glTF object.
#include <cstddef>
#include <cstdint>
#include <span>

#include "scene/base_color_texture.h"
#include "scene/gltf_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  siviflow::GltfImage image;
  image.encoded.assign(data, data + size);
  if (!siviflow::read_image_extent(std::span<const uint8_t>(data, size), "image", &image.width,
                                   &image.height)
           .ok()) {
    return 0;
  }
  image.mime_type = size > 0 && data[0] == 0x89 ? "image/png" : "image/jpeg";
  siviflow::BaseColorTexture texture;
  (void)siviflow::decode_base_color(image, "image", &texture);
  return 0;
}
