// A run of an index buffer drawn in one call: a water chunk, a world piece's level.
#pragma once

#include <cstdint>

namespace siviflow {

struct IndexRange {
  uint32_t first_index = 0;
  uint32_t index_count = 0;

  bool operator==(const IndexRange&) const = default;
};

}  // namespace siviflow
