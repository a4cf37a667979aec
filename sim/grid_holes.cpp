#include "grid_holes.h"

#include <limits>

namespace siviflow {

size_t cut_grid_quads(uint32_t across, const std::function<bool(uint32_t, uint32_t)>& cut,
                      std::vector<glm::vec3>* positions, std::vector<uint32_t>* indices,
                      std::vector<float>* depth) {
  if (across < 2 || indices->size() % (6 * size_t{across - 1}) != 0) return 0;  // not a grid strip
  const size_t quads_across = across - 1;
  const size_t rows = indices->size() / 6 / quads_across;
  std::vector<uint8_t> gone(rows * quads_across, 0);
  for (uint32_t k = 0; k < rows; ++k) {
    for (uint32_t j = 0; j < quads_across; ++j) gone[k * quads_across + j] = cut(k, j) ? 1 : 0;
  }
  // Two cut quads meeting only at a corner would pinch the shore into a figure eight.
  const auto at = [&](size_t k, size_t j) { return gone[k * quads_across + j] != 0; };
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t k = 0; k + 1 < rows; ++k) {
      for (size_t j = 0; j + 1 < quads_across; ++j) {
        const bool main_diagonal = at(k, j) && at(k + 1, j + 1) && !at(k + 1, j) && !at(k, j + 1);
        const bool anti_diagonal = at(k, j + 1) && at(k + 1, j) && !at(k, j) && !at(k + 1, j + 1);
        if (main_diagonal || anti_diagonal) {
          gone[(k + 1) * quads_across + (main_diagonal ? j : j + 1)] = 1;
          changed = true;
        }
      }
    }
  }
  size_t cut_count = 0;
  std::vector<uint32_t> kept;
  kept.reserve(indices->size());
  for (size_t t = 0; t < indices->size() / 3; ++t) {
    if (gone[t / 2]) {
      cut_count += t % 2;
      continue;
    }
    kept.insert(kept.end(), indices->begin() + 3 * t, indices->begin() + 3 * t + 3);
  }
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> remap(positions->size(), kUnused);
  for (const uint32_t v : kept) remap[v] = 0;
  uint32_t next = 0;
  for (size_t v = 0; v < positions->size(); ++v) {
    if (remap[v] == kUnused) continue;
    remap[v] = next;
    (*positions)[next] = (*positions)[v];
    if (depth != nullptr && !depth->empty()) (*depth)[next] = (*depth)[v];
    ++next;
  }
  positions->resize(next);
  if (depth != nullptr && !depth->empty()) depth->resize(next);
  for (uint32_t& v : kept) v = remap[v];
  *indices = std::move(kept);
  return cut_count;
}

}  // namespace siviflow
