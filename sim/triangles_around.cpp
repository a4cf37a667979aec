#include "siviflow/sim/triangles_around.h"

#include <algorithm>
#include <limits>

namespace siviflow {

TrianglesAround TrianglesAround::of_mesh(size_t vertex_count, std::span<const uint32_t> indices) {
  const size_t corners = indices.empty() ? vertex_count : indices.size();
  const auto corner = [&](size_t i) { return indices.empty() ? uint32_t(i) : indices[i]; };
  TrianglesAround around;
  around.vertex_count_ = vertex_count;
  around.triangle_count_ = corners / 3;
  // Counted, then filled in triangle order: each vertex's come out ascending. Straight into
  // 2 bytes a triangle, without a list of 4 beside it, until one does not fit.
  std::vector<uint32_t> start(vertex_count + 1, 0);
  for (size_t i = 0; i < corners; ++i) ++start[corner(i) + 1];
  for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  around.offsets_.resize(corners);
  for (size_t i = 0; i < corners; ++i) {
    const uint32_t v = corner(i);
    const int64_t offset = static_cast<int64_t>(i / 3) - around.anchor(v);
    if (offset < std::numeric_limits<int16_t>::min() ||
        offset > std::numeric_limits<int16_t>::max()) {
      around.offsets_ = std::vector<int16_t>();  // frees it, as clear() would not
      break;
    }
    around.offsets_[fill[v]++] = static_cast<int16_t>(offset);
  }
  if (around.offsets_.empty() && corners > 0) {
    std::copy(start.begin(), start.end() - 1, fill.begin());
    around.triangles_.resize(corners);
    for (size_t i = 0; i < corners; ++i) {
      around.triangles_[fill[corner(i)]++] = static_cast<uint32_t>(i / 3);
    }
  }
  fill = std::vector<uint32_t>();
  around.compact_starts(&start);
  return around;
}

void TrianglesAround::compact_starts(std::vector<uint32_t>* starts) {
  const std::vector<uint32_t>& s = *starts;
  block_start_.resize((vertex_count_ >> kBlockShift) + 1);
  start_in_block_.resize(s.size());
  for (size_t v = 0; v < s.size(); ++v) {
    const uint32_t block_start = s[(v >> kBlockShift) << kBlockShift];
    if (s[v] - block_start > std::numeric_limits<uint16_t>::max()) {
      block_start_ = std::vector<uint32_t>();
      start_in_block_ = std::vector<uint16_t>();
      start_ = std::move(*starts);
      return;
    }
    block_start_[v >> kBlockShift] = block_start;
    start_in_block_[v] = static_cast<uint16_t>(s[v] - block_start);
  }
  *starts = std::vector<uint32_t>();
}

size_t TrianglesAround::memory_bytes() const {
  return block_start_.capacity() * sizeof(uint32_t) +
         start_in_block_.capacity() * sizeof(uint16_t) + start_.capacity() * sizeof(uint32_t) +
         offsets_.capacity() * sizeof(int16_t) + triangles_.capacity() * sizeof(uint32_t);
}

}  // namespace siviflow
