// An oracle for islands, independent of the simulation: psi from a finite-difference solution of
// Laplace's equation on a fine grid over a straight channel with an island, the island's psi
// set by zero circulation about it (the superposition of two solves). For the unit tests of the
// stream function and the end-to-end test of the captured flow.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

namespace siviflow::test {

// A straight channel along +Z: x from +width/2 (the left bank, psi = Q) to -width/2 (the right
// bank, psi = 0), z from z0 to z0 + length, meshed as a grid strip of quads `dx` across and
// `dz` along (vertex x = width/2 - j dx, z = z0 + k dz).
struct Channel {
  double width = 10.0;
  double z0 = 0.0;
  double length = 60.0;
  double dx = 0.5;
  double dz = 1.0;
};

// The island as a mesh has it: the quads of the grid (k along, j across) the mesh lacks.
struct QuadIsland {
  Channel channel;
  std::set<std::pair<int, int>> cut;

  // Inside or on the border of a cut quad.
  bool covers(double x, double z) const {
    const double j = (0.5 * channel.width - x) / channel.dx, k = (z - channel.z0) / channel.dz;
    for (const int dk : {0, -1}) {
      for (const int dj : {0, -1}) {
        const int qk = int(std::floor(k + 1e-9)) + dk, qj = int(std::floor(j + 1e-9)) + dj;
        if (k - qk > 1 + 1e-9 || j - qj > 1 + 1e-9) continue;
        if (cut.count({qk, qj})) return true;
      }
    }
    return false;
  }
};

// The quads of `channel` that no triangle of the mesh covers.
inline QuadIsland island_of(const Channel& channel, const std::vector<glm::vec3>& positions,
                            const std::vector<uint32_t>& indices) {
  std::set<std::pair<int, int>> present;
  for (size_t t = 0; t < indices.size(); t += 3) {
    const glm::vec3 c =
        (positions[indices[t]] + positions[indices[t + 1]] + positions[indices[t + 2]]) / 3.0f;
    present.insert({int(std::floor((c.z - channel.z0) / channel.dz)),
                    int(std::floor((0.5 * channel.width - c.x) / channel.dx))});
  }
  QuadIsland island{channel, {}};
  const int rows = int(std::lround(channel.length / channel.dz));
  const int columns = int(std::lround(channel.width / channel.dx));
  for (int k = 0; k < rows; ++k) {
    for (int j = 0; j < columns; ++j) {
      if (!present.count({k, j})) island.cut.insert({k, j});
    }
  }
  return island;
}

// psi on a grid of spacing h: Q on the left bank, 0 on the right, uniform flow at both ends, the
// island's psi the value of zero circulation about it.
class LaplaceOracle {
 public:
  LaplaceOracle(const QuadIsland& island, double q, double h) : channel_(island.channel), h_(h) {
    nx_ = int(std::lround(channel_.width / h)) + 1;
    nz_ = int(std::lround(channel_.length / h)) + 1;
    island_.resize(size_t(nx_) * nz_);
    for (int i = 0; i < nx_; ++i) {
      for (int k = 0; k < nz_; ++k) island_[index(i, k)] = island.covers(x_of(i), z_of(k));
    }
    const std::vector<double> base = relax(q, 0.0), unit = relax(0.0, 1.0);
    island_psi_ = -circulation(base) / circulation(unit);
    psi_.resize(base.size());
    for (size_t n = 0; n < base.size(); ++n) psi_[n] = base[n] + island_psi_ * unit[n];
  }

  double island_psi() const { return island_psi_; }
  // Velocity grad(psi) x +Y = (-dpsi/dz, 0, dpsi/dx), bilinear between central differences.
  glm::dvec3 velocity(double x, double z) const {
    const double fi = (0.5 * channel_.width - x) / h_, fk = (z - channel_.z0) / h_;
    const int i = std::clamp(int(fi), 1, nx_ - 3), k = std::clamp(int(fk), 1, nz_ - 3);
    const double u = fi - i, w = fk - k;
    glm::dvec3 v(0.0);
    for (const auto& [di, dk, weight] :
         {std::tuple{0, 0, (1 - u) * (1 - w)}, std::tuple{1, 0, u * (1 - w)},
          std::tuple{0, 1, (1 - u) * w}, std::tuple{1, 1, u * w}}) {
      const int a = i + di, b = k + dk;
      // x decreases with i.
      const double dpsi_dx = -(psi_[index(a + 1, b)] - psi_[index(a - 1, b)]) / (2 * h_);
      const double dpsi_dz = (psi_[index(a, b + 1)] - psi_[index(a, b - 1)]) / (2 * h_);
      v += weight * glm::dvec3(-dpsi_dz, 0.0, dpsi_dx);
    }
    return v;
  }

 private:
  size_t index(int i, int k) const { return size_t(k) * nx_ + size_t(i); }
  double x_of(int i) const { return 0.5 * channel_.width - i * h_; }
  double z_of(int k) const { return channel_.z0 + k * h_; }

  // Successive over-relaxation to a fixed point.
  std::vector<double> relax(double q, double island_value) const {
    std::vector<double> psi(size_t(nx_) * nz_);
    for (int k = 0; k < nz_; ++k) {
      for (int i = 0; i < nx_; ++i) {
        const double uniform = q * double(nx_ - 1 - i) / double(nx_ - 1);
        psi[index(i, k)] = island_[index(i, k)] ? island_value : uniform;
      }
    }
    const double omega = 2.0 / (1.0 + std::sin(M_PI * h_ / channel_.width)) * 0.98;
    for (int sweep = 0; sweep < 100000; ++sweep) {
      double change = 0.0;
      for (int k = 1; k + 1 < nz_; ++k) {
        for (int i = 1; i + 1 < nx_; ++i) {
          const size_t n = index(i, k);
          if (island_[n]) continue;
          const double target = 0.25 * (psi[n - 1] + psi[n + 1] + psi[n - nx_] + psi[n + nx_]);
          change = std::max(change, std::abs(target - psi[n]));
          psi[n] += omega * (target - psi[n]);
        }
      }
      if (change < 1e-12 * std::max(1.0, q)) break;
    }
    return psi;
  }

  // Flux of grad(psi) out of a box of grid lines two steps outside the island.
  double circulation(const std::vector<double>& psi) const {
    int i0 = nx_, i1 = 0, k0 = nz_, k1 = 0;
    for (int k = 0; k < nz_; ++k) {
      for (int i = 0; i < nx_; ++i) {
        if (!island_[index(i, k)]) continue;
        i0 = std::min(i0, i - 2), i1 = std::max(i1, i + 2), k0 = std::min(k0, k - 2),
        k1 = std::max(k1, k + 2);
      }
    }
    const auto p = [&](int i, int k) { return psi[index(i, k)]; };
    double flux = 0.0;
    for (int i = i0; i < i1; ++i) {  // the upstream and downstream sides
      flux += 0.5 * (p(i, k0 - 1) - p(i, k0) + p(i + 1, k0 - 1) - p(i + 1, k0));
      flux += 0.5 * (p(i, k1 + 1) - p(i, k1) + p(i + 1, k1 + 1) - p(i + 1, k1));
    }
    for (int k = k0; k < k1; ++k) {  // the two sides
      flux += 0.5 * (p(i0 - 1, k) - p(i0, k) + p(i0 - 1, k + 1) - p(i0, k + 1));
      flux += 0.5 * (p(i1 + 1, k) - p(i1, k) + p(i1 + 1, k + 1) - p(i1, k + 1));
    }
    return flux;
  }

  Channel channel_;
  double h_;
  int nx_ = 0, nz_ = 0;
  std::vector<uint8_t> island_;
  std::vector<double> psi_;
  double island_psi_ = 0.0;
};

}  // namespace siviflow::test
