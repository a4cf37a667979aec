#include "siviflow/sim/spatial_grid.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

namespace siviflow {

void XzGrid::init(glm::dvec2 lo, glm::dvec2 hi, double cell_size, size_t max_cells) {
  lo_ = lo;
  const glm::dvec2 extent = glm::max(hi - lo, glm::dvec2(0.0));
  cell_ = cell_size > 0.0 && std::isfinite(cell_size) ? cell_size
                                                      : std::max({extent.x, extent.y, 1.0});
  max_cells = std::max<size_t>(max_cells, 1);
  for (;;) {
    const double nx = std::floor(extent.x / cell_) + 1.0;
    const double nz = std::floor(extent.y / cell_) + 1.0;
    if (nx * nz <= static_cast<double>(max_cells)) {
      nx_ = static_cast<int>(nx);
      nz_ = static_cast<int>(nz);
      break;
    }
    cell_ *= 1.5;
  }
  cell_start_.clear();
  items_.clear();
}

int XzGrid::cell_x(double x) const {
  const double c = std::floor((x - lo_.x) / cell_);
  return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(nx_ - 1)));
}

int XzGrid::cell_z(double z) const {
  const double c = std::floor((z - lo_.y) / cell_);
  return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(nz_ - 1)));
}

void XzGrid::insert_points(std::span<const glm::vec3> points) {
  const size_t cells = static_cast<size_t>(nx_) * nz_;
  cell_start_.assign(cells + 1, 0);
  std::vector<uint32_t> cell_of(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    cell_of[i] = static_cast<uint32_t>(cell_z(points[i].z) * nx_ + cell_x(points[i].x));
    ++cell_start_[cell_of[i] + 1];
  }
  for (size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  items_.resize(points.size());
  std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < points.size(); ++i) items_[fill[cell_of[i]]++] = static_cast<uint32_t>(i);
}

void XzGrid::insert_triangles(std::span<const glm::vec3> points,
                              std::span<const uint32_t> triangles) {
  const size_t count = triangles.size() / 3;
  auto bounds = [&](size_t t, int* x0, int* x1, int* z0, int* z1) {
    const glm::vec3& a = points[triangles[3 * t]];
    const glm::vec3& b = points[triangles[3 * t + 1]];
    const glm::vec3& c = points[triangles[3 * t + 2]];
    *x0 = cell_x(std::min({a.x, b.x, c.x}));
    *x1 = cell_x(std::max({a.x, b.x, c.x}));
    *z0 = cell_z(std::min({a.z, b.z, c.z}));
    *z1 = cell_z(std::max({a.z, b.z, c.z}));
  };
  // A few huge triangles over tiny cells would list each one in very many cells: coarsen the
  // grid until the listing stays linear in the triangle count.
  for (;;) {
    size_t total = 0;
    for (size_t t = 0; t < count; ++t) {
      int x0, x1, z0, z1;
      bounds(t, &x0, &x1, &z0, &z1);
      total += static_cast<size_t>(x1 - x0 + 1) * static_cast<size_t>(z1 - z0 + 1);
    }
    if (total <= 16 * count + 1024 || (nx_ == 1 && nz_ == 1)) break;
    cell_ *= 2.0;
    nx_ = std::max(1, (nx_ + 1) / 2);
    nz_ = std::max(1, (nz_ + 1) / 2);
  }
  const size_t cells = static_cast<size_t>(nx_) * nz_;
  cell_start_.assign(cells + 1, 0);
  for (size_t t = 0; t < count; ++t) {
    int x0, x1, z0, z1;
    bounds(t, &x0, &x1, &z0, &z1);
    for (int z = z0; z <= z1; ++z) {
      for (int x = x0; x <= x1; ++x) ++cell_start_[static_cast<size_t>(z) * nx_ + x + 1];
    }
  }
  for (size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  items_.resize(cell_start_[cells]);
  std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t t = 0; t < count; ++t) {
    int x0, x1, z0, z1;
    bounds(t, &x0, &x1, &z0, &z1);
    for (int z = z0; z <= z1; ++z) {
      for (int x = x0; x <= x1; ++x) {
        items_[fill[static_cast<size_t>(z) * nx_ + x]++] = static_cast<uint32_t>(t);
      }
    }
  }
}

}  // namespace siviflow
