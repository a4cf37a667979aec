// What FoamField reads of a river surface per vertex besides the flow: the distance to the
// nearer bank along the section, and the section. Shared by the foam tests and benchmark.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "siviflow/sim/river_surface.h"

namespace siviflow::test {

struct FoamInputs {
  std::vector<float> bank;
  std::vector<uint32_t> section;
};

inline FoamInputs foam_inputs(const RiverSurface& surface, size_t vertex_count) {
  FoamInputs in;
  for (size_t v = 0; v < vertex_count; ++v) {
    const RiverVertex vertex = surface.vertex(v);
    in.bank.push_back(std::min(vertex.d_left, vertex.d_right));
    in.section.push_back(vertex.section);
  }
  return in;
}

}  // namespace siviflow::test
