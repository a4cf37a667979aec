// Point queries of the water (siviflow/sim/water_sample.h): which river triangle lies under a
// point in the XZ plane, found through a sparse grid of cells (only the cells the river covers,
// sorted, so a point costs one binary search whatever the river's shape and length), and the
// surface, flow, depth and foam there, interpolated from the triangle's vertices.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "particles.h"
#include "siviflow/sim/water_sample.h"
#include "siviflow/status.h"

namespace siviflow {

class WaterQuery {
 public:
  // Indexes the surface of `field` (positions and indices; its flow, depth and foam are read at
  // every query, so a re-solved flow is seen at once). `field`'s spans must outlive the query.
  static Status build(const RiverFlowField& field, WaterQuery* out);

  // The sample at `point`: `obstacle` is the index into `footprints` of the footprint holding the
  // point plus one, 0 outside every one (the caller maps it to its own ids). Deterministic: a
  // point on an edge takes the lowest-numbered triangle it touches.
  WaterSample sample(const glm::vec3& point, std::span<const DryFootprint> footprints) const;

  // Bytes held by the index (not the referenced field).
  size_t memory_bytes() const;

 private:
  // The triangle whose XZ projection holds (x, z), or UINT32_MAX; its barycentric weights.
  uint32_t locate(double x, double z, glm::dvec3* weights) const;
  uint32_t vertex(uint32_t triangle, int corner) const;
  int64_t cell_key(double x, double z) const;

  RiverFlowField field_;
  double cell_size_ = 1.0;
  std::vector<int64_t> keys_;     // the cells the river covers, ascending
  std::vector<uint32_t> starts_;  // keys_.size() + 1 offsets into triangles_
  std::vector<uint32_t> triangles_;  // per cell, ascending
};

}  // namespace siviflow
