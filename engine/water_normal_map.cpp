#include "water_normal_map.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>

namespace siviflow {
namespace {

// ---- Tunables of the ripple spectrum (all lengths in cycles per map, i.e. per tile repeat) ----
constexpr uint32_t kSize = 256;            // mip 0 texels per side (power of two)
constexpr int kWaveCount = 64;             // sinusoids summed; enough for a noise-like look
constexpr double kMinCycles = 3.0;         // longest ripple: a third of the map
constexpr double kMaxCycles = 28.0;        // shortest ripple: about 9 texels, no aliasing
constexpr double kSpectrumPower = 1.25;    // height amplitude ~ |k|^-p (slopes ~ |k|^(1-p))
constexpr double kDirectionSpread = 1.3;   // radians either side of +U: crests lie across the flow
constexpr double kRmsSlope = 0.55;         // RMS of |gradient| before normalising to unit normals
constexpr uint32_t kSeed = 0x5171f10u;     // fixed: the map is the same on every run

// A small counter-based hash (a variant of the "lowbias32" integer mix) -> [0, 1).
double hash01(uint32_t counter) {
  uint32_t h = counter * 0x9e3779b9u + kSeed;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return static_cast<double>(h) / 4294967296.0;
}

struct Wave {
  int kx = 0;  // integer cycles per map along U and V: the sum wraps exactly at the edges
  int ky = 0;
  double amplitude = 0.0;
  double phase = 0.0;
};

std::array<Wave, kWaveCount> make_waves() {
  std::array<Wave, kWaveCount> waves{};
  uint32_t counter = 0;
  for (int i = 0; i < kWaveCount;) {
    const double cycles = kMinCycles * std::pow(kMaxCycles / kMinCycles, hash01(counter++));
    const double angle = (2.0 * hash01(counter++) - 1.0) * kDirectionSpread;
    const double jitter = 0.5 + hash01(counter++);
    const double phase = 2.0 * std::numbers::pi * hash01(counter++);
    Wave w;
    w.kx = static_cast<int>(std::lround(cycles * std::cos(angle)));
    w.ky = static_cast<int>(std::lround(cycles * std::sin(angle)));
    // Rounding can give the zero vector or a repeat; a repeated (or opposite) wave vector would
    // just beat with its twin, so draw again.
    const bool taken = std::any_of(waves.begin(), waves.begin() + i, [&](const Wave& o) {
      return (o.kx == w.kx && o.ky == w.ky) || (o.kx == -w.kx && o.ky == -w.ky);
    });
    if ((w.kx == 0 && w.ky == 0) || taken) continue;
    w.amplitude = jitter * std::pow(std::hypot(w.kx, w.ky), -kSpectrumPower);
    w.phase = phase;
    waves[static_cast<size_t>(i++)] = w;
  }
  return waves;
}

// One mip level in floats: unit normal xyz and height per texel, row-major.
struct Level {
  uint32_t size = 0;
  std::vector<std::array<float, 4>> texels;
};

Level make_base_level() {
  const std::array<Wave, kWaveCount> waves = make_waves();
  Level level;
  level.size = kSize;
  level.texels.resize(size_t{kSize} * kSize);
  std::vector<std::array<double, 3>> field(level.texels.size());  // height, dh/du, dh/dv
  double slope_sq = 0.0;
  double max_height = 0.0;
  const double two_pi = 2.0 * std::numbers::pi;
  for (uint32_t y = 0; y < kSize; ++y) {
    for (uint32_t x = 0; x < kSize; ++x) {
      // Texel centres, as the GPU samples them.
      const double u = (x + 0.5) / kSize;
      const double v = (y + 0.5) / kSize;
      std::array<double, 3>& f = field[size_t{y} * kSize + x];
      f = {0.0, 0.0, 0.0};
      for (const Wave& w : waves) {
        const double arg = two_pi * (w.kx * u + w.ky * v) + w.phase;
        const double c = w.amplitude * std::cos(arg);
        f[0] += w.amplitude * std::sin(arg);
        f[1] += two_pi * w.kx * c;  // analytic gradient: no finite-difference seam at the edge
        f[2] += two_pi * w.ky * c;
      }
      slope_sq += f[1] * f[1] + f[2] * f[2];
      max_height = std::max(max_height, std::abs(f[0]));
    }
  }
  const double slope_scale = kRmsSlope / std::sqrt(slope_sq / static_cast<double>(field.size()));
  for (size_t i = 0; i < field.size(); ++i) {
    const double nx = -field[i][1] * slope_scale;
    const double ny = -field[i][2] * slope_scale;
    const double inv = 1.0 / std::sqrt(nx * nx + ny * ny + 1.0);
    level.texels[i] = {static_cast<float>(nx * inv), static_cast<float>(ny * inv),
                       static_cast<float>(inv),
                       static_cast<float>(0.5 + 0.5 * field[i][0] / max_height)};
  }
  return level;
}

// Next mip: average of each 2x2 block, normals renormalised (sizes are powers of two, so the
// blocks never straddle the wrap and the level stays tileable).
Level downsample(const Level& fine) {
  Level coarse;
  coarse.size = fine.size / 2;
  coarse.texels.resize(size_t{coarse.size} * coarse.size);
  for (uint32_t y = 0; y < coarse.size; ++y) {
    for (uint32_t x = 0; x < coarse.size; ++x) {
      std::array<float, 4> sum{};
      for (uint32_t dy = 0; dy < 2; ++dy) {
        for (uint32_t dx = 0; dx < 2; ++dx) {
          const auto& t = fine.texels[size_t{2 * y + dy} * fine.size + (2 * x + dx)];
          for (size_t c = 0; c < 4; ++c) sum[c] += t[c];
        }
      }
      const float length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
      auto& out = coarse.texels[size_t{y} * coarse.size + x];
      if (length > 1e-6f) {
        out = {sum[0] / length, sum[1] / length, sum[2] / length, sum[3] * 0.25f};
      } else {
        out = {0.0f, 0.0f, 1.0f, sum[3] * 0.25f};  // cancelling normals: flat is the best guess
      }
    }
  }
  return coarse;
}

uint8_t encode_signed(float value) {
  return static_cast<uint8_t>(std::clamp(std::lround(127.5 + 127.5 * value), 0l, 255l));
}

uint8_t encode_unsigned(float value) {
  return static_cast<uint8_t>(std::clamp(std::lround(255.0 * value), 0l, 255l));
}

}  // namespace

WaterNormalMap make_water_normal_map() {
  WaterNormalMap map;
  map.size = kSize;
  map.mip_levels = static_cast<uint32_t>(std::bit_width(kSize));
  size_t total = 0;
  for (uint32_t level = 0; level < map.mip_levels; ++level) {
    map.mip_offsets.push_back(total);
    total += map.mip_bytes(level);
  }
  map.texels.resize(total);
  Level level = make_base_level();
  for (uint32_t i = 0; i < map.mip_levels; ++i) {
    if (i > 0) level = downsample(level);
    uint8_t* out = map.texels.data() + map.mip_offsets[i];
    for (const auto& t : level.texels) {
      *out++ = encode_signed(t[0]);
      *out++ = encode_signed(t[1]);
      *out++ = encode_signed(t[2]);
      *out++ = encode_unsigned(t[3]);
    }
  }
  return map;
}

}  // namespace siviflow
