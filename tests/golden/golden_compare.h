// Compares a rendered EXR with a golden one within a tolerance, as llvmpipe output is not
// bit-identical across CPUs: per channel |a - b| <= abs_tol + rel_tol * |golden| (equal
// infinities, the sky's depth, agree), and a small fraction of pixels may fail (geometry edges).
// The beauty's R, G, B and A are compared, and the depth and water mask where the golden has
// them. On failure a diff image (R, G, B) is written beside.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "siviflow/image_files.h"

namespace siviflow::testing {

struct GoldenTolerance {
  float abs_tol = 0.02f;
  float rel_tol = 0.02f;
  double max_failing_fraction = 0.005;
  bool beauty_only = false;  // R, G, B and A alone: a frame rendered without the AOVs
};

struct GoldenResult {
  bool pass = false;
  std::string message;
  double failing_fraction = 0.0;
  float max_diff = 0.0f;
};

inline GoldenResult compare_with_golden(const std::string& rendered, const std::string& golden,
                                        const std::string& diff_png, const GoldenTolerance& tol) {
  GoldenResult result;
  ExrImage a;
  ExrImage b;
  Status status = read_exr(rendered, &a);
  if (status.ok()) status = read_exr(golden, &b);
  if (!status.ok()) {
    result.message = status.message();
    return result;
  }
  if (a.width != b.width || a.height != b.height) {
    result.message = "size differs from the golden";
    return result;
  }
  std::vector<std::string> names = {"R", "G", "B", "A"};
  for (const char* layer : {"depth.Z", "water.A"}) {
    if (!tol.beauty_only && b.find(layer) != nullptr) names.push_back(layer);
  }
  std::vector<const std::vector<float>*> channels[2];
  for (const std::string& name : names) {
    channels[0].push_back(a.find(name));
    channels[1].push_back(b.find(name));
    if (channels[0].back() == nullptr || channels[1].back() == nullptr) {
      result.message = "an image lacks the channel " + name;
      return result;
    }
  }
  const size_t pixels = size_t(a.width) * a.height;
  std::vector<float> diff(pixels * 4, 1.0f);
  size_t failing = 0;
  for (size_t i = 0; i < pixels; ++i) {
    bool bad = false;
    for (size_t c = 0; c < names.size(); ++c) {
      const float va = (*channels[0][c])[i];
      const float vb = (*channels[1][c])[i];
      const float d = va == vb ? 0.0f : std::abs(va - vb);
      result.max_diff = std::max(result.max_diff, d);
      bad = bad || !(d <= tol.abs_tol + tol.rel_tol * std::abs(vb));  // NaN fails too
      if (c < 3) diff[i * 4 + c] = std::min(1.0f, d * 10.0f);
    }
    failing += bad ? 1 : 0;
  }
  result.failing_fraction = static_cast<double>(failing) / static_cast<double>(pixels);
  result.pass = result.failing_fraction <= tol.max_failing_fraction;
  result.message = std::to_string(failing) + " of " + std::to_string(pixels) +
                   " pixels outside the tolerance, max difference " + std::to_string(result.max_diff);
  if (!result.pass) {
    const Status written = write_png(diff_png, a.width, a.height, diff.data(), PngChannels::kRgb);
    result.message += written.ok() ? ", diff image: " + diff_png : ", diff image not written: " + written.message();
  }
  return result;
}

}  // namespace siviflow::testing
