#include "sim/foam.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace siviflow {
namespace {

constexpr float kRayHeight = 100.0f;  // metres above a point to cast down from (the river is a
                                      // height field seen from above)
constexpr float kMinDirectionSpeed = 0.05f;  // m/s below which the flow has no direction

float smoothstep(float edge0, float edge1, float x) {
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// Barycentric weights of `p` in the x/z projection of triangle (a, b, c).
glm::vec3 barycentric_xz(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                         const glm::vec3& c) {
  const float e0x = b.x - a.x, e0z = b.z - a.z;
  const float e1x = c.x - a.x, e1z = c.z - a.z;
  const float px = p.x - a.x, pz = p.z - a.z;
  const float det = e0x * e1z - e1x * e0z;
  if (std::fabs(det) < 1e-12f) return {1.0f, 0.0f, 0.0f};
  const float v = (px * e1z - e1x * pz) / det;
  const float w = (e0x * pz - px * e0z) / det;
  return glm::clamp(glm::vec3(1.0f - v - w, v, w), 0.0f, 1.0f);
}

}  // namespace

Status FoamField::create(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                         std::span<const uint32_t> section, const TriangleBvh* bvh,
                         const FoamParams& params, FoamField* out, VertexTriangles around) {
  if (bvh == nullptr) return Status::error("FoamField: no ray-cast structure");
  if (section.size() != positions.size()) return Status::error("FoamField: a section per vertex");
  if (!(params.gradient_full > params.gradient_onset) || !(params.lifetime_s > 0.0f) ||
      !(params.deficit_full > params.deficit_onset) || !(params.step_s > 0.0f) ||
      !(params.bank_width_m > 0.0f) || !(params.bank_speed_full > 0.0f) ||
      !(params.front_share >= 0.0f && params.front_share <= 1.0f) ||
      !(params.min_section_speed > 0.0f) ||
      !(params.lee_acceleration > 0.0f)) {
    return Status::error("FoamParams: full above onset, positive lifetime, step, bank width, bank "
                         "speed, lee acceleration and least section speed, and a front share in "
                         "[0, 1] expected");
  }
  FoamField field;
  field.positions_ = positions;
  field.section_ = section;
  uint32_t sections = 0;
  for (uint32_t s : section) sections = std::max(sections, s + 1);
  field.section_speed_.assign(sections, 0.0f);
  field.section_size_.assign(sections, 0);
  for (uint32_t s : section) ++field.section_size_[s];
  field.bvh_ = bvh;
  field.params_ = params;
  const size_t count = positions.size();
  const size_t corners = indices.empty() ? count : indices.size();
  const auto corner = [&](size_t i) { return indices.empty() ? uint32_t(i) : indices[i]; };
  for (size_t i = 0; i < corners; ++i) {
    if (corner(i) >= count) return Status::error("FoamField: index out of range");
  }
  field.indices_ = indices;
  if (around.start.empty()) {
    // Counted, then filled in triangle order.
    field.own_start_.assign(count + 1, 0);
    for (size_t i = 0; i < corners; ++i) ++field.own_start_[corner(i) + 1];
    for (size_t v = 0; v < count; ++v) field.own_start_[v + 1] += field.own_start_[v];
    field.own_list_.resize(corners);
    std::vector<uint32_t> fill(field.own_start_.begin(), field.own_start_.end() - 1);
    for (size_t i = 0; i < corners; ++i) {
      field.own_list_[fill[corner(i)]++] = static_cast<uint32_t>(i / 3);
    }
  } else if (around.start.size() != count + 1 || around.start.back() != around.list.size()) {
    return Status::error("FoamField: the triangles around the vertices do not fit the mesh");
  }
  *out = std::move(field);
  // Spans into the moved vectors: a vector's move keeps its storage.
  out->around_ = around.start.empty() ? VertexTriangles{out->own_start_, out->own_list_} : around;
  return Status::success();
}

void FoamField::compute(std::span<const glm::vec3> velocity, std::span<const float> bank_distance,
                        std::span<float> foam) {
  const size_t count = positions_.size();
  const FoamParams& p = params_;
  std::fill(section_speed_.begin(), section_speed_.end(), 0.0f);
  for (size_t v = 0; v < count; ++v) {
    section_speed_[section_[v]] += std::hypot(velocity[v].x, velocity[v].z) / float(section_size_[section_[v]]);
  }
  // Per vertex: where the flow came from one step earlier (the triangle there and its corners'
  // weights; all 0 weights when that point is off the river), and its own foam source.
  std::vector<uint32_t> upstream_triangle(count, 0);
  std::vector<float> upstream_weight(count * 3, 0.0f);
  std::vector<float> source(count, 0.0f);
  const auto corner = [&](size_t i) { return indices_.empty() ? uint32_t(i) : indices_[i]; };
  std::vector<uint32_t> ring;
  for (size_t v = 0; v < count; ++v) {
    // The one-ring through the triangles, each neighbour once, ascending.
    ring.clear();
    for (uint32_t k = around_.start[v]; k < around_.start[v + 1]; ++k) {
      const size_t t = around_.list[k];
      for (size_t c = 3 * t; c < 3 * t + 3; ++c) {
        if (corner(c) != v) ring.push_back(corner(c));
      }
    }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    // Least-squares horizontal velocity gradient over the one-ring: G = (sum du dx^T)(sum dx dx^T)^-1.
    float axx = 0.0f, axz = 0.0f, azz = 0.0f;
    float bxx = 0.0f, bxz = 0.0f, bzx = 0.0f, bzz = 0.0f;
    for (const uint32_t j : ring) {
      const float dx = positions_[j].x - positions_[v].x;
      const float dz = positions_[j].z - positions_[v].z;
      const float dux = velocity[j].x - velocity[v].x;
      const float duz = velocity[j].z - velocity[v].z;
      axx += dx * dx;
      axz += dx * dz;
      azz += dz * dz;
      bxx += dux * dx;
      bxz += dux * dz;
      bzx += duz * dx;
      bzz += duz * dz;
    }
    const float det = axx * azz - axz * axz;
    float g00 = 0.0f, g01 = 0.0f, g10 = 0.0f, g11 = 0.0f;  // d(u_x, u_z) / d(x, z)
    if (det > 1e-12f) {
      const float ixx = azz / det, ixz = -axz / det, izz = axx / det;
      g00 = bxx * ixx + bxz * ixz;
      g01 = bxx * ixz + bxz * izz;
      g10 = bzx * ixx + bzz * ixz;
      g11 = bzx * ixz + bzz * izz;
    }
    const float gradient = std::sqrt(g00 * g00 + g01 * g01 + g10 * g10 + g11 * g11);
    const float speed = std::hypot(velocity[v].x, velocity[v].z);
    const float section_speed = section_speed_[section_[v]];
    const float deficit = section_speed > 0.0f ? 1.0f - speed / section_speed : 0.0f;
    // How the speed changes along the flow (1/s): negative where the water slows towards an
    // obstacle, positive where it gathers speed again in the lee.
    float along = 0.0f;
    if (speed > kMinDirectionSpeed) {
      const float ux = velocity[v].x / speed, uz = velocity[v].z / speed;
      along = ux * (g00 * ux + g01 * uz) + uz * (g10 * ux + g11 * uz);
    }
    const float lee = p.front_share + (1.0f - p.front_share) *
                                          smoothstep(-p.lee_acceleration, p.lee_acceleration, along);
    const float bank = p.bank_strength * std::exp(-bank_distance[v] / p.bank_width_m) *
                       std::min(section_speed / p.bank_speed_full, 1.0f);
    const float relative_gradient = gradient / std::max(section_speed, p.min_section_speed);
    source[v] = std::max({smoothstep(p.gradient_onset, p.gradient_full, relative_gradient),
                          lee * smoothstep(p.deficit_onset, p.deficit_full, deficit), bank});

    // Where this vertex's water was one step ago: cast down onto the surface there.
    const glm::vec3 back = positions_[v] - p.step_s * glm::vec3(velocity[v].x, 0.0f, velocity[v].z);
    RayHit hit;
    float* weight = &upstream_weight[v * 3];
    if (bvh_->intersect(back + glm::vec3(0.0f, kRayHeight, 0.0f), {0.0f, -1.0f, 0.0f},
                        2.0f * kRayHeight, &hit)) {
      upstream_triangle[v] = hit.triangle;
      uint32_t from[3];
      for (int c = 0; c < 3; ++c) from[c] = bvh_->triangle_vertex(hit.triangle, c);
      const glm::vec3 b = barycentric_xz(back, positions_[from[0]], positions_[from[1]],
                                         positions_[from[2]]);
      const float sum = std::max(b.x + b.y + b.z, 1e-6f);
      for (int c = 0; c < 3; ++c) weight[c] = b[c] / sum;
    } else {
      for (int c = 0; c < 3; ++c) weight[c] = 0.0f;  // came in over the inlet or a bank: none
    }
  }
  // Steady transport: each step the foam moves one step downstream and decays.
  const float decay = std::exp(-p.step_s / p.lifetime_s);
  std::copy(source.begin(), source.end(), foam.begin());
  std::vector<float> next(count);
  for (uint32_t step = 0; step < p.steps; ++step) {
    for (size_t v = 0; v < count; ++v) {
      const size_t t = upstream_triangle[v];
      const float* weight = &upstream_weight[v * 3];
      const float carried = weight[0] * foam[corner(3 * t)] + weight[1] * foam[corner(3 * t + 1)] +
                            weight[2] * foam[corner(3 * t + 2)];
      next[v] = std::max(source[v], decay * carried);
    }
    std::copy(next.begin(), next.end(), foam.begin());
  }
}

}  // namespace siviflow
