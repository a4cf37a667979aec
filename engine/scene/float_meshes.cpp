#include "scene/float_meshes.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

namespace siviflow {
namespace {

constexpr glm::vec3 kBark(0.22f, 0.15f, 0.09f);
constexpr glm::vec3 kHeartwood(0.62f, 0.47f, 0.30f);
constexpr float kLogThickness = 0.15f;  // of its half length: a 1.2 m log 18 cm thick
constexpr float kLogAfloat = 0.35f;     // of its thickness: its axis above the water
constexpr float kLeafWidth = 0.42f;     // half width, of its half length
constexpr float kLeafCurl = 0.12f;      // how far its edges rise, of its half width
constexpr float kLeafAfloat = 0.004f;   // metres above the water: drawn over it, not in it

uint32_t next_vertex(const SceneGeometry& g) { return static_cast<uint32_t>(g.vertices.size()); }

// A knobbly cylinder along x with flat cut ends.
void add_log(float radius, float seed, SceneGeometry* g) {
  constexpr int kSegments = 12;
  constexpr int kRings = 8;
  const float thickness = kLogThickness * radius;
  const float lift = kLogAfloat * thickness;
  const auto ring_radius = [&](int ring, float phi) {
    return thickness * (1.0f + 0.08f * std::sin(2.3f * ring + 3.0f * phi + seed));
  };
  const uint32_t base = next_vertex(*g);
  for (int ring = 0; ring <= kRings; ++ring) {
    const float x = -radius + 2.0f * radius * static_cast<float>(ring) / kRings;
    for (int seg = 0; seg <= kSegments; ++seg) {
      const float phi = glm::two_pi<float>() * static_cast<float>(seg) / kSegments;
      const glm::vec3 radial(0.0f, std::cos(phi), std::sin(phi));
      const float occlusion = 0.6f + 0.4f * (radial.y * 0.5f + 0.5f);
      g->vertices.push_back({glm::vec3(x, lift, 0.0f) + radial * ring_radius(ring, phi), radial,
                             glm::vec4(kBark, occlusion)});
    }
  }
  for (uint32_t ring = 0; ring < kRings; ++ring) {
    for (uint32_t seg = 0; seg < kSegments; ++seg) {
      const uint32_t a = base + ring * (kSegments + 1) + seg;
      const uint32_t c = a + kSegments + 1;
      g->indices.insert(g->indices.end(), {a, c, a + 1, a + 1, c, c + 1});
    }
  }
  // The cut ends: a fan of the end ring's points round the axis, pale heartwood.
  for (int end = 0; end < 2; ++end) {
    const int ring = end == 0 ? 0 : kRings;
    const float side = end == 0 ? -1.0f : 1.0f;
    const glm::vec3 normal(side, 0.0f, 0.0f);
    const uint32_t centre = next_vertex(*g);
    g->vertices.push_back({glm::vec3(side * radius, lift, 0.0f), normal, glm::vec4(kHeartwood, 1.0f)});
    for (int seg = 0; seg <= kSegments; ++seg) {
      const glm::vec3 rim = g->vertices[base + ring * (kSegments + 1) + seg].position;
      g->vertices.push_back({rim, normal, glm::vec4(kHeartwood * 0.8f, 0.9f)});
    }
    for (uint32_t seg = 0; seg < kSegments; ++seg) {
      const uint32_t a = centre + 1 + seg;
      if (end == 0) {
        g->indices.insert(g->indices.end(), {centre, a + 1, a});
      } else {
        g->indices.insert(g->indices.end(), {centre, a, a + 1});
      }
    }
  }
}

// A pointed oval along x with a midrib, its edges curled up, lying on the water.
void add_leaf(float radius, float seed, SceneGeometry* g) {
  constexpr int kAlong = 10;
  constexpr int kAcross = 4;  // each side of the midrib
  // Autumn: from orange to red by the seed.
  const float hue = 0.5f + 0.5f * std::sin(seed * 1.7f);
  const glm::vec3 colour = glm::mix(glm::vec3(0.62f, 0.30f, 0.05f), glm::vec3(0.50f, 0.10f, 0.04f), hue);
  const float half_width = kLeafWidth * radius;
  const uint32_t base = next_vertex(*g);
  for (int i = 0; i <= kAlong; ++i) {
    const float u = static_cast<float>(i) / kAlong;  // 0 stem .. 1 tip
    const float x = -radius + 2.0f * radius * u;
    const float width = half_width * std::pow(std::max(0.0f, std::sin(glm::pi<float>() * u)), 0.8f);
    for (int j = -kAcross; j <= kAcross; ++j) {
      const float v = static_cast<float>(j) / kAcross;  // -1 .. 1 across
      const float z = width * v;
      const float y = kLeafAfloat + kLeafCurl * half_width * v * v;
      // The curl's slope tilts the normal across; the midrib darkens.
      const glm::vec3 normal = glm::normalize(glm::vec3(0.0f, 1.0f, -2.0f * kLeafCurl * v));
      const float rib = std::abs(v) < 0.13f ? 0.75f : 1.0f;
      g->vertices.push_back({glm::vec3(x, y, z), normal, glm::vec4(colour * rib, 1.0f)});
    }
  }
  constexpr uint32_t kRow = 2 * kAcross + 1;
  for (uint32_t i = 0; i < kAlong; ++i) {
    for (uint32_t j = 0; j + 1 < kRow; ++j) {
      const uint32_t a = base + i * kRow + j;
      const uint32_t c = a + kRow;
      g->indices.insert(g->indices.end(), {a, a + 1, c, a + 1, c + 1, c});
    }
  }
}

}  // namespace

glm::vec3 float_reach(FloatMesh mesh, float radius) {
  if (mesh == FloatMesh::kLog) {
    const float thickness = kLogThickness * radius;
    return {radius, (1.0f + kLogAfloat) * thickness, radius};
  }
  return {radius, kLeafCurl * kLeafWidth * radius + kLeafAfloat, radius};
}

IndexRange add_float_mesh(FloatMesh mesh, float radius, float seed, SceneGeometry* geometry) {
  const auto first = static_cast<uint32_t>(geometry->indices.size());
  if (mesh == FloatMesh::kLog) {
    add_log(radius, seed, geometry);
  } else {
    add_leaf(radius, seed, geometry);
  }
  return {first, static_cast<uint32_t>(geometry->indices.size()) - first};
}

}  // namespace siviflow
