// A tileable ground-detail texture made on the CPU (no asset to download): value noise at two
// scales, in the red and green channels, for breaking up the terrain's vertex colours.
#pragma once

#include <cstdint>
#include <vector>

namespace siviflow {

struct DetailTexture {
  uint32_t size = 0;             // width and height in texels
  std::vector<uint8_t> texels;  // RGBA8, row-major
};

DetailTexture make_detail_texture();

}  // namespace siviflow
