#include "scene/detail_texture.h"

#include <cmath>

namespace siviflow {
namespace {

constexpr uint32_t kSize = 256;

// Integer hash of a lattice point, wrapped by `period` so that the noise tiles.
float lattice(int x, int y, int period, uint32_t salt) {
  uint32_t h = static_cast<uint32_t>((x % period + period) % period) * 73856093u ^
               static_cast<uint32_t>((y % period + period) % period) * 19349663u ^ salt * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<float>(h & 0xffffu) / 65535.0f;
}

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

// Fractal value noise in [0,1] over a torus of kSize texels.
float fractal_noise(float u, float v, int base_period, uint32_t salt) {
  float sum = 0.0f;
  float amplitude = 0.5f;
  float total = 0.0f;
  for (int octave = 0, period = base_period; octave < 4; ++octave, period *= 2) {
    const float x = u * static_cast<float>(period);
    const float y = v * static_cast<float>(period);
    const int x0 = static_cast<int>(std::floor(x));
    const int y0 = static_cast<int>(std::floor(y));
    const float fx = smooth(x - static_cast<float>(x0));
    const float fy = smooth(y - static_cast<float>(y0));
    const float a = lattice(x0, y0, period, salt + octave);
    const float b = lattice(x0 + 1, y0, period, salt + octave);
    const float c = lattice(x0, y0 + 1, period, salt + octave);
    const float d = lattice(x0 + 1, y0 + 1, period, salt + octave);
    sum += amplitude * ((a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy);
    total += amplitude;
    amplitude *= 0.5f;
  }
  return sum / total;
}

}  // namespace

DetailTexture make_detail_texture() {
  DetailTexture texture;
  texture.size = kSize;
  texture.texels.resize(size_t{kSize} * kSize * 4);
  for (uint32_t y = 0; y < kSize; ++y) {
    for (uint32_t x = 0; x < kSize; ++x) {
      const float u = static_cast<float>(x) / kSize;
      const float v = static_cast<float>(y) / kSize;
      uint8_t* texel = &texture.texels[(size_t{y} * kSize + x) * 4];
      texel[0] = static_cast<uint8_t>(255.0f * fractal_noise(u, v, 8, 1));  // fine grain
      texel[1] = static_cast<uint8_t>(255.0f * fractal_noise(u, v, 4, 7));  // broad patches
      texel[2] = 0;
      texel[3] = 255;
    }
  }
  return texture;
}

}  // namespace siviflow
