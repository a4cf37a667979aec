// A tileable, mipmapped water normal map made on the CPU (no asset to download): small ripples
// for Tiled Directional Flow (shaders/tiled_directional_flow.glsl, algorithms.md §2.1).
//
// Format: VK_FORMAT_R8G8B8A8_UNORM, tangent space, +Z out of the surface, texture +U (columns)
// along the tile's flow direction once TDF rotates it:
//   R, G  normal x, y encoded as 0.5 + 0.5 n (the only channels TDF reads, as in van Hoesel's)
//   B     normal z encoded the same way (for inspection; z = sqrt(1 - x^2 - y^2) anyway)
//   A     ripple height, 0..1 (mean 0.5), averaged down the mips; free for foam or glints
// Why RGBA8 UNORM: 8 bits resolve a slope of 1/127, below what the 0.3-scaled normal can show;
// 4-byte texels go through the renderer's existing RGBA8 upload path, and the fourth channel
// costs nothing on lavapipe (RG8 would halve bandwidth but not the number of texture reads).
// RGBA16F would double the bytes for precision nobody can see.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace siviflow {

struct WaterNormalMap {
  uint32_t size = 0;                // width and height of mip 0 in texels (a power of two)
  uint32_t mip_levels = 0;          // size, size/2, ..., 1
  std::vector<uint8_t> texels;      // RGBA8, every mip level back to back, each row-major
  std::vector<size_t> mip_offsets;  // byte offset of each level in `texels`

  // Width and height of mip `level`, and its byte size.
  uint32_t mip_size(uint32_t level) const { return size >> level; }
  size_t mip_bytes(uint32_t level) const {
    return size_t{mip_size(level)} * mip_size(level) * 4;
  }
};

// Deterministic: fixed seed and an own hash (no std:: distributions), so the same bytes on
// every call; only libm's sin/cos could move a texel by one code on another platform.
WaterNormalMap make_water_normal_map();

}  // namespace siviflow
