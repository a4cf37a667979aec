// What FoamField reads of a river surface per vertex besides the flow: the distance to the
// nearer bank along the section, and the section. Shared by the foam tests and benchmark.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "sim/foam.h"
#include "siviflow/sim/river_surface.h"

namespace siviflow::test {

struct FoamInputs {
  MarginDistances bank;
  std::vector<uint32_t> section;
};

inline FoamInputs foam_inputs(const RiverSurface& surface, size_t vertex_count) {
  FoamInputs in;
  in.bank = margin_distances(surface);
  for (size_t v = 0; v < vertex_count; ++v) {
    in.section.push_back(surface.vertex(v).section);
  }
  return in;
}

}  // namespace siviflow::test
