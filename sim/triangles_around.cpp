#include "siviflow/sim/triangles_around.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace siviflow {

TrianglesAround TrianglesAround::of_mesh(size_t vertex_count, std::span<const uint32_t> indices) {
  const size_t corners = indices.empty() ? vertex_count : indices.size();
  const auto corner = [&](size_t i) { return indices.empty() ? uint32_t(i) : indices[i]; };
  TrianglesAround around;
  around.vertex_count_ = vertex_count;
  around.triangle_count_ = corners / 3;
  // Counted, then filled in triangle order: each vertex's come out ascending, in the narrowest
  // width that holds every offset (found first, so no wider list is held beside it).
  std::vector<uint32_t> start(vertex_count + 1, 0);
  int64_t lowest = 0, highest = 0;
  for (size_t i = 0; i < corners; ++i) {
    ++start[corner(i) + 1];
    const int64_t offset = static_cast<int64_t>(i / 3) - around.anchor(corner(i));
    lowest = std::min(lowest, offset);
    highest = std::max(highest, offset);
  }
  for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  const auto fill_lists = [&](auto* lists, auto entry_of) {
    lists->resize(corners);
    for (size_t i = 0; i < corners; ++i) {
      const uint32_t v = corner(i);
      (*lists)[fill[v]++] = entry_of(i, v);
    }
  };
  // Into `lists` when every offset fits their entries' type; false, untouched, when one does not.
  const auto fill_offsets_if_they_fit = [&](auto* lists) {
    using Offset = typename std::remove_pointer_t<decltype(lists)>::value_type;
    if (lowest < std::numeric_limits<Offset>::min() ||
        highest > std::numeric_limits<Offset>::max()) {
      return false;
    }
    fill_lists(lists, [&](size_t i, uint32_t v) {
      return static_cast<Offset>(static_cast<int64_t>(i / 3) - around.anchor(v));
    });
    return true;
  };
  if (!fill_offsets_if_they_fit(&around.offsets8_) &&
      !fill_offsets_if_they_fit(&around.offsets16_)) {
    fill_lists(&around.triangles_, [](size_t i, uint32_t) { return static_cast<uint32_t>(i / 3); });
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
         offsets8_.capacity() * sizeof(int8_t) + offsets16_.capacity() * sizeof(int16_t) +
         triangles_.capacity() * sizeof(uint32_t);
}

}  // namespace siviflow
