#include "island_circulation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "siviflow/sim/river_tuning.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr int32_t kFixed = -1;

// Islands whose sections, widened by the margin, overlap: solved together.
struct Cluster {
  uint32_t first_section = 0;
  uint32_t last_section = 0;
  std::vector<uint32_t> islands;
};

std::vector<Cluster> clusters_of(const RiverSurface& surface) {
  const auto sections = surface.sections();
  const double margin = kIslandSolveMarginWidths * surface.widest_section();
  std::vector<Cluster> spans;
  for (uint32_t i = 0; i < surface.islands().size(); ++i) {
    uint32_t k0 = UINT32_MAX, k1 = 0;
    for (const uint32_t n : surface.island_nodes(i)) {
      k0 = std::min(k0, surface.node_section()[n]);
      k1 = std::max(k1, surface.node_section()[n]);
    }
    // An island's shore never holds an end section's vertex (those are the outer border's), so
    // the closing sections lie beyond it; clamped all the same.
    uint32_t first = k0 > 0 ? k0 - 1 : 0;
    uint32_t last = std::min<uint32_t>(k1 + 1, uint32_t(sections.size() - 1));
    while (first > 0 && sections[k0].along - sections[first].along < margin) --first;
    while (last + 1 < sections.size() && sections[last].along - sections[k1].along < margin) ++last;
    spans.push_back({first, last, {i}});
  }
  std::sort(spans.begin(), spans.end(),
            [](const Cluster& a, const Cluster& b) { return a.first_section < b.first_section; });
  std::vector<Cluster> merged;
  for (Cluster& c : spans) {
    if (!merged.empty() && c.first_section <= merged.back().last_section) {
      merged.back().last_section = std::max(merged.back().last_section, c.last_section);
      merged.back().islands.push_back(c.islands.front());
    } else {
      merged.push_back(std::move(c));
    }
  }
  return merged;
}

// One edge of a triangle with its half-cotangent weight, in unknowns (or fixed values).
struct Edge {
  int32_t du, dv;  // unknown of each end, or kFixed
  double fu, fv;   // the fixed value of an end that has no unknown
  double weight;
};

// y = A x over the unknowns; with `fixed`, the fixed ends' values take part (K psi at x).
void apply(const std::vector<Edge>& edges, const std::vector<double>& x, bool fixed,
           std::vector<double>* y) {
  std::fill(y->begin(), y->end(), 0.0);
  for (const Edge& e : edges) {
    const double u = e.du != kFixed ? x[size_t(e.du)] : (fixed ? e.fu : 0.0);
    const double v = e.dv != kFixed ? x[size_t(e.dv)] : (fixed ? e.fv : 0.0);
    const double flux = e.weight * (u - v);
    if (e.du != kFixed) (*y)[size_t(e.du)] += flux;
    if (e.dv != kFixed) (*y)[size_t(e.dv)] -= flux;
  }
}

// Preconditioned conjugate gradients on A x = -K_fc psi_c; x holds the first guess.
bool solve(const std::vector<Edge>& edges, std::vector<double>* x) {
  const size_t n = x->size();
  std::vector<double> diag(n, 0.0), r(n), z(n), p(n), ap(n);
  for (const Edge& e : edges) {
    if (e.du == e.dv) continue;  // both ends on one island's shore
    if (e.du != kFixed) diag[size_t(e.du)] += e.weight;
    if (e.dv != kFixed) diag[size_t(e.dv)] += e.weight;
  }
  apply(edges, *x, true, &r);
  std::vector<double> zero(n, 0.0), b(n);
  apply(edges, zero, true, &b);  // K_fc psi_c
  double b_norm = 0.0;
  for (size_t i = 0; i < n; ++i) {
    r[i] = -r[i];
    b_norm += b[i] * b[i];
    if (!(diag[i] > 0.0)) diag[i] = 1.0;
  }
  b_norm = std::sqrt(b_norm);
  double rz = 0.0;
  for (size_t i = 0; i < n; ++i) {
    z[i] = r[i] / diag[i];
    p[i] = z[i];
    rz += r[i] * z[i];
  }
  for (int iteration = 0; iteration < kIslandSolveMaxIterations; ++iteration) {
    double r_norm = 0.0;
    for (const double v : r) r_norm += v * v;
    if (std::sqrt(r_norm) <= kIslandSolveTolerance * b_norm) return true;
    apply(edges, p, false, &ap);
    double pap = 0.0;
    for (size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
    if (!(pap > 0.0)) return false;
    const double alpha = rz / pap;
    double rz_next = 0.0;
    for (size_t i = 0; i < n; ++i) {
      (*x)[i] += alpha * p[i];
      r[i] -= alpha * ap[i];
      z[i] = r[i] / diag[i];
      rz_next += r[i] * z[i];
    }
    const double beta = rz_next / rz;
    rz = rz_next;
    for (size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
  }
  return false;
}

// Cotangent of the angle at c in triangle (a, b, c).
double cotangent(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 u = a - c, v = b - c;
  return glm::dot(u, v) / glm::length(glm::cross(u, v));
}

}  // namespace

Status island_stream_values(const RiverSurface& surface, double discharge,
                            std::vector<double>* out) {
  const size_t island_count = surface.islands().size();
  std::vector<double> values(island_count, 0.0);
  const auto pos = surface.node_positions();
  const auto tris = surface.triangles();
  const auto bank = surface.node_bank();
  std::vector<int32_t> unknown(surface.node_count(), kFixed);
  std::vector<double> fixed_value(surface.node_count(), 0.0);

  for (const Cluster& cluster : clusters_of(surface)) {
    // Unknowns: the islands first, then every other node strictly inside the cluster that is
    // not on a bank. The closing sections and the banks are fixed.
    std::vector<uint32_t> nodes;
    std::vector<double> x(cluster.islands.size(), 0.0);
    for (uint32_t k = cluster.first_section; k <= cluster.last_section; ++k) {
      const auto chain = surface.section_nodes(k);
      const double width = surface.sections()[k].width;
      const bool closing = k == cluster.first_section || k == cluster.last_section;
      double water = 0.0;  // arc over water from the left bank (no island on a closing section)
      for (size_t i = 0; i < chain.size(); ++i) {
        const uint32_t n = chain[i];
        if (i > 0 && closing)
          water += glm::distance(glm::dvec3(pos[chain[i - 1]]), glm::dvec3(pos[n]));
        nodes.push_back(n);
        if (surface.on_island(n)) {
          const auto it = std::find(cluster.islands.begin(), cluster.islands.end(),
                                    static_cast<uint32_t>(surface.island_of(n)));
          unknown[n] = static_cast<int32_t>(it - cluster.islands.begin());
        } else if (closing || bank[n] != Bank::kNone) {
          fixed_value[n] = closing ? discharge * (1.0 - water / width)
                                   : (bank[n] == Bank::kLeft ? discharge : 0.0);
        } else {
          unknown[n] = static_cast<int32_t>(x.size());
          // First guess: uniform flow between the banks' own borders.
          const RiverVertex v = surface.node(n);
          x.push_back(discharge * v.d_right / (v.d_left + v.d_right));
        }
      }
    }
    std::vector<uint32_t> triangles;
    for (const uint32_t n : nodes) {
      if (unknown[n] == kFixed) continue;
      for (const uint32_t t : surface.node_triangles(n)) triangles.push_back(t);
    }
    std::sort(triangles.begin(), triangles.end());
    triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
    std::vector<Edge> edges;
    edges.reserve(3 * triangles.size());
    for (const uint32_t t : triangles) {
      const uint32_t c[3] = {tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]};
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = c[i], b = c[(i + 1) % 3], o = c[(i + 2) % 3];
        const double w =
            0.5 * cotangent(glm::dvec3(pos[a]), glm::dvec3(pos[b]), glm::dvec3(pos[o]));
        edges.push_back({unknown[a], unknown[b], fixed_value[a], fixed_value[b], w});
      }
    }
    for (size_t i = 0; i < cluster.islands.size(); ++i) x[i] = 0.5 * discharge;  // first guess
    const bool converged = solve(edges, &x);
    for (const uint32_t n : nodes) {
      unknown[n] = kFixed;
      fixed_value[n] = 0.0;
    }
    if (!converged) {
      return Status::error(text_format(
          "the flow about island %u (at river vertex %u) did not converge: its mesh may have "
          "inverted or degenerate triangles",
          cluster.islands.front(),
          surface.vertex_of_node(surface.island_nodes(cluster.islands.front())[0])));
    }
    for (size_t i = 0; i < cluster.islands.size(); ++i) values[cluster.islands[i]] = x[i];
  }
  *out = std::move(values);
  return Status::success();
}

}  // namespace siviflow
