// Point queries of the water (siviflow/sim/water_sample.h): the river triangle under a point in
// the XZ plane, found through the surface's bounding volume hierarchy (O(log n), nothing built
// for it), and the surface, flow, depth and foam there, interpolated from its vertices.
#pragma once

#include <span>

#include <glm/vec3.hpp>

#include "sim/particles.h"
#include "sim/triangle_bvh.h"
#include "siviflow/sim/water_sample.h"

namespace siviflow {

class WaterQuery {
 public:
  WaterQuery() = default;
  // `field` and `bvh` (the hierarchy of field's positions and indices) outlive the query; the
  // field's flow, depth and foam are read at every query, so a re-solved flow is seen at once.
  WaterQuery(const RiverFlowField& field, const TriangleBvh* bvh) : field_(field), bvh_(bvh) {}

  // The sample at `point`: `obstacle` is the index into `footprints` of the footprint holding the
  // point plus one, 0 outside every one (the caller maps it to its own ids). Deterministic.
  WaterSample sample(const glm::vec3& point, std::span<const DryFootprint> footprints) const;

 private:
  RiverFlowField field_;
  const TriangleBvh* bvh_ = nullptr;
};

}  // namespace siviflow
