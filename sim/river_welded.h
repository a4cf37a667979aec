// The welded river mesh as RiverSurface::build has checked it (one piece, manifold, a disc with
// holes), handed to the part of the build that finds its sections.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "siviflow/sim/river_surface.h"
#include "strip_layering.h"

namespace siviflow {

struct RiverSurface::Welded {
  std::vector<glm::vec3>& pos;
  std::vector<uint32_t>& tris;
  TrianglesAround& node_tris;
  Csr& adj;
  std::vector<uint32_t>& node_vertex;
  std::vector<uint32_t>& node_of_vertex;
  std::vector<std::vector<uint32_t>>& island_loops;
  std::vector<uint32_t>& node_island;
  const std::vector<uint32_t>& loop;  // the outer border
  const std::vector<double>& angles;  // the water's angle at each node of `loop`, in its order
  size_t vertex_count;
};

}  // namespace siviflow
