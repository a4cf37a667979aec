#include "sim/foam.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

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

// Squared horizontal speed.
float speed2(const glm::vec3& velocity) {
  return velocity.x * velocity.x + velocity.z * velocity.z;
}

// 1 + the index of the first box holding p; 0 when none does (the boxes are few: one or two per
// obstacle moved).
uint32_t first_holding(std::span<const XzBox> boxes, const glm::vec3& p) {
  for (size_t b = 0; b < boxes.size(); ++b) {
    if (boxes[b].holds(p)) return uint32_t(b + 1);
  }
  return 0u;
}

// A vertex's foam after one more transport step: its own source, or what the step carried to it
// from its upstream corners, decayed. One expression for the whole river and for a window, so
// both round alike.
float transported(float source, float decay, const float* weight, float a, float b, float c) {
  return std::max(source, decay * (weight[0] * a + weight[1] * b + weight[2] * c));
}

}  // namespace

MarginDistances margin_distances(const RiverSurface& surface) {
  return {surface.node_d_left(), surface.node_d_right(), surface.node_of_vertex()};
}

Status FoamField::create(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                         NodeSections section, const TriangleBvh* bvh, const FoamParams& params,
                         FoamField* out, const TrianglesAround* around) {
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
  for (size_t v = 0; v < section.size(); ++v) sections = std::max(sections, section[v] + 1);
  field.section_speed_.assign(sections, 0.0f);
  field.section_size_.assign(sections, 0);
  for (size_t v = 0; v < section.size(); ++v) ++field.section_size_[section[v]];
  field.bvh_ = bvh;
  field.params_ = params;
  const size_t count = positions.size();
  const size_t corners = indices.empty() ? count : indices.size();
  const auto corner = [&](size_t i) { return indices.empty() ? uint32_t(i) : indices[i]; };
  for (size_t i = 0; i < corners; ++i) {
    if (corner(i) >= count) return Status::error("FoamField: index out of range");
  }
  for (size_t i = 0; i < corners; ++i) {
    const glm::vec3& a = positions[corner(i)];
    const glm::vec3& b = positions[corner(i % 3 == 2 ? i - 2 : i + 1)];
    field.longest_edge_ = std::max(field.longest_edge_, std::hypot(a.x - b.x, a.z - b.z));
  }
  // A step's upstream point is rounded to a float: off by up to half a float's spacing there.
  float farthest = 0.0f;
  for (const glm::vec3& p : positions) {
    farthest = std::max({farthest, std::fabs(p.x), std::fabs(p.z)});
  }
  field.rounding_ = 2.0f * (std::nextafter(farthest, INFINITY) - farthest);
  std::vector<XzBox> section_bounds(sections);
  for (size_t v = 0; v < count; ++v) section_bounds[section[v]].grow(positions[v]);
  for (const XzBox& box : section_bounds) {
    if (!box.empty()) {
      field.widest_section_ = std::max(field.widest_section_, glm::length(box.hi - box.lo));
    }
  }
  field.indices_ = indices;
  if (around == nullptr) {
    field.own_around_ = TrianglesAround::of_mesh(count, indices);
  } else if (around->vertex_count() != count || around->triangle_count() != corners / 3) {
    return Status::error("FoamField: the triangles around the vertices do not fit the mesh");
  }
  field.shared_around_ = around;
  // update() finds vertices through the triangles: one in none would be left out.
  for (size_t v = 0; v < count; ++v) {
    if (field.around().of(static_cast<uint32_t>(v)).size() == 0) {
      return Status::error("FoamField: vertex " + std::to_string(v) +
                           " is a corner of no triangle");
    }
  }
  *out = std::move(field);
  return Status::success();
}

float FoamField::source_of(size_t v, std::span<const glm::vec3> velocity,
                           const MarginDistances& bank_distance,
                           std::vector<uint32_t>* ring) const {
  const FoamParams& p = params_;
  // The one-ring through the triangles, each neighbour once, ascending.
  ring->clear();
  for (const size_t t : around().of(static_cast<uint32_t>(v))) {
    for (size_t c = 3 * t; c < 3 * t + 3; ++c) {
      if (corner(c) != v) ring->push_back(corner(c));
    }
  }
  std::sort(ring->begin(), ring->end());
  ring->erase(std::unique(ring->begin(), ring->end()), ring->end());
  // Least-squares horizontal velocity gradient over the one-ring: G = (sum du dx^T)(sum dx dx^T)^-1.
  float axx = 0.0f, axz = 0.0f, azz = 0.0f;
  float bxx = 0.0f, bxz = 0.0f, bzx = 0.0f, bzz = 0.0f;
  for (const uint32_t j : *ring) {
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
  const float bank = p.bank_strength * std::exp(-bank_distance(v) / p.bank_width_m) *
                     std::min(section_speed / p.bank_speed_full, 1.0f);
  const float relative_gradient = gradient / std::max(section_speed, p.min_section_speed);
  return std::max({smoothstep(p.gradient_onset, p.gradient_full, relative_gradient),
                   lee * smoothstep(p.deficit_onset, p.deficit_full, deficit), bank});
}

FoamField::Upstream FoamField::upstream_of(size_t v, std::span<const glm::vec3> velocity) const {
  // Where this vertex's water was one step ago: cast down onto the surface there.
  const glm::vec3 back =
      positions_[v] - params_.step_s * glm::vec3(velocity[v].x, 0.0f, velocity[v].z);
  Upstream up;
  RayHit hit;
  if (!bvh_->intersect(back + glm::vec3(0.0f, kRayHeight, 0.0f), {0.0f, -1.0f, 0.0f},
                       2.0f * kRayHeight, &hit)) {
    return up;  // came in over the inlet or a bank: none
  }
  up.triangle = hit.triangle;
  uint32_t from[3];
  for (int c = 0; c < 3; ++c) from[c] = bvh_->triangle_vertex(hit.triangle, c);
  const glm::vec3 b =
      barycentric_xz(back, positions_[from[0]], positions_[from[1]], positions_[from[2]]);
  const float sum = std::max(b.x + b.y + b.z, 1e-6f);
  for (int c = 0; c < 3; ++c) up.weight[c] = b[c] / sum;
  return up;
}

void FoamField::compute(std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
                        std::span<float> foam) {
  const size_t count = positions_.size();
  std::fill(section_speed_.begin(), section_speed_.end(), 0.0f);
  fastest2_ = 0.0f;
  for (size_t v = 0; v < count; ++v) {
    add_speed(v, velocity);
    fastest2_ = std::max(fastest2_, speed2(velocity[v]));
  }
  computed_ = true;
  last_rederived_ = count;
  std::vector<Upstream> upstream(count);
  std::vector<float> source(count);
  std::vector<uint32_t> ring;
  for (size_t v = 0; v < count; ++v) {
    source[v] = source_of(v, velocity, bank_distance, &ring);
    upstream[v] = upstream_of(v, velocity);
  }
  // Steady transport: each step the foam moves one step downstream and decays.
  const float decay = std::exp(-params_.step_s / params_.lifetime_s);
  std::copy(source.begin(), source.end(), foam.begin());
  std::vector<float> next(count);
  for (uint32_t step = 0; step < params_.steps; ++step) {
    for (size_t v = 0; v < count; ++v) {
      const size_t t = upstream[v].triangle;
      next[v] = transported(source[v], decay, upstream[v].weight, foam[corner(3 * t)],
                            foam[corner(3 * t + 1)], foam[corner(3 * t + 2)]);
    }
    std::copy(next.begin(), next.end(), foam.begin());
  }
}

// Why a window suffices: a vertex's foam after n transport steps reads its own source and the
// foam, one step earlier, at the corners of its upstream triangle, which lie within
// hop = step * |velocity| + the longest edge of it. So the foam can change only within n hops of
// a vertex whose source or upstream point changed (those whose velocity or whose neighbours'
// changed, and every vertex of a section whose mean speed changed), and those vertices' foam
// reads nothing farther than n hops more: re-running the n steps on that window, whatever stands
// outside it, gives the inner vertices their exact values.
void FoamField::update(std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
                       std::span<const XzBox> changed, std::span<float> foam) {
  const bool bounded =
      std::all_of(changed.begin(), changed.end(), [](const XzBox& box) { return box.finite(); });
  if (!computed_ || !bounded) {
    compute(velocity, bank_distance, foam);
    return;
  }
  last_rederived_ = 0;
  if (changed.empty()) return;
  const std::vector<XzBox> sources = resum_sections(velocity, changed);
  const double hop =
      double(params_.step_s) * std::sqrt(double(fastest2_)) + longest_edge_ + rounding_;
  const double reach = double(params_.steps) * hop * (1.0 + 1e-6) + 1e-3;  // float rounding
  std::vector<XzBox> changed_foam, window_boxes;
  for (const XzBox& box : sources) {
    changed_foam.push_back(box.widened(reach));
    window_boxes.push_back(box.widened(2.0 * reach));
  }
  const std::vector<uint32_t> window = vertices_in(window_boxes);
  if (2 * window.size() > positions_.size()) {
    compute(velocity, bank_distance, foam);
    return;
  }
  rederive(window, changed_foam, velocity, bank_distance, foam);
}

std::vector<XzBox> FoamField::resum_sections(std::span<const glm::vec3> velocity,
                                             std::span<const XzBox> changed) {
  // About each box, the changed vertices' one-rings, and their sections whole (each section
  // grows the first box that reaches it). The changed vertices lie in the boxes, so the fastest
  // speed is kept up to date from them.
  std::vector<XzBox> sources, sections_reach;
  for (const XzBox& box : changed) {
    sources.push_back(box.widened(longest_edge_));
    sections_reach.push_back(sources.back().widened(widest_section_));
  }
  std::vector<uint32_t> section_box(section_speed_.size(), 0);  // box + 1; 0: unchanged
  for (const uint32_t v : vertices_in(sources)) {
    const uint32_t b = first_holding(sources, positions_[v]);
    if (section_box[section_[v]] == 0) section_box[section_[v]] = b;
    fastest2_ = std::max(fastest2_, speed2(velocity[v]));
  }
  // Every vertex of a section lies within the widest section of any other of its vertices.
  std::vector<uint32_t> resummed = vertices_in(sections_reach);
  std::erase_if(resummed, [&](uint32_t v) { return section_box[section_[v]] == 0; });
  for (const uint32_t v : resummed) section_speed_[section_[v]] = 0.0f;
  for (const uint32_t v : resummed) {  // ascending, as compute() sums them
    add_speed(v, velocity);
    sources[section_box[section_[v]] - 1].grow(positions_[v]);
  }
  return sources;
}

void FoamField::rederive(std::span<const uint32_t> window, std::span<const XzBox> changed_foam,
                         std::span<const glm::vec3> velocity, const MarginDistances& bank_distance,
                         std::span<float> foam) {
  last_rederived_ = window.size();
  // The window's vertices first, then the foam outside it that their upstream corners read
  // (held as it was: only the window's outer steps see it).
  const size_t inner = window.size();
  std::vector<float> source(inner);
  std::vector<Upstream> upstream(inner);
  std::vector<uint32_t> slot(3 * inner);
  std::vector<uint32_t> ring;
  std::vector<uint32_t> outside;  // global vertex of value[inner + k]
  const auto slot_of = [&](uint32_t vertex) {
    const auto at = std::lower_bound(window.begin(), window.end(), vertex);
    if (at != window.end() && *at == vertex) return uint32_t(at - window.begin());
    outside.push_back(vertex);
    return uint32_t(inner + outside.size() - 1);
  };
  for (size_t i = 0; i < inner; ++i) {
    const uint32_t v = window[i];
    source[i] = source_of(v, velocity, bank_distance, &ring);
    upstream[i] = upstream_of(v, velocity);
    const size_t t = upstream[i].triangle;
    for (int c = 0; c < 3; ++c) slot[3 * i + c] = slot_of(corner(3 * t + c));
  }
  std::vector<float> value(inner + outside.size());
  std::copy(source.begin(), source.end(), value.begin());
  for (size_t k = 0; k < outside.size(); ++k) value[inner + k] = foam[outside[k]];
  const float decay = std::exp(-params_.step_s / params_.lifetime_s);
  std::vector<float> next(inner);
  for (uint32_t step = 0; step < params_.steps; ++step) {
    for (size_t i = 0; i < inner; ++i) {
      const uint32_t* s = &slot[3 * i];
      next[i] =
          transported(source[i], decay, upstream[i].weight, value[s[0]], value[s[1]], value[s[2]]);
    }
    std::copy(next.begin(), next.end(), value.begin());
  }
  for (size_t i = 0; i < inner; ++i) {
    if (first_holding(changed_foam, positions_[window[i]]) != 0) foam[window[i]] = value[i];
  }
}

std::vector<uint32_t> FoamField::vertices_in(std::span<const XzBox> boxes) const {
  std::vector<uint32_t> found;
  for (const XzBox& box : boxes) bvh_->append_vertices_in(box, &found);
  // Each once, ascending: a bit a vertex sorts them.
  std::vector<uint64_t> seen((positions_.size() + 63) / 64, 0);
  for (const uint32_t v : found) seen[v / 64] |= uint64_t{1} << (v % 64);
  std::vector<uint32_t> ascending;
  for (size_t word = 0; word < seen.size(); ++word) {
    for (uint64_t bits = seen[word]; bits != 0; bits &= bits - 1) {
      ascending.push_back(uint32_t(64 * word + size_t(std::countr_zero(bits))));
    }
  }
  return ascending;
}

void FoamField::add_speed(size_t v, std::span<const glm::vec3> velocity) {
  section_speed_[section_[v]] +=
      std::hypot(velocity[v].x, velocity[v].z) / float(section_size_[section_[v]]);
}

}  // namespace siviflow
