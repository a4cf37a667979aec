// Base-colour textures of glTF objects: the encoded PNG/JPEG bytes kept by the importer, decoded
// (libpng, libjpeg-turbo) into RGBA8 with a full mip chain for VK_FORMAT_R8G8B8A8_SRGB.
//
// The importer already read each image's extent from its header and refused anything over
// kMaxGltfImageDimension; the decoder checks that the decoded extent is that one, so a file
// whose header lies cannot make it allocate more.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/gltf_import.h"
#include "siviflow/status.h"

namespace siviflow {

struct BaseColorTexture {
  uint32_t width = 0;  // of mip 0
  uint32_t height = 0;
  std::vector<uint8_t> texels;      // RGBA8 sRGB, every level back to back, each row-major
  std::vector<size_t> mip_offsets;  // byte offset of each level; level l is max(1, size >> l)
};

// Decodes `image` and builds its mip chain (2x2 box filter in linear light). `what` names the
// image in messages ("duck.glb: image 0"). `out` is left untouched on failure.
Status decode_base_color(const GltfImage& image, const std::string& what, BaseColorTexture* out);

// A 1x1 white texture, for primitives without a base-colour image.
BaseColorTexture white_base_color();

}  // namespace siviflow
