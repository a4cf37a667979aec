// An oracle for a Y of two arms joining into one channel (tests/unit/river_network_meshes.h's
// y_channel), independent of the simulation: psi from a finite-difference solution of Laplace's
// equation on a fine grid, psi fixed on the banks and on the tongue between the arms, uniform
// flow (psi linear across) at the three ends.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/vec3.hpp>
#include <utility>
#include <vector>

namespace siviflow::test {

struct YShape {
  double arm_width = 4.0;  // each arm; the main channel is twice as wide
  double main_length = 24.0;
  double left_length = 16.0;  // the arm on +X
  double right_length = 10.0;
  double spread = 0.25;  // the tongue's half-width grows this much per metre upstream
};

class YLaplaceOracle {
 public:
  // psi_left on the +X bank, psi_tongue on the tongue, 0 on the -X bank.
  YLaplaceOracle(const YShape& y, double psi_left, double psi_tongue, double h)
      : y_(y), psi_left_(psi_left), psi_tongue_(psi_tongue), h_(h) {
    const double reach = std::max(y.left_length, y.right_length);
    x0_ = -(y.arm_width + reach * y.spread) - 2 * h;
    z0_ = -reach - 2 * h;
    nx_ = int(std::ceil(-2 * x0_ / h)) + 1;
    nz_ = int(std::ceil((y.main_length - z0_) / h)) + 3;
    psi_.assign(size_t(nx_) * nz_, 0.0);
    inside_.assign(psi_.size(), 0);
    for (int i = 0; i < nx_; ++i) {
      for (int k = 0; k < nz_; ++k) {
        inside_[index(i, k)] = water(x_of(i), z_of(k));
        psi_[index(i, k)] = boundary(x_of(i), z_of(k));
      }
    }
    solve();
  }

  // The x at which psi first crosses `value` along the row nearest z, from +X towards -X.
  double crossing(double z, double value) const {
    const int k = int(std::lround((z - z0_) / h_));
    for (int i = nx_ - 1; i > 0; --i) {
      const double a = at(i, k), b = at(i - 1, k);
      if (!inside_[index(i, k)] || !inside_[index(i - 1, k)]) continue;
      if ((a - value) * (b - value) <= 0.0 && a != b) {
        return x_of(i) + (x_of(i - 1) - x_of(i)) * (a - value) / (a - b);
      }
    }
    return NAN;
  }

  // Velocity grad(psi) x +Y = (-dpsi/dz, 0, dpsi/dx), by central differences of the bilinear psi.
  glm::dvec3 velocity(double x, double z) const {
    return {-(psi(x, z + h_) - psi(x, z - h_)) / (2 * h_), 0.0,
            (psi(x + h_, z) - psi(x - h_, z)) / (2 * h_)};
  }

  // Whether (x, z) lies in the water at least `margin` from every border and end.
  bool inside(double x, double z, double margin) const {
    for (const double dx : {-margin, 0.0, margin}) {
      for (const double dz : {-margin, 0.0, margin}) {
        if (!water(x + dx, z + dz)) return false;
      }
    }
    return true;
  }

  double psi(double x, double z) const {
    const double fi = (x - x0_) / h_, fk = (z - z0_) / h_;
    const int i = std::clamp(int(std::floor(fi)), 0, nx_ - 2);
    const int k = std::clamp(int(std::floor(fk)), 0, nz_ - 2);
    const double u = fi - i, v = fk - k;
    return (1 - u) * (1 - v) * at(i, k) + u * (1 - v) * at(i + 1, k) + (1 - u) * v * at(i, k + 1) +
           u * v * at(i + 1, k + 1);
  }

 private:
  double x_of(int i) const { return x0_ + i * h_; }
  double z_of(int k) const { return z0_ + k * h_; }
  size_t index(int i, int k) const { return size_t(k) * nx_ + i; }
  double at(int i, int k) const { return psi_[index(i, k)]; }

  bool water(double x, double z) const {
    const double w = y_.arm_width;
    if (z >= 0.0) return z <= y_.main_length && std::abs(x) <= w;
    const double d = -z, off = d * y_.spread;
    if (x >= 0.0) return d <= y_.left_length && x >= off && x <= w + off;
    return d <= y_.right_length && x <= -off && x >= -w - off;
  }

  // psi outside the water (and its first guess inside): the border beside, or across an end the
  // uniform profile.
  double boundary(double x, double z) const {
    const double w = y_.arm_width;
    auto lerp = [](double a, double b, double t) { return a + (b - a) * std::clamp(t, 0.0, 1.0); };
    if (z >= 0.0) return lerp(0.0, psi_left_, (x + w) / (2 * w));
    const double off = -z * y_.spread;
    if (x >= 0.0) return x < off ? psi_tongue_ : lerp(psi_tongue_, psi_left_, (x - off) / w);
    return x > -off ? psi_tongue_ : lerp(0.0, psi_tongue_, (x + off + w) / w);
  }

  // Successive over-relaxation of the five-point Laplacian on the water's nodes (those off the
  // ends, listed once: most of the grid's box is land).
  void solve() {
    std::vector<std::pair<int, int>> free;
    for (int k = 1; k + 1 < nz_; ++k) {
      for (int i = 1; i + 1 < nx_; ++i) {
        if (inside_[index(i, k)] && !on_end(z_of(k), x_of(i))) free.emplace_back(i, k);
      }
    }
    const double omega = 1.985;  // near the optimum for the grid's longest run of nodes
    for (int sweep = 0; sweep < 100000; ++sweep) {
      double change = 0.0;
      for (const auto& [i, k] : free) {
        const double mean = 0.25 * (at(i - 1, k) + at(i + 1, k) + at(i, k - 1) + at(i, k + 1));
        const double delta = omega * (mean - at(i, k));
        psi_[index(i, k)] += delta;
        change = std::max(change, std::abs(delta));
      }
      if (change < 1e-9 * psi_left_) return;
    }
  }

  // Within half a step of an end: psi held at the uniform profile there.
  bool on_end(double z, double x) const {
    if (z > y_.main_length - 0.5 * h_) return true;
    const double d = -z;
    const double length = x >= 0.0 ? y_.left_length : y_.right_length;
    return d > length - 0.5 * h_;
  }

  YShape y_;
  double psi_left_, psi_tongue_, h_;
  double x0_ = 0.0, z0_ = 0.0;
  int nx_ = 0, nz_ = 0;
  std::vector<double> psi_;
  std::vector<uint8_t> inside_;
};

}  // namespace siviflow::test
