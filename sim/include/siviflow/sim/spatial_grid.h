// A uniform grid over the XZ plane whose cells list items (points or triangles) in CSR form,
// for the obstacle queries of the stream function: no query scans the whole river.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace siviflow {

class XzGrid {
 public:
  // Cells of `cell_size` metres over [lo, hi]; at most `max_cells` cells (the size grows).
  void init(glm::dvec2 lo, glm::dvec2 hi, double cell_size, size_t max_cells);
  // Each point goes into the cell holding it.
  void insert_points(std::span<const glm::vec3> points);
  // Each triangle (3 indices into `points`) goes into every cell its XZ bounds overlap.
  void insert_triangles(std::span<const glm::vec3> points, std::span<const uint32_t> triangles);

  bool empty() const { return cell_start_.empty(); }
  double cell_size() const { return cell_; }
  size_t memory_bytes() const {
    return (cell_start_.capacity() + items_.capacity()) * sizeof(uint32_t);
  }

  // Calls f(item) for every item of every cell overlapping [lo, hi]; a triangle spanning several
  // cells is reported once per cell. Items of one cell come in ascending order.
  template <class F>
  void for_each_in(glm::dvec2 lo, glm::dvec2 hi, F&& f) const {
    if (cell_start_.empty()) return;
    const int x0 = cell_x(lo.x), x1 = cell_x(hi.x);
    const int z0 = cell_z(lo.y), z1 = cell_z(hi.y);
    for (int z = z0; z <= z1; ++z) {
      for (int x = x0; x <= x1; ++x) {
        const size_t c = static_cast<size_t>(z) * nx_ + x;
        for (uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) f(items_[i]);
      }
    }
  }

 private:
  int cell_x(double x) const;
  int cell_z(double z) const;

  glm::dvec2 lo_{0.0};
  double cell_ = 1.0;
  int nx_ = 0;
  int nz_ = 0;
  std::vector<uint32_t> cell_start_;
  std::vector<uint32_t> items_;
};

}  // namespace siviflow
