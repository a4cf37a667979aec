// River meshes for the sim tests: straight, varying-width and bent strips, strips whose sections
// differ in vertex count, and helpers to shuffle a mesh and to measure fluxes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "siviflow/sim/stream_function.h"
#include "sim/grid_holes.h"

namespace siviflow::test {

struct TestMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
};

// n points evenly from `left` to `right`.
inline std::vector<glm::vec3> section_line(glm::vec3 left, glm::vec3 right, uint32_t n) {
  std::vector<glm::vec3> out;
  for (uint32_t j = 0; j < n; ++j) {
    const float t = float(j) / float(n - 1);
    out.push_back(left + t * (right - left));
  }
  return out;
}

// A strip through the given sections (each from the left shore to the right shore), vertices
// section-major; each band is zipped by arc-length fraction, so sections may differ in count.
inline TestMesh mesh_from_sections(const std::vector<std::vector<glm::vec3>>& sections) {
  TestMesh m;
  std::vector<uint32_t> first;
  for (const auto& s : sections) {
    first.push_back(uint32_t(m.positions.size()));
    m.positions.insert(m.positions.end(), s.begin(), s.end());
  }
  for (size_t k = 0; k + 1 < sections.size(); ++k) {
    const uint32_t n = uint32_t(sections[k].size()), mm = uint32_t(sections[k + 1].size());
    uint32_t i = 0, j = 0;
    while (i + 1 < n || j + 1 < mm) {
      const uint32_t a = first[k] + i, b = first[k + 1] + j;
      const double ti = n > 1 ? double(i + 1) / (n - 1) : 2.0;
      const double tj = mm > 1 ? double(j + 1) / (mm - 1) : 2.0;
      if (j + 1 >= mm || (i + 1 < n && ti <= tj)) {
        m.indices.insert(m.indices.end(), {a, a + 1, b});
        ++i;
      } else {
        m.indices.insert(m.indices.end(), {a, b + 1, b});
        ++j;
      }
    }
  }
  return m;
}

// Straight channel along +Z from z = 0 to `length`, the left bank (+X side) at x = +width/2.
inline TestMesh straight_channel(float width, float length, uint32_t sections, uint32_t across) {
  std::vector<std::vector<glm::vec3>> s;
  for (uint32_t k = 0; k < sections; ++k) {
    const float z = length * float(k) / float(sections - 1);
    s.push_back(section_line({0.5f * width, 0.0f, z}, {-0.5f * width, 0.0f, z}, across));
  }
  return mesh_from_sections(s);
}

// Straight channel as above, with diagonals mirrored about x = 0 and z = length/2 so that the
// triangulation is symmetric both across and along the flow (sections and across odd).
inline TestMesh symmetric_channel(float width, float length, uint32_t sections, uint32_t across) {
  TestMesh m;
  for (uint32_t k = 0; k < sections; ++k) {
    const float z = length * float(k) / float(sections - 1);
    for (uint32_t j = 0; j < across; ++j) {
      const float x = 0.5f * width - width * float(j) / float(across - 1);
      m.positions.push_back({x, 0.0f, z});
    }
  }
  for (uint32_t k = 0; k + 1 < sections; ++k) {
    for (uint32_t j = 0; j + 1 < across; ++j) {
      const uint32_t a = k * across + j, b = a + 1, c = a + across, d = c + 1;
      const float xc = 0.5f * (m.positions[a].x + m.positions[b].x);
      const float zc = 0.5f * (m.positions[a].z + m.positions[c].z) - 0.5f * length;
      if ((xc > 0) == (zc > 0)) {
        m.indices.insert(m.indices.end(), {a, b, d, a, d, c});
      } else {
        m.indices.insert(m.indices.end(), {a, b, c, b, d, c});
      }
    }
  }
  return m;
}

// symmetric_channel with an island: the quads whose centres lie in the ellipse about (x, z)
// with half-axes rx across and rz along the flow cut out.
inline TestMesh channel_with_island(float width, float length, uint32_t sections, uint32_t across,
                                    float x, float z, float rx, float rz) {
  TestMesh m = symmetric_channel(width, length, sections, across);
  const float dx = width / float(across - 1), dz = length / float(sections - 1);
  cut_grid_quads(
      across,
      [&](uint32_t k, uint32_t j) {
        const float qx = 0.5f * width - dx * (float(j) + 0.5f) - x;
        const float qz = dz * (float(k) + 0.5f) - z;
        return (qx / rx) * (qx / rx) + (qz / rz) * (qz / rz) < 1.0f;
      },
      &m.positions, &m.indices);
  return m;
}

// Quarter annulus r1 <= r <= r2 with radial sections; vertex 0 on the inner bank at angle 0.
inline TestMesh bend(float r1, float r2, float angle, uint32_t sections, uint32_t across) {
  std::vector<std::vector<glm::vec3>> s;
  for (uint32_t k = 0; k < sections; ++k) {
    const float a = angle * float(k) / float(sections - 1);
    const glm::vec3 dir(std::cos(a), 0.0f, std::sin(a));
    s.push_back(section_line(r1 * dir, r2 * dir, across));
  }
  return mesh_from_sections(s);
}

// Shuffles vertex order (keeping vertex 0), triangle order and each triangle's rotation.
inline TestMesh shuffled(const TestMesh& in, uint32_t seed, std::vector<uint32_t>* new_of_old) {
  std::mt19937 rng(seed);
  const size_t n = in.positions.size();
  std::vector<uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin() + 1, perm.end(), rng);  // perm[new] = old
  new_of_old->assign(n, 0);
  for (uint32_t i = 0; i < n; ++i) (*new_of_old)[perm[i]] = i;
  TestMesh out;
  for (uint32_t i = 0; i < n; ++i) out.positions.push_back(in.positions[perm[i]]);
  std::vector<uint32_t> order(in.indices.size() / 3);
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), rng);
  for (const uint32_t t : order) {
    const uint32_t r = rng() % 3;
    for (uint32_t i = 0; i < 3; ++i) {
      out.indices.push_back((*new_of_old)[in.indices[3 * t + (i + r) % 3]]);
    }
  }
  return out;
}

// Downstream in-surface normal of the section segment u -> w (walking left to right).
inline glm::dvec3 segment_normal(const glm::vec3& u, const glm::vec3& w) {
  return glm::normalize(glm::cross(glm::dvec3(0, 1, 0), glm::dvec3(w - u)));
}

// Flux across section k by the trapezoid rule on the vertex velocities.
inline double vertex_flux(const StreamFunction& flow, size_t k) {
  const auto nodes = flow.surface().section_nodes(k);
  const auto pos = flow.surface().node_positions();
  const auto vel = flow.node_velocity();
  double flux = 0.0;
  for (size_t i = 0; i + 1 < nodes.size(); ++i) {
    const glm::vec3& u = pos[nodes[i]];
    const glm::vec3& w = pos[nodes[i + 1]];
    const glm::dvec3 v = 0.5 * (glm::dvec3(vel[nodes[i]]) + glm::dvec3(vel[nodes[i + 1]]));
    flux += glm::dot(v, segment_normal(u, w)) * glm::distance(glm::dvec3(u), glm::dvec3(w));
  }
  return flux;
}

// psi at every node.
inline std::vector<double> node_psis(const StreamFunction& flow) {
  std::vector<double> psi(flow.surface().node_count());
  for (uint32_t n = 0; n < psi.size(); ++n) psi[n] = flow.node_psi(n);
  return psi;
}

// How many nodes' psi or velocity differ between two solves of one river (psi, evaluated when
// asked, differs only where the obstacles do: the velocities tell the updates apart).
inline size_t nodes_that_differ(const StreamFunction& a, const StreamFunction& b) {
  size_t differ = 0;
  for (uint32_t n = 0; n < a.surface().node_count(); ++n) {
    differ += a.node_psi(n) != b.node_psi(n) || a.node_velocity()[n] != b.node_velocity()[n];
  }
  return differ;
}

// A triangle holding both nodes (an edge), preferring the one downstream of section k.
inline uint32_t triangle_on_edge(const RiverSurface& s, uint32_t a, uint32_t b) {
  uint32_t found = UINT32_MAX;
  for (const uint32_t t : s.node_triangles(a)) {
    const auto tri = s.triangles().subspan(3 * size_t{t}, 3);
    if (tri[0] == b || tri[1] == b || tri[2] == b) found = std::min(found, t);
  }
  return found;
}

// Flux across section k from node index `from` to `to` in the section (exclusive of nothing),
// with each segment's flux taken from a triangle on it: exact for P1 psi (equals psi difference).
inline double triangle_flux(const StreamFunction& flow, size_t k, size_t from, size_t to) {
  const RiverSurface& s = flow.surface();
  const auto nodes = s.section_nodes(k);
  const auto pos = s.node_positions();
  double flux = 0.0;
  for (size_t i = from; i < to; ++i) {
    const glm::vec3& u = pos[nodes[i]];
    const glm::vec3& w = pos[nodes[i + 1]];
    const uint32_t t = triangle_on_edge(s, nodes[i], nodes[i + 1]);
    const glm::dvec3 v(flow.triangle_velocity(t));
    flux += glm::dot(v, segment_normal(u, w)) * glm::distance(glm::dvec3(u), glm::dvec3(w));
  }
  return flux;
}

}  // namespace siviflow::test
