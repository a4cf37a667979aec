// A solved river flow on a test mesh (river_test_meshes.h), and a single-point query of it: the
// water the query and drift tests ask.
#pragma once

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "river_simulation.h"
#include "sim/half_float.h"
#include "unit/river_test_meshes.h"

namespace siviflow::test {

// A RiverFlow on a test mesh, `depth` metres deep everywhere.
inline std::unique_ptr<RiverFlow> river_flow(const TestMesh& m, const FlowParams& params,
                                             std::vector<Obstacle> obstacles = {},
                                             float depth = 1.0f) {
  RiverInput input;
  input.mesh.positions = m.positions;
  input.mesh.indices = m.indices;
  input.depth.assign(m.positions.size(), to_half(depth));
  EXPECT_TRUE(RiverSurface::build(m.positions, m.indices, {}, &input.surface).ok());
  auto flow = std::make_unique<RiverFlow>();
  const Status created = flow->create(std::move(input), params, std::move(obstacles));
  EXPECT_TRUE(created.ok()) << created.message();
  return flow;
}

inline WaterSample query(const RiverFlow& flow, glm::vec3 point) {
  WaterSample s;
  flow.query(std::span<const glm::vec3>(&point, 1), std::span<WaterSample>(&s, 1));
  return s;
}

}  // namespace siviflow::test
