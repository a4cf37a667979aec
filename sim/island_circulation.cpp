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

// A x = b over a cluster's unknowns: A symmetric and positive definite, in rows (columns
// ascending, the diagonal among them).
struct System {
  std::vector<uint32_t> start;  // row r's entries are [start[r], start[r + 1])
  std::vector<uint32_t> column;
  std::vector<double> value;
  std::vector<double> rhs;
  size_t size() const { return rhs.size(); }
};

void multiply(const System& a, const std::vector<double>& x, std::vector<double>* y) {
  for (size_t r = 0; r < a.size(); ++r) {
    double sum = 0.0;
    for (uint32_t e = a.start[r]; e < a.start[r + 1]; ++e) sum += a.value[e] * x[a.column[e]];
    (*y)[r] = sum;
  }
}

// Incomplete Cholesky without fill (IC(0)): L on A's lower pattern, L L^T ~ A. Fails (false)
// where a pivot is not positive; the caller then falls back to the diagonal.
struct IncompleteCholesky {
  std::vector<uint32_t> start, column;  // lower rows, the diagonal last in each
  std::vector<double> value;

  bool factor(const System& a) {
    const size_t n = a.size();
    start.assign(n + 1, 0);
    column.clear();
    value.clear();
    for (size_t r = 0; r < n; ++r) {
      for (uint32_t e = a.start[r]; e < a.start[r + 1] && a.column[e] <= r; ++e) {
        column.push_back(a.column[e]);
        value.push_back(a.value[e]);
      }
      start[r + 1] = uint32_t(column.size());
      if (column.empty() || column.back() != r) return false;  // no diagonal
    }
    for (size_t i = 0; i < n; ++i) {
      for (uint32_t e = start[i]; e < start[i + 1]; ++e) {
        const uint32_t k = column[e];
        // L[i][k] -= sum over j < k of L[i][j] L[k][j] (both rows ascending: a merge).
        double sum = 0.0;
        uint32_t p = start[i], q = start[k];
        while (p < e && q + 1 < start[k + 1]) {
          if (column[p] == column[q]) {
            sum += value[p++] * value[q++];
          } else if (column[p] < column[q]) {
            ++p;
          } else {
            ++q;
          }
        }
        if (k < i) {
          value[e] = (value[e] - sum) / value[start[k + 1] - 1];
        } else {
          const double pivot = value[e] - sum;
          if (!(pivot > 0.0)) return false;
          value[e] = std::sqrt(pivot);
        }
      }
    }
    return true;
  }

  // z = (L L^T)^-1 r.
  void apply(const std::vector<double>& r, std::vector<double>* z) const {
    const size_t n = r.size();
    for (size_t i = 0; i < n; ++i) {
      double sum = r[i];
      for (uint32_t e = start[i]; e + 1 < start[i + 1]; ++e) sum -= value[e] * (*z)[column[e]];
      (*z)[i] = sum / value[start[i + 1] - 1];
    }
    for (size_t i = n; i-- > 0;) {
      (*z)[i] /= value[start[i + 1] - 1];
      for (uint32_t e = start[i]; e + 1 < start[i + 1]; ++e) (*z)[column[e]] -= value[e] * (*z)[i];
    }
  }
};

// Preconditioned conjugate gradients on A x = b; x holds the first guess.
bool solve(const System& a, std::vector<double>* x) {
  const size_t n = a.size();
  IncompleteCholesky cholesky;
  const bool factored = cholesky.factor(a);
  std::vector<double> diag(n, 1.0);
  for (size_t r = 0; r < n; ++r) {
    for (uint32_t e = a.start[r]; e < a.start[r + 1]; ++e) {
      if (a.column[e] == r && a.value[e] > 0.0) diag[r] = a.value[e];
    }
  }
  const auto precondition = [&](const std::vector<double>& r, std::vector<double>* z) {
    if (factored) {
      cholesky.apply(r, z);
    } else {
      for (size_t i = 0; i < n; ++i) (*z)[i] = r[i] / diag[i];
    }
  };
  std::vector<double> r(n), z(n), p(n), ap(n);
  multiply(a, *x, &r);
  double b_norm = 0.0;
  for (size_t i = 0; i < n; ++i) {
    r[i] = a.rhs[i] - r[i];
    b_norm += a.rhs[i] * a.rhs[i];
  }
  b_norm = std::sqrt(b_norm);
  precondition(r, &z);
  p = z;
  double rz = 0.0;
  for (size_t i = 0; i < n; ++i) rz += r[i] * z[i];
  for (int iteration = 0; iteration < kIslandSolveMaxIterations; ++iteration) {
    double r_norm = 0.0;
    for (const double v : r) r_norm += v * v;
    if (std::sqrt(r_norm) <= kIslandSolveTolerance * b_norm) return true;
    multiply(a, p, &ap);
    double pap = 0.0;
    for (size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
    if (!(pap > 0.0)) return false;
    const double alpha = rz / pap;
    for (size_t i = 0; i < n; ++i) {
      (*x)[i] += alpha * p[i];
      r[i] -= alpha * ap[i];
    }
    precondition(r, &z);
    double rz_next = 0.0;
    for (size_t i = 0; i < n; ++i) rz_next += r[i] * z[i];
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

Status island_stream_values(const RiverSurface& surface, const std::vector<double>& border_psi,
                            std::vector<double>* out) {
  const size_t island_count = surface.islands().size();
  std::vector<double> values(island_count, 0.0);
  const auto pos = surface.node_positions();
  const auto tris = surface.triangles();
  const auto bank = surface.node_bank();
  std::vector<int32_t> unknown(surface.node_count(), kFixed);
  std::vector<double> fixed_value(surface.node_count(), 0.0);
  // A first guess for an island's psi: halfway between the banks.
  const double middle = 0.5 * (border_psi[kLeftBankBorder] + border_psi[kRightBankBorder]);
  auto known_psi = [&](BorderId b) { return surface.is_island_border(b) ? middle : border_psi[b]; };
  // psi of uniform flow across a node's arm: linear between the borders either side.
  auto uniform = [&](uint32_t n) {
    const RiverVertex v = surface.node(n);
    const double right = known_psi(v.right_border);
    return right + (known_psi(v.left_border) - right) * v.d_right / (v.d_left + v.d_right);
  };

  for (const Cluster& cluster : clusters_of(surface)) {
    // Unknowns: the islands first, then every other node strictly inside the cluster that is
    // not on a bank. The closing sections and the banks are fixed.
    std::vector<uint32_t> nodes;
    std::vector<double> x(cluster.islands.size(), 0.0);
    for (uint32_t k = cluster.first_section; k <= cluster.last_section; ++k) {
      const auto chain = surface.section_nodes(k);
      const bool closing = k == cluster.first_section || k == cluster.last_section;
      for (size_t i = 0; i < chain.size(); ++i) {
        const uint32_t n = chain[i];
        nodes.push_back(n);
        if (surface.on_island(n)) {
          const auto it = std::find(cluster.islands.begin(), cluster.islands.end(),
                                    static_cast<uint32_t>(surface.island_of(n)));
          if (it == cluster.islands.end()) {  // a cluster holds every island its sections meet
            return Status::error(text_format(
                "the flow about the islands near river vertex %u could not be set up: island "
                "%zu lies across the sections that close its neighbour's region",
                surface.vertex_of_node(n), surface.island_of(n)));
          }
          unknown[n] = static_cast<int32_t>(it - cluster.islands.begin());
        } else if (bank[n] != Bank::kNone) {
          fixed_value[n] = border_psi[bank[n] == Bank::kLeft ? kLeftBankBorder : kRightBankBorder];
        } else if (surface.on_tongue(n)) {
          fixed_value[n] = border_psi[surface.node_left_border(n)];
        } else if (closing) {
          fixed_value[n] = uniform(n);
        } else {
          unknown[n] = static_cast<int32_t>(x.size());
          x.push_back(uniform(n));
        }
      }
    }
    // The rows: at each unknown node, sum over its triangles' two other corners m of
    // w (psi_n - psi_m), w the half-cotangent of the angle opposite edge nm; an island's row is
    // the sum of its shore's.
    std::vector<std::vector<std::pair<uint32_t, double>>> rows(x.size());
    System system;
    system.rhs.assign(x.size(), 0.0);
    // A node's row has a handful of entries, merged as they come; an island's has one per shore
    // neighbour, appended and merged once sorted.
    const size_t island_rows = cluster.islands.size();
    const auto add = [&](uint32_t row, uint32_t col, double w) {
      if (row < island_rows) {
        rows[row].emplace_back(col, w);
        return;
      }
      for (auto& [c, v] : rows[row]) {
        if (c == col) {
          v += w;
          return;
        }
      }
      rows[row].emplace_back(col, w);
    };
    for (const uint32_t n : nodes) {
      if (unknown[n] == kFixed) continue;
      const auto u = static_cast<uint32_t>(unknown[n]);
      for (const uint32_t t : surface.node_triangles(n)) {
        const uint32_t* c = &tris[3 * size_t{t}];
        const int i = c[0] == n ? 0 : c[1] == n ? 1 : 2;
        const uint32_t a = c[(i + 1) % 3], b = c[(i + 2) % 3];
        const glm::dvec3 pn(pos[n]), pa(pos[a]), pb(pos[b]);
        for (const auto& [m, w] : {std::pair{a, 0.5 * cotangent(pn, pa, pb)},
                                   std::pair{b, 0.5 * cotangent(pn, pb, pa)}}) {
          if (unknown[m] == unknown[n]) continue;  // along one island's shore
          add(u, u, w);
          if (unknown[m] == kFixed) {
            system.rhs[u] += w * fixed_value[m];
          } else {
            add(u, static_cast<uint32_t>(unknown[m]), -w);
          }
        }
      }
    }
    system.start.assign(x.size() + 1, 0);
    for (size_t r = 0; r < rows.size(); ++r) {
      std::sort(rows[r].begin(), rows[r].end());
      for (const auto& [c, v] : rows[r]) {
        if (!system.column.empty() && system.column.size() > system.start[r] &&
            system.column.back() == c) {
          system.value.back() += v;  // an island's entries, appended apart
          continue;
        }
        system.column.push_back(c);
        system.value.push_back(v);
      }
      system.start[r + 1] = static_cast<uint32_t>(system.column.size());
    }
    for (size_t i = 0; i < cluster.islands.size(); ++i) x[i] = middle;  // first guess
    const bool converged = solve(system, &x);
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
