// River Particle Generator (Algorithm 2) against analytic oracles: the BVH queries, Poisson-disk
// spacing and coverage, temporal stability, surface anchoring, ids, nearest-vertex flow, empty
// and all-water views, fades, advection and determinism whatever frame a run starts from.
#include "sim/particles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "sim/flow_textures.h"
#include "sim/triangle_bvh.h"
#include "siviflow/sim/procedural_river.h"
#include "unit/brute_force_ray.h"
#include "unit/particle_scenes.h"

namespace siviflow {
namespace {

using test::GridRiver;

// A repeatable stream of uniform values in [0, 1): a 64-bit LCG's top 24 bits.
class UnitRandom {
 public:
  explicit UnitRandom(uint64_t seed) : state_(seed) {}
  float next() {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>(state_ >> 40) * 0x1.0p-24f;
  }

 private:
  uint64_t state_;
};

// A 23 x 31 grid river over x [-5, 5], z [0, 20], its surface a sine wave `amplitude` metres high.
GridRiver wavy_grid(float amplitude) {
  return test::grid_river(
      23, 31, {-5.0f, 0.0f}, {5.0f, 20.0f},
      [amplitude](float x, float z) { return amplitude * std::sin(x + z); },
      [](float, float) { return glm::vec3(0.0f, 0.0f, 1.0f); }, 0.4f);
}

constexpr glm::uvec2 kSmall{640u, 360u};
constexpr float kDt = 1.0f / 60.0f;

ParticleField make_field(const GridRiver& river, ParticleParams params = {}) {
  ParticleField field;
  const Status s = ParticleField::create(river.field(), params, &field);
  EXPECT_TRUE(s.ok()) << s.message();
  return field;
}

ParticleParams small_params(uint64_t seed = 7) {
  ParticleParams p;
  p.seed = seed;
  p.viewport = kSmall;
  return p;
}

float screen_distance(const Particle& a, const Particle& b) { return glm::length(a.screen - b.screen); }

// Fails unless every pair of live particles is at least the minimum distance apart.
void expect_min_distance(const ParticleField& field) {
  const auto ps = field.particles();
  const float d = field.min_distance_px();
  size_t violations = 0;
  for (size_t i = 0; i < ps.size(); ++i) {
    if (!ps[i].live()) continue;
    for (size_t j = i + 1; j < ps.size(); ++j) {
      if (ps[j].live() && screen_distance(ps[i], ps[j]) < d) ++violations;
    }
  }
  EXPECT_EQ(violations, 0u) << "live pairs closer than " << d << " px";
}

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
float point_triangle_distance(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + d1 / (d1 - d3) * ab));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + d2 / (d2 - d6) * ac));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return glm::length(p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)));
  }
  const float denom = 1.0f / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// ---------------------------------------------------------------------------------------------
// BVH

TEST(TriangleBvh, RayHitsTheSurfaceAndMissesBesideIt) {
  const GridRiver r = test::straight_channel(10.0f, 50.0f, 11, 51);
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(r.positions, r.indices, &bvh).ok());
  RayHit hit;
  ASSERT_TRUE(bvh.intersect({1.25f, 5.0f, 20.3f}, {0.0f, -10.0f, 0.0f}, 1.0f, &hit));
  EXPECT_NEAR(hit.t, 0.5f, 1e-6f);
  EXPECT_NEAR(hit.position.x, 1.25f, 1e-5f);
  EXPECT_NEAR(hit.position.y, 0.0f, 1e-6f);
  EXPECT_NEAR(hit.position.z, 20.3f, 1e-5f);
  // Beside the channel, above it pointing up, and too short to reach it.
  EXPECT_FALSE(bvh.intersect({6.0f, 5.0f, 20.0f}, {0.0f, -10.0f, 0.0f}, 1.0f, &hit));
  EXPECT_FALSE(bvh.intersect({1.0f, 5.0f, 20.0f}, {0.0f, 10.0f, 0.0f}, 1.0f, &hit));
  EXPECT_FALSE(bvh.intersect({1.0f, 5.0f, 20.0f}, {0.0f, -1.0f, 0.0f}, 4.0f, &hit));
  // A grazing ray along the channel from above hits the first triangle it meets.
  ASSERT_TRUE(bvh.intersect({0.3f, 2.0f, -10.0f}, {0.0f, -2.0f, 40.0f}, 1.0f, &hit));
  EXPECT_NEAR(hit.position.z, 30.0f, 1e-3f);
}

TEST(TriangleBvh, NearestVertexIsTheBruteForceOne) {
  const GridRiver r = wavy_grid(0.2f);
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(r.positions, r.indices, &bvh).ok());
  UnitRandom random(99);
  for (int n = 0; n < 2000; ++n) {
    const float u = random.next();
    const float v = random.next();
    RayHit hit;
    ASSERT_TRUE(bvh.intersect({-4.9f + 9.8f * u, 5.0f, 0.1f + 19.8f * v}, {0.0f, -10.0f, 0.0f},
                              1.0f, &hit));
    const uint32_t got = bvh.nearest_vertex(hit.position, 100.0f, hit.triangle);
    uint32_t want = 0;
    float best = std::numeric_limits<float>::infinity();
    for (uint32_t i = 0; i < r.positions.size(); ++i) {
      const float d2 = distance2(hit.position, r.positions[i]);
      if (d2 < best) {
        best = d2;
        want = i;
      }
    }
    ASSERT_EQ(got, want) << "at " << hit.position.x << ", " << hit.position.z;
    // A tiny radius falls back to the hit triangle's nearest corner.
    const uint32_t near_corner = bvh.nearest_vertex(hit.position, 1e-6f, hit.triangle);
    bool is_corner = false;
    for (int k = 0; k < 3; ++k) is_corner |= bvh.triangle_vertex(hit.triangle, k) == near_corner;
    EXPECT_TRUE(is_corner);
  }
}

// The vertices in an x/z box are the brute-force ones (each at least once), at any height.
TEST(TriangleBvh, VerticesInABoxAreTheBruteForceOnes) {
  const GridRiver r = wavy_grid(3.0f);
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(r.positions, r.indices, &bvh).ok());
  UnitRandom random(7);
  for (int n = 0; n < 500; ++n) {
    const glm::dvec2 a(-6.0 + 12.0 * random.next(), -1.0 + 22.0 * random.next());
    const glm::dvec2 b(a.x + 4.0 * random.next(), a.y + 4.0 * random.next());
    const XzBox box{a, b};
    std::vector<uint32_t> got;
    bvh.append_vertices_in(box, &got);
    std::sort(got.begin(), got.end());
    got.erase(std::unique(got.begin(), got.end()), got.end());
    std::vector<uint32_t> want;
    for (uint32_t i = 0; i < r.positions.size(); ++i) {
      if (box.holds(r.positions[i])) want.push_back(i);
    }
    ASSERT_EQ(got, want) << "box " << a.x << ", " << a.y << " to " << b.x << ", " << b.y;
  }
  std::vector<uint32_t> none;
  bvh.append_vertices_in(XzBox{}, &none);
  EXPECT_TRUE(none.empty());
}

// The closest hit of rays of every slope over a meandering procedural river (whose triangles
// the build sorts on every axis) is the brute-force one: the same triangle (ties: the lower)
// at the same t.
TEST(TriangleBvh, ClosestHitIsTheBruteForceOne) {
  ProceduralRiverParams params;
  params.length = 300.0f;
  params.section_spacing = 2.0f;
  RiverMesh r;
  ASSERT_TRUE(ProceduralRiver(params).generate_mesh(&r).ok());
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(r.positions, r.indices, &bvh).ok());
  UnitRandom random(7);
  const auto next = [&] { return random.next(); };
  int hits = 0;
  for (int n = 0; n < 400; ++n) {
    const glm::vec3& at = r.positions[static_cast<size_t>(next() * float(r.positions.size() - 1))];
    const glm::vec3 origin = at + glm::vec3(8.0f * next() - 4.0f, 3.0f, 8.0f * next() - 4.0f);
    const glm::vec3 direction(4.0f * next() - 2.0f, -1.0f, 4.0f * next() - 2.0f);
    RayHit got, want;
    const bool hit = bvh.intersect(origin, direction, 10.0f, &got);
    ASSERT_EQ(hit, test::brute_force_hit(r.positions, r.indices, origin, direction, 10.0f, &want))
        << n;
    if (!hit) continue;
    ++hits;
    EXPECT_EQ(got.triangle, want.triangle) << n;
    EXPECT_EQ(got.t, want.t) << n;
  }
  EXPECT_GT(hits, 200);
}

TEST(TriangleBvh, AnyHitAgreesWithTheClosestHitOverTheSegment) {
  // A wavy sheet, and segments of every direction: a hit within [t_min, t_max] exists exactly
  // when the closest hit from t_min on lies within t_max.
  const GridRiver r = test::grid_river(
      17, 17, {-5.0f, -5.0f}, {5.0f, 5.0f}, [](float x, float z) { return std::sin(x) * std::cos(z); },
      [](float, float) { return glm::vec3(0.0f, 0.0f, 1.0f); }, 0.4f);
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(r.positions, r.indices, &bvh).ok());
  UnitRandom random(5);
  const auto next = [&random] { return random.next() * 2.0f - 1.0f; };  // [-1, 1)
  int hits = 0, misses = 0;
  for (int n = 0; n < 3000; ++n) {
    const glm::vec3 from(6.0f * next(), 2.0f * next(), 6.0f * next());
    const glm::vec3 to(6.0f * next(), 2.0f * next(), 6.0f * next());
    const float t_min = 0.3f * (next() + 1.0f);
    const glm::vec3 dir = to - from;
    RayHit closest;
    const bool want = bvh.intersect(from + t_min * dir, dir, 1.0f - t_min, &closest);
    ASSERT_EQ(bvh.any_hit(from, dir, t_min, 1.0f), want) << "segment " << n;
    (want ? hits : misses)++;
  }
  EXPECT_GT(hits, 500);
  EXPECT_GT(misses, 500);
}

TEST(TriangleBvh, NonIndexedMeshesAndBadMeshes) {
  const std::vector<glm::vec3> tri = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  TriangleBvh bvh;
  ASSERT_TRUE(TriangleBvh::build(tri, {}, &bvh).ok());
  RayHit hit;
  EXPECT_TRUE(bvh.intersect({0.2f, 1.0f, 0.2f}, {0.0f, -2.0f, 0.0f}, 1.0f, &hit));
  EXPECT_FALSE(TriangleBvh::build({}, {}, &bvh).ok());
  EXPECT_FALSE(TriangleBvh::build(std::span(tri).first(2), {}, &bvh).ok());
  const std::vector<uint32_t> out_of_range = {0, 1, 3};
  const Status s = TriangleBvh::build(tri, out_of_range, &bvh);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("out of range"), std::string::npos) << s.message();
  const std::vector<glm::vec3> nan = {{0, 0, 0}, {1, std::nanf(""), 0}, {0, 0, 1}};
  EXPECT_FALSE(TriangleBvh::build(nan, {}, &bvh).ok());
}

// ---------------------------------------------------------------------------------------------
// Inputs

TEST(Particles, RejectsBadInputs) {
  GridRiver r = test::straight_channel(20.0f, 100.0f, 5, 11);
  ParticleField field;
  RiverFlowField f = r.field();
  f.flow = f.flow.first(3);
  EXPECT_FALSE(ParticleField::create(f, {}, &field).ok());
  f = r.field();
  f.depth = f.depth.first(3);
  EXPECT_FALSE(ParticleField::create(f, {}, &field).ok());
  ParticleParams p;
  p.viewport = {0, 720};
  EXPECT_FALSE(ParticleField::create(r.field(), p, &field).ok());
  p = {};
  p.min_distance_px = 2.0f;  // 1280x720 at 2 px needs far more than 65535 ids
  const Status tiny = ParticleField::create(r.field(), p, &field);
  EXPECT_FALSE(tiny.ok());
  EXPECT_NE(tiny.message().find("65535"), std::string::npos) << tiny.message();
  p = {};
  p.fill_spacing = 0.5f;
  EXPECT_FALSE(ParticleField::create(r.field(), p, &field).ok());
  p = {};
  p.fade_in_seconds = -1.0f;
  EXPECT_FALSE(ParticleField::create(r.field(), p, &field).ok());
  r.speed[4] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(ParticleField::create(r.field(), {}, &field).ok());
}

TEST(Particles, RejectsBadFrames) {
  const GridRiver r = test::straight_channel(20.0f, 100.0f, 5, 11);
  ParticleField field = make_field(r, small_params());
  const ScreenCamera cam = test::look_at({0, 10, -5}, {0, 0, 30}, kSmall);
  ParticleField never_created;
  EXPECT_FALSE(never_created.update(cam, 0, kDt).ok());
  EXPECT_FALSE(field.update(cam, 1, kDt).ok());  // not the next frame
  ScreenCamera wrong = cam;
  wrong.viewport = {1280, 720};
  EXPECT_FALSE(field.update(wrong, 0, kDt).ok());
  ScreenCamera singular = cam;
  singular.view_proj = glm::mat4(0.0f);
  EXPECT_FALSE(field.update(singular, 0, kDt).ok());
  EXPECT_FALSE(field.update(cam, 0, -1.0f).ok());
  EXPECT_TRUE(field.particles().empty());
  ASSERT_TRUE(field.update(cam, 0, kDt).ok());
  EXPECT_EQ(field.next_frame(), 1u);
}

// ---------------------------------------------------------------------------------------------
// Poisson-disk properties

TEST(Particles, LiveParticlesKeepTheMinimumDistance) {
  const GridRiver r = test::straight_channel(40.0f, 300.0f, 21, 151);
  ParticleField field = make_field(r, small_params());
  for (uint64_t f = 0; f < 40; ++f) {
    // Move forward and yaw: perspective compresses and stretches the pattern.
    const float a = 0.01f * static_cast<float>(f);
    const glm::vec3 eye(2.0f * std::sin(a), 10.0f, -5.0f + 0.5f * f);
    ASSERT_TRUE(field.update(test::look_at(eye, eye + glm::vec3(std::sin(3 * a), -0.4f, 1.0f), kSmall),
                             f, kDt).ok());
    expect_min_distance(field);
    if (HasFailure()) return;
  }
  EXPECT_GT(field.stats().live, 100u);
}

// Whether the analytic channel's water is under pixel px.
bool channel_water_at(const test::PixelRays& rays, glm::vec2 px, float half_width, float length) {
  glm::vec3 at;
  if (!test::hit_plane_y(rays(px), 0.0f, &at)) return false;
  return std::fabs(at.x) <= half_width && at.z >= 0.0f && at.z <= length;
}

TEST(Particles, FillCoversTheVisibleWater) {
  const float width = 60.0f, length = 400.0f;
  const GridRiver r = test::straight_channel(width, length, 31, 201);
  ParticleField field = make_field(r, small_params());
  const ScreenCamera cam = test::look_at({5, 12, -8}, {0, 0, 40}, kSmall);
  ASSERT_TRUE(field.update(cam, 0, kDt).ok());
  const float d = field.min_distance_px();
  const test::PixelRays rays(cam);
  // Placement at the fill spacing, re-projected in float: a hair of slack.
  const float allowed = field.cover_radius_px() * 1.0005f;
  const float probe = 1.5f * d;
  size_t checked = 0, uncovered = 0;
  float worst = 0.0f;
  for (float y = 0.5f; y < kSmall.y; y += 3.0f) {
    for (float x = 0.5f; x < kSmall.x; x += 3.0f) {
      const glm::vec2 px(x, y);
      if (!channel_water_at(rays, px, 0.5f * width, length)) continue;
      bool interior = true;  // away from the water's edges (the screen's are covered by the margin)
      for (int k = 0; k < 8 && interior; ++k) {
        const float a = 0.785398f * k;
        interior = channel_water_at(rays, px + probe * glm::vec2(std::cos(a), std::sin(a)),
                                    0.5f * width, length);
      }
      if (!interior) continue;
      ++checked;
      float nearest = std::numeric_limits<float>::infinity();
      for (const Particle& p : field.particles()) {
        if (p.live()) nearest = std::min(nearest, glm::length(p.screen - px));
      }
      worst = std::max(worst, nearest);
      if (nearest > allowed) ++uncovered;
    }
  }
  EXPECT_GT(checked, 5000u);
  EXPECT_EQ(uncovered, 0u) << "worst gap " << worst << " px, cover radius " << field.cover_radius_px();
  expect_min_distance(field);
}

// The largest screen distance from a water pixel inside `region` (x, z bounds on the water
// plane) to the nearest live particle.
float worst_gap_in(const ParticleField& field, const ScreenCamera& camera, glm::vec2 lo, glm::vec2 hi) {
  const test::PixelRays rays(camera);
  float worst = 0.0f;
  for (float y = 0.5f; y < kSmall.y; y += 2.0f) {
    for (float x = 0.5f; x < kSmall.x; x += 2.0f) {
      glm::vec3 at;
      if (!test::hit_plane_y(rays({x, y}), 0.0f, &at) || at.x < lo.x || at.x > hi.x ||
          at.z < lo.y || at.z > hi.y) {
        continue;
      }
      float nearest = std::numeric_limits<float>::infinity();
      for (const Particle& p : field.particles()) {
        if (p.live()) nearest = std::min(nearest, glm::length(p.screen - glm::vec2(x, y)));
      }
      worst = std::max(worst, nearest);
    }
  }
  return worst;
}

TEST(Particles, NoneInsideAnObstaclesFootprintAndTheWaterItLeavesIsCoveredAtOnce) {
  const GridRiver r = test::straight_channel(30.0f, 200.0f, 31, 201);
  ParticleField field = make_field(r, small_params());
  const ScreenCamera cam = test::top_down(0.0f, 30.0f, 25.0f, kSmall);  // still all along
  Obstacle boulder;
  boulder.radius = 3.0f;
  Obstacle hull;  // a polygon, turned
  hull.polygon = {{-1.0f, -4.0f}, {1.0f, -4.0f}, {1.5f, 3.0f}, {-1.5f, 3.0f}};
  const auto inside = [&](const Particle& p, const DryFootprint& d) {
    return footprint_distance(*d.obstacle, d.centre_xz, glm::dvec2(p.world.x, p.world.z)) < 0.0;
  };
  const auto count_inside = [&](std::initializer_list<DryFootprint> dry) {
    size_t n = 0;
    for (const Particle& p : field.particles()) {
      for (const DryFootprint& d : dry) n += p.slot != 0 && inside(p, d) ? 1 : 0;
    }
    return n;
  };
  const DryFootprint here[] = {{&boulder, {-5.0, 30.0}}, {&hull, {6.0, 26.0}}};
  ASSERT_TRUE(field.update(cam, 0, kDt, here).ok());
  EXPECT_GT(field.stats().dry_hits, 0u) << "rays met the river on dry ground";
  uint64_t frame = 1;
  for (; frame < 3; ++frame) ASSERT_TRUE(field.update(cam, frame, kDt, here).ok());
  EXPECT_GT(field.particles().size(), 200u);
  EXPECT_EQ(count_inside({here[0], here[1]}), 0u) << "no particle on dry ground";

  // The boulder rolls 8 m downstream: the next frame none is under its new place, and the water
  // it left is covered as closely as open water (the camera has not moved).
  const DryFootprint moved[] = {{&boulder, {-5.0, 38.0}}, here[1]};
  ASSERT_TRUE(field.update(cam, frame++, kDt, moved).ok());
  EXPECT_GT(field.stats().dry, 0u) << "particles under the new place went";
  EXPECT_EQ(count_inside({moved[0]}), 0u);
  const float left = worst_gap_in(field, cam, {-7.0f, 28.0f}, {-3.0f, 32.0f});
  EXPECT_LE(left, field.cover_radius_px() * 1.0005f) << "the water the boulder left is covered";
  expect_min_distance(field);

  // Without footprints the same water is covered again.
  ASSERT_TRUE(field.update(cam, frame++, kDt, {}).ok());
  EXPECT_LE(worst_gap_in(field, cam, {-7.0f, 35.0f}, {-3.0f, 41.0f}), field.cover_radius_px() * 1.0005f);

  const DryFootprint broken[] = {{nullptr, {0.0, 0.0}}};
  const Status refused = field.update(cam, frame, kDt, broken);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("dry footprint 0"), std::string::npos) << refused.message();
}

TEST(Particles, NoneWhereAnObstacleStandsBetweenTheCameraAndTheWater) {
  // A tall block in the channel seen at a low angle: the water behind it, up to its top, is
  // hidden; a flat footprint of the same shape hides only what it covers.
  const GridRiver r = test::straight_channel(30.0f, 200.0f, 31, 201);
  ParticleField field = make_field(r, small_params());
  const ScreenCamera cam = test::look_at({0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 30.0f}, kSmall);
  Obstacle block;
  block.polygon = {{-3.0f, -1.0f}, {3.0f, -1.0f}, {3.0f, 1.0f}, {-3.0f, 1.0f}};
  block.height = 2.0f;
  const DryFootprint standing[] = {{&block, {0.0, 15.0}, 2.0}};
  // The test's own sight-line check: the eye-to-water segment, below the top, over the block.
  const glm::vec3 eye(0.0f, 3.0f, 0.0f);
  const auto hidden = [&](const Particle& p) {
    for (float t = 0.0f; t <= 1.0f; t += 0.002f) {
      const glm::vec3 q = eye + t * (p.world - eye);
      if (q.y <= 2.0f && std::abs(q.x) < 3.0f && std::abs(q.z - 15.0f) < 1.0f) return true;
    }
    return false;
  };
  ASSERT_TRUE(field.update(cam, 0, kDt, standing).ok());
  EXPECT_GT(field.stats().hidden_hits, 0u) << "rays met the block before the water";
  size_t behind = 0, beside = 0;
  for (const Particle& p : field.particles()) {
    EXPECT_FALSE(hidden(p)) << "particle " << p.id << " at " << p.world.x << ", " << p.world.z;
    behind += p.world.z > 16.0f && std::abs(p.world.x) < 2.0f ? 1 : 0;
    beside += p.world.z > 16.0f && std::abs(p.world.x) > 5.0f ? 1 : 0;
  }
  EXPECT_GT(beside, 20u) << "the water beside the block is seen";
  EXPECT_GT(behind, 0u) << "far behind it, over its top, the water is seen again";

  // The block drops to the water: what it hid is covered again at once, as closely as by a
  // field that never saw it stand.
  const DryFootprint flat[] = {{&block, {0.0, 15.0}}};  // no top: hides nothing
  ASSERT_TRUE(field.update(cam, 1, kDt, flat).ok());
  ParticleField fresh = make_field(r, small_params());
  ASSERT_TRUE(fresh.update(cam, 0, kDt, flat).ok());
  const auto close_behind = [](const ParticleField& f) {
    size_t n = 0;
    for (const Particle& p : f.particles()) {
      n += p.live() && p.world.z > 16.0f && p.world.z < 25.0f && std::abs(p.world.x) < 2.0f;
    }
    return n;
  };
  EXPECT_GT(close_behind(fresh), 5u);
  EXPECT_GE(close_behind(field), close_behind(fresh) * 8 / 10);
}

TEST(Particles, NoneWhereTheOccludersStandBetweenTheCameraAndTheWater) {
  // A wall across the channel (the host's geometry, not an obstacle: it stands on no footprint)
  // seen at a low angle hides the water behind it up to the height of its top.
  const GridRiver r = test::straight_channel(30.0f, 200.0f, 31, 201);
  ParticleField field = make_field(r, small_params());
  const std::vector<glm::vec3> wall = {{-3.0f, -0.5f, 15.0f}, {3.0f, -0.5f, 15.0f},
                                       {3.0f, 2.0f, 15.0f},   {-3.0f, 2.0f, 15.0f}};
  const std::vector<uint32_t> quad = {0, 1, 2, 0, 2, 3};
  auto occluders = std::make_shared<TriangleBvh>();
  ASSERT_TRUE(TriangleBvh::build(wall, quad, occluders.get()).ok());
  // The test's own check: the eye-to-water segment crosses the wall's rectangle (not within
  // the first kSightLineSkipM from the water, which the particles leave out).
  const auto hidden = [](const Particle& p, glm::vec3 eye) {
    const float t = (15.0f - eye.z) / (p.world.z - eye.z);
    const float skip = static_cast<float>(kSightLineSkipM) / glm::length(p.world - eye);
    if (!(t > 0.0f && t < 1.0f - skip)) return false;
    const glm::vec3 q = eye + t * (p.world - eye);
    return std::abs(q.x) < 3.0f && q.y < 2.0f;
  };
  const auto count_hidden = [&](glm::vec3 eye) {
    size_t n = 0;
    for (const Particle& p : field.particles()) n += p.slot != 0 && hidden(p, eye) ? 1 : 0;
    return n;
  };
  glm::vec3 eye(0.0f, 3.0f, 0.0f);
  ScreenCamera cam = test::look_at(eye, {0.0f, 0.0f, 30.0f}, kSmall);
  uint64_t frame = 0;
  for (; frame < 2; ++frame) ASSERT_TRUE(field.update(cam, frame, kDt).ok());
  const size_t hidden_without = count_hidden(eye);
  EXPECT_GT(hidden_without, 20u) << "without occluders the water behind the wall has particles";

  // The wall comes: the next frame, under the same camera, the particles it hides are gone.
  field.set_occluders(occluders);
  ASSERT_TRUE(field.update(cam, frame++, kDt).ok());
  EXPECT_GE(field.stats().dry, hidden_without) << "those the wall hides went";
  EXPECT_EQ(count_hidden(eye), 0u);
  size_t behind = 0, beside = 0;
  for (const Particle& p : field.particles()) {
    behind += p.slot != 0 && p.world.z > 16.0f && std::abs(p.world.x) < 2.0f ? 1 : 0;
    beside += p.slot != 0 && p.world.z > 16.0f && std::abs(p.world.x) > 5.0f ? 1 : 0;
  }
  EXPECT_GT(beside, 20u) << "the water beside the wall is seen";
  EXPECT_GT(behind, 0u) << "far behind it, over its top, the water is seen again";

  // The camera steps aside: new rays meet the wall (no particle is made behind it) and the
  // particles it now hides go at once.
  eye = {2.5f, 2.6f, 1.0f};
  cam = test::look_at(eye, {1.0f, 0.0f, 30.0f}, kSmall);
  ASSERT_TRUE(field.update(cam, frame++, kDt).ok());
  EXPECT_GT(field.stats().hidden_hits, 0u) << "rays met the wall before the water";
  EXPECT_EQ(count_hidden(eye), 0u);

  // The wall goes: the water behind it is covered again.
  field.set_occluders(nullptr);
  ASSERT_TRUE(field.update(cam, frame++, kDt).ok());
  EXPECT_GT(count_hidden(eye), 10u);
}

// Worst distance from an interior water pixel of the channel to the nearest live particle.
float worst_gap(const ParticleField& field, const ScreenCamera& camera, float width, float length) {
  const test::PixelRays cam(camera);
  const float probe = 1.5f * field.min_distance_px();
  float worst = 0.0f;
  for (float y = 0.5f; y < kSmall.y; y += 4.0f) {
    for (float x = 0.5f; x < kSmall.x; x += 4.0f) {
      const glm::vec2 px(x, y);
      if (!channel_water_at(cam, px, 0.5f * width, length)) continue;
      bool inside = true;
      for (int k = 0; k < 8 && inside; ++k) {
        const float a = 0.785398f * k;
        inside = channel_water_at(cam, px + probe * glm::vec2(std::cos(a), std::sin(a)),
                                  0.5f * width, length);
      }
      if (!inside) continue;
      float nearest = std::numeric_limits<float>::infinity();
      for (const Particle& p : field.particles()) {
        if (p.live()) nearest = std::min(nearest, glm::length(p.screen - px));
      }
      worst = std::max(worst, nearest);
    }
  }
  return worst;
}

TEST(Particles, CoverLoosensWhileMovingAndIsExactOnceStill) {
  const float width = 60.0f, length = 400.0f;
  const GridRiver r = test::straight_channel(width, length, 31, 201);
  ParticleField field = make_field(r, small_params());
  const auto cam_at = [](int f) {
    return test::look_at({5.0f + 0.1f * f, 12.0f, -8.0f + 0.25f * f}, {0.2f * f, 0.0f, 40.0f + 0.3f * f},
                         kSmall);
  };
  float worst_moving = 0.0f;
  int f = 0;
  for (; f < 30; ++f) {
    ASSERT_TRUE(field.update(cam_at(f), f, kDt).ok());
    if (f % 10 == 9) worst_moving = std::max(worst_moving, worst_gap(field, cam_at(f), width, length));
    expect_min_distance(field);
  }
  std::printf("moving: worst gap %.3f x min distance\n", worst_moving / field.min_distance_px());
  // Gaps wait for the moving cover (and a staggered recheck) while the camera moves ...
  EXPECT_LT(worst_moving, 1.25f * field.min_distance_px());
  // ... and the first still frame closes them to the exact cover.
  ASSERT_TRUE(field.update(cam_at(f - 1), f, kDt).ok());
  EXPECT_LE(worst_gap(field, cam_at(f - 1), width, length), field.cover_radius_px() * 1.0005f);
  expect_min_distance(field);
}

// The same camera recomputed by another code path (constant folding, FMA, libm) differs by a few
// ulps; that must count as still, or the still frame keeps the moving cover's gaps.
TEST(Particles, StillCameraRecomputedWithRoundingGetsTheExactCover) {
  const float width = 60.0f, length = 400.0f;
  const GridRiver r = test::straight_channel(width, length, 31, 201);
  ParticleField field = make_field(r, small_params());
  const auto cam_at = [](int f) {
    return test::look_at({5.0f + 0.1f * f, 12.0f, -8.0f + 0.25f * f}, {0.2f * f, 0.0f, 40.0f + 0.3f * f},
                         kSmall);
  };
  int f = 0;
  for (; f < 30; ++f) ASSERT_TRUE(field.update(cam_at(f), f, kDt).ok());
  const ScreenCamera still = cam_at(f - 1);
  // Two ulps on most entries, in either direction, alternating frame by frame.
  const auto nudged = [&still](int dir) {
    ScreenCamera c = still;
    for (int i = 0; i < 16; ++i) {
      float& e = c.view_proj[i / 4][i % 4];
      const float to = (i % 3 == 0 ? -dir : dir) * std::numeric_limits<float>::max();
      if (e != 0.0f && i % 5 != 4) e = std::nextafter(std::nextafter(e, to), to);
    }
    return c;
  };
  ASSERT_TRUE(field.update(nudged(1), f++, kDt).ok());
  EXPECT_LE(worst_gap(field, still, width, length), field.cover_radius_px() * 1.0005f);
  expect_min_distance(field);
  // Rounding noise from then on is no motion: no circle is recomputed, nothing born or thinned.
  const std::vector<Particle> settled(field.particles().begin(), field.particles().end());
  for (int k = 0; k < 4; ++k, ++f) {
    ASSERT_TRUE(field.update(k % 2 ? still : nudged(k % 4 == 0 ? -1 : 1), f, kDt).ok());
    EXPECT_EQ(field.stats().born, 0u);
    EXPECT_EQ(field.stats().thinned, 0u);
    EXPECT_LE(field.stats().arc_checks, settled.size() / 20);  // dry-sector rechecks only
  }
  ASSERT_EQ(field.particles().size(), settled.size());
  for (size_t i = 0; i < settled.size(); ++i) EXPECT_EQ(field.particles()[i].id, settled[i].id);
  // A real move, however slow, is still seen once it outgrows the rounding.
  ASSERT_TRUE(field.update(cam_at(f - 1), f, kDt).ok());
  EXPECT_GT(field.stats().arc_checks, 0u);
}

// Screen-space distance from particles to the screen edge, for "interior" checks.
bool interior(const glm::vec2& s, glm::uvec2 vp, float margin) {
  return s.x >= margin && s.y >= margin && s.x <= vp.x - margin && s.y <= vp.y - margin;
}

TEST(Particles, StillCameraKeepsTheSameSet) {
  const GridRiver r = test::straight_channel(60.0f, 400.0f, 31, 201);
  ParticleField field = make_field(r, small_params());
  const ScreenCamera cam = test::look_at({5, 12, -8}, {0, 0, 40}, kSmall);
  ASSERT_TRUE(field.update(cam, 0, kDt).ok());
  const std::vector<Particle> first(field.particles().begin(), field.particles().end());
  ASSERT_GT(first.size(), 300u);
  for (uint64_t f = 1; f < 30; ++f) {
    ASSERT_TRUE(field.update(cam, f, kDt).ok());
    const auto now = field.particles();
    ASSERT_EQ(now.size(), first.size()) << "frame " << f;
    for (size_t i = 0; i < now.size(); ++i) {
      EXPECT_EQ(now[i].id, first[i].id);
      EXPECT_EQ(now[i].slot, first[i].slot);
      EXPECT_EQ(now[i].world, first[i].world);
      EXPECT_EQ(now[i].screen, first[i].screen);
    }
    EXPECT_EQ(field.stats().rays, 0u) << "a still camera casts no ray";
    EXPECT_EQ(field.stats().born + field.stats().thinned + field.stats().culled, 0u);
  }
  for (const Particle& p : field.particles()) EXPECT_EQ(p.state, ParticleState::kActive);
}

// Runs a camera path and returns, for the last frame, whether the particles in the interior of the
// screen were all there at frame 0 (and the reverse); `changed` counts the exceptions.
struct PanResult {
  size_t interior_now = 0;
  size_t new_in_interior = 0;
  size_t lost_from_interior = 0;
};

template <class CameraAt>
PanResult pan(const GridRiver& r, CameraAt camera_at, int frames, float interior_margin) {
  ParticleField field = make_field(r, small_params(3));
  EXPECT_TRUE(field.update(camera_at(0), 0, kDt).ok());
  std::map<uint32_t, glm::vec3> at_start;
  for (const Particle& p : field.particles()) at_start[p.id] = p.world;
  for (int f = 1; f <= frames; ++f) EXPECT_TRUE(field.update(camera_at(f), f, kDt).ok());
  PanResult out;
  std::set<uint32_t> live_now;
  for (const Particle& p : field.particles()) {
    if (!interior(p.screen, kSmall, interior_margin)) continue;
    ++out.interior_now;
    if (!at_start.count(p.id) || !p.live()) ++out.new_in_interior;
    if (p.live()) live_now.insert(p.id);
  }
  // Every frame-0 particle that now projects into the interior must still be there, live.
  const ScreenCamera last = camera_at(frames);
  for (const auto& [id, world] : at_start) {
    const glm::vec4 c = last.view_proj * glm::vec4(world, 1.0f);
    const glm::vec2 s((c.x / c.w * 0.5f + 0.5f) * kSmall.x, (c.y / c.w * 0.5f + 0.5f) * kSmall.y);
    if (c.w > 0 && interior(s, kSmall, interior_margin) && !live_now.count(id)) {
      ++out.lost_from_interior;
    }
  }
  return out;
}

TEST(Particles, SmallPanChangesOnlyParticlesNearTheEdges) {
  const GridRiver r = test::plane(200.0f, 81);
  // Top-down: a pan is a pure screen translation (~5 px a frame).
  const auto camera_at = [](int f) { return test::top_down(0.5f * f, 0.0f, 30.0f, kSmall); };
  const PanResult res = pan(r, camera_at, 6, 3.0f * 12.0f);
  EXPECT_GT(res.interior_now, 200u);
  EXPECT_EQ(res.new_in_interior, 0u);
  EXPECT_EQ(res.lost_from_interior, 0u);
}

TEST(Particles, SmallObliquePanKeepsMostInteriorParticles) {
  const GridRiver r = test::plane(200.0f, 81);
  // Oblique yaw of 0.1 degree a frame: perspective changes screen distances slightly, so a few
  // pairs placed at exactly the spacing are thinned; the rest must stay.
  const auto camera_at = [](int f) {
    const float yaw = glm::radians(0.1f * f);
    return test::look_at({0, 12, -10}, glm::vec3(40.0f * std::sin(yaw), 0.0f, -10.0f + 40.0f * std::cos(yaw)),
                         kSmall);
  };
  const PanResult res = pan(r, camera_at, 6, 3.0f * 12.0f);
  EXPECT_GT(res.interior_now, 200u);
  const double changed = double(res.new_in_interior + res.lost_from_interior) / res.interior_now;
  RecordProperty("changed_fraction", std::to_string(changed));
  std::printf("oblique pan: %zu interior, %zu new, %zu lost\n", res.interior_now,
              res.new_in_interior, res.lost_from_interior);
  EXPECT_LT(changed, 0.1);
}

TEST(Particles, OrthographicAndInfiniteFarProjections) {
  const GridRiver r = test::plane(100.0f, 41);
  // An orthographic camera looking down (w = 1 everywhere) ...
  glm::mat4 ortho = glm::orthoRH_ZO(-30.0f, 30.0f, -17.0f, 17.0f, 0.1f, 100.0f);
  ortho[1][1] *= -1.0f;
  const ScreenCamera top{ortho * glm::lookAtRH(glm::vec3(0, 20, 0), glm::vec3(0, 0, 0), glm::vec3(0, 0, -1)),
                         kSmall};
  // ... and a perspective one with the far plane at infinity (clip w of depth 1 is 0).
  glm::mat4 infinite = glm::perspectiveRH_ZO(glm::radians(60.0f), 16.0f / 9.0f, 0.1f, 100.0f);
  infinite[2][2] = -1.0f;
  infinite[3][2] = -0.1f;
  infinite[1][1] *= -1.0f;
  const ScreenCamera horizon{infinite * glm::lookAtRH(glm::vec3(0, 8, -90), glm::vec3(0, 0, -60),
                                                      glm::vec3(0, 1, 0)),
                             kSmall};
  for (const ScreenCamera& cam : {top, horizon}) {
    ParticleField field = make_field(r, small_params());
    ASSERT_TRUE(field.update(cam, 0, kDt).ok());
    EXPECT_GT(field.particles().size(), 200u);
    for (const Particle& p : field.particles()) EXPECT_NEAR(p.world.y, 0.0f, 1e-4f);
    expect_min_distance(field);
  }
}

// ---------------------------------------------------------------------------------------------
// Anchoring, ids and flow

TEST(Particles, EveryParticleLiesOnTheWaterSurface) {
  const GridRiver r = test::grid_river(
      41, 61, {-20.0f, 0.0f}, {20.0f, 120.0f},
      [](float x, float z) { return 0.6f * std::sin(0.4f * x) * std::cos(0.15f * z) + 0.02f * z; },
      [](float, float) { return glm::vec3(0.0f, 0.0f, 1.0f); }, 0.3f);
  ParticleField field = make_field(r, small_params());
  for (uint64_t f = 0; f < 10; ++f) {
    const glm::vec3 eye(0.0f, 14.0f, -6.0f + 1.0f * f);
    ASSERT_TRUE(field.update(test::look_at(eye, eye + glm::vec3(0.1f, -0.5f, 1.0f), kSmall), f, kDt).ok());
  }
  ASSERT_GT(field.particles().size(), 100u);
  for (const Particle& p : field.particles()) {
    float best = std::numeric_limits<float>::infinity();
    for (size_t t = 0; t < r.indices.size(); t += 3) {
      best = std::min(best, point_triangle_distance(p.world, r.positions[r.indices[t]],
                                                    r.positions[r.indices[t + 1]],
                                                    r.positions[r.indices[t + 2]]));
    }
    EXPECT_LT(best, 1e-4f) << "particle " << p.id;
  }
}

TEST(Particles, IdsAreUniqueAndNeverReused) {
  const GridRiver r = test::straight_channel(40.0f, 300.0f, 21, 151);
  ParticleField field = make_field(r, small_params());
  std::map<uint32_t, glm::vec3> seen;
  uint32_t max_id_before = 0;
  for (uint64_t f = 0; f < 60; ++f) {
    // Forward, then a cut back to the start at frame 30.
    const float z = -5.0f + 2.0f * static_cast<float>(f % 30);
    ASSERT_TRUE(field.update(test::look_at({0, 10, z}, {0, 0, z + 30}, kSmall), f, kDt).ok());
    std::set<uint32_t> ids, slots;
    uint32_t max_id = 0;
    uint32_t previous = 0;
    for (const Particle& p : field.particles()) {
      EXPECT_TRUE(ids.insert(p.id).second) << "id " << p.id << " twice";
      EXPECT_TRUE(slots.insert(p.slot).second) << "slot " << p.slot << " twice";
      EXPECT_GT(p.id, previous) << "particles are in id order";
      EXPECT_GE(p.slot, 1u);
      EXPECT_LE(p.slot, field.slot_count());
      previous = p.id;
      max_id = std::max(max_id, p.id);
      const auto [it, fresh] = seen.emplace(p.id, p.world);
      if (fresh) {
        EXPECT_GT(p.id, max_id_before) << "a new particle reuses an old id";
      } else {
        EXPECT_EQ(it->second, p.world) << "id " << p.id << " moved: it is not the same particle";
      }
    }
    max_id_before = std::max(max_id_before, max_id);
  }
  EXPECT_GT(seen.size(), 1000u);
}

TEST(Particles, FlowIsTheNearestVertexs) {
  GridRiver r = test::grid_river(
      31, 81, {-15.0f, 0.0f}, {15.0f, 160.0f}, [](float, float z) { return 0.01f * z; },
      [](float x, float z) { return glm::vec3(0.05f * x, 0.0f, 1.0f + 0.01f * z); }, 0.4f);
  ParticleParams params = small_params();
  params.vertex_search_radius = 50.0f;
  ParticleField field = make_field(r, params);
  const ScreenCamera cam = test::look_at({0, 12, -6}, {0, 0, 30}, kSmall);
  const auto check = [&]() {
    for (const Particle& p : field.particles()) {
      uint32_t want = 0;
      float best = std::numeric_limits<float>::infinity();
      for (uint32_t i = 0; i < r.positions.size(); ++i) {
        const float d2 = distance2(p.world, r.positions[i]);
        if (d2 < best) {
          best = d2;
          want = i;
        }
      }
      ASSERT_EQ(p.vertex, want) << "particle " << p.id;
      EXPECT_EQ(p.flow, r.flow[want]);
      EXPECT_EQ(p.speed, r.speed[want]);
      EXPECT_EQ(p.depth, from_half(r.depth[want]));
      EXPECT_EQ(p.slope, from_half(r.slope[want]));
    }
  };
  ASSERT_TRUE(field.update(cam, 0, kDt).ok());
  ASSERT_GT(field.particles().size(), 100u);
  check();
  // A re-solved flow (say an obstacle moved) reaches the particles the next frame.
  for (glm::vec3& f : r.flow) f = glm::vec3(f.z, 0.0f, -f.x);
  for (float& s : r.speed) s *= 2.0f;
  ASSERT_TRUE(field.update(cam, 1, kDt).ok());
  check();
}

TEST(Particles, EmptySpeedDepthSlopeAreDerived) {
  GridRiver r = test::straight_channel(40.0f, 300.0f, 11, 61, 2.5f);
  RiverFlowField f = r.field();
  f.speed = {};
  f.depth = {};
  f.slope = {};
  ParticleField field;
  ASSERT_TRUE(ParticleField::create(f, small_params(), &field).ok());
  ASSERT_TRUE(field.update(test::look_at({0, 10, -5}, {0, 0, 30}, kSmall), 0, kDt).ok());
  ASSERT_FALSE(field.particles().empty());
  for (const Particle& p : field.particles()) {
    EXPECT_FLOAT_EQ(p.speed, 2.5f);
    EXPECT_EQ(p.depth, 0.0f);
    EXPECT_EQ(p.slope, 0.0f);
  }
}

// ---------------------------------------------------------------------------------------------
// Degenerate views

TEST(Particles, NoWaterInViewGivesNoParticles) {
  const GridRiver r = test::straight_channel(20.0f, 100.0f, 11, 51);
  ParticleField field = make_field(r, small_params());
  // Looking at the sky, then at land beside the river, then with the river behind the camera.
  const ScreenCamera views[] = {
      test::look_at({0, 5, -10}, {0, 40, 0}, kSmall),
      test::look_at({200, 20, 50}, {300, 0, 50}, kSmall),
      test::look_at({0, 5, -10}, {0, 2, -40}, kSmall),
  };
  uint64_t f = 0;
  for (const ScreenCamera& v : views) {
    for (int k = 0; k < 3; ++k, ++f) {
      ASSERT_TRUE(field.update(v, f, kDt).ok());
      EXPECT_TRUE(field.particles().empty());
      // Bounded work: at most one seed ray per cell of the grid.
      EXPECT_LE(field.stats().rays, field.stats().seed_tests);
    }
  }
}

TEST(Particles, AllWaterViewStaysBounded) {
  const GridRiver r = test::plane(500.0f, 101);
  ParticleField field = make_field(r, small_params());
  const float d = field.min_distance_px();
  for (uint64_t f = 0; f < 30; ++f) {
    ASSERT_TRUE(field.update(test::top_down(0.3f * f, 0.2f * f, 40.0f, kSmall), f, kDt).ok());
    // Live particles are >= d apart in the culled region [-2d, W + 2d] x [-2d, H + 2d].
    const double a = kSmall.x + 5.0 * d, b = kSmall.y + 5.0 * d;
    EXPECT_LE(field.stats().live, a * b * 2.0 / std::sqrt(3.0) / (d * d));
    EXPECT_LE(field.particles().size(), field.slot_count());
  }
  // And the screen is covered: at least the count of a loose packing of the viewport.
  EXPECT_GT(field.stats().live, 0.5 * kSmall.x * kSmall.y / (4.0 * d * d));
}

// Automatic spacing on tiny, odd and very wide outputs: at least 1 px and within the 16-bit ids.
TEST(Particles, AutomaticSpacingFitsTinyAndVeryWideOutputs) {
  const GridRiver r = test::plane(200.0f, 41);
  const glm::uvec2 sizes[] = {{64u, 16u}, {16u, 16u}, {1u, 1u}, {8192u, 200u}};
  for (const glm::uvec2 vp : sizes) {
    SCOPED_TRACE(std::to_string(vp.x) + "x" + std::to_string(vp.y));
    ParticleParams params;
    params.seed = 3;
    params.viewport = vp;
    ParticleField field;
    const Status s = ParticleField::create(r.field(), params, &field);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_GE(field.min_distance_px(), 1.0f);
    EXPECT_LE(field.slot_count(), kMaxParticleSlots);
    for (uint64_t f = 0; f < 4; ++f) {
      ASSERT_TRUE(field.update(test::top_down(0.5f * f, 0.0f, 40.0f, vp), f, kDt).ok());
      std::set<uint16_t> slots;
      uint32_t last_id = 0;
      for (const Particle& p : field.particles()) {
        EXPECT_GT(p.id, last_id);  // unique, in id order
        last_id = p.id;
        EXPECT_GE(p.slot, 1u);
        EXPECT_LE(p.slot, field.slot_count());
        EXPECT_TRUE(slots.insert(p.slot).second) << "slot " << p.slot << " used twice";
      }
    }
    expect_min_distance(field);
    EXPECT_GT(field.stats().live, 0u);  // the plane fills every one of these views
    FlowTextures textures;
    ASSERT_TRUE(FlowTextures::create(field, kDefaultFlowTexelPx, &textures).ok());
    std::vector<std::byte> staging(textures.layout().total_bytes);
    const Status packed = textures.pack(field, staging);
    EXPECT_TRUE(packed.ok()) << packed.message();
  }
  // The default scale is unchanged where it fits.
  ParticleField hd;
  ASSERT_TRUE(ParticleField::create(r.field(), ParticleParams{}, &hd).ok());
  EXPECT_EQ(hd.min_distance_px(), kDefaultMinDistancePx * 720.0f / kDefaultMinDistanceHeight);
  // The wide output needs a wider spacing than the height alone gives.
  ParticleParams wide;
  wide.viewport = {8192u, 200u};
  ParticleField w;
  ASSERT_TRUE(ParticleField::create(r.field(), wide, &w).ok());
  EXPECT_GT(w.min_distance_px(), kDefaultMinDistancePx * 200.0f / kDefaultMinDistanceHeight);
  // An explicit spacing that cannot work is still refused, with the reason.
  ParticleParams explicit_small;
  explicit_small.viewport = {64u, 16u};
  explicit_small.min_distance_px = 0.5f;
  const Status sub_pixel = ParticleField::create(r.field(), explicit_small, &w);
  EXPECT_NE(sub_pixel.message().find("below 1 pixel"), std::string::npos) << sub_pixel.message();
  wide.min_distance_px = 2.0f;
  const Status too_many = ParticleField::create(r.field(), wide, &w);
  EXPECT_NE(too_many.message().find("65535"), std::string::npos) << too_many.message();
}

TEST(Particles, SeedsWaterNotConnectedOnScreen) {
  // Two parallel channels 30 m apart with land between: both get particles in the first frame,
  // and a third one entering the view during a pan gets particles before it is on screen.
  GridRiver a = test::straight_channel(10.0f, 400.0f, 6, 101);
  const auto add = [&a](float dx) {
    const GridRiver b = test::straight_channel(10.0f, 400.0f, 6, 101);
    const uint32_t base = static_cast<uint32_t>(a.positions.size());
    for (glm::vec3 p : b.positions) a.positions.push_back(p + glm::vec3(dx, 0, 0));
    for (uint32_t i : b.indices) a.indices.push_back(base + i);
    a.flow.insert(a.flow.end(), b.flow.begin(), b.flow.end());
    a.speed.insert(a.speed.end(), b.speed.begin(), b.speed.end());
    a.depth.insert(a.depth.end(), b.depth.begin(), b.depth.end());
    a.slope.insert(a.slope.end(), b.slope.begin(), b.slope.end());
  };
  add(30.0f);
  add(90.0f);
  ParticleField field = make_field(a, small_params());
  const auto count_near = [&field](float x0, float x1) {
    size_t n = 0;
    for (const Particle& p : field.particles()) n += p.world.x >= x0 && p.world.x <= x1;
    return n;
  };
  ASSERT_TRUE(field.update(test::top_down(15.0f, 100.0f, 40.0f, kSmall), 0, kDt).ok());
  EXPECT_GT(count_near(-5, 5), 20u);
  EXPECT_GT(count_near(25, 35), 20u);
  EXPECT_EQ(count_near(85, 95), 0u);
  // Pan right 1 m a frame until the third channel shows 2 m inside the right edge.
  const float half_view = 40.0f * std::tan(glm::radians(30.0f)) * kSmall.x / kSmall.y;
  uint64_t f = 1;
  for (; f < 100; ++f) {
    const float x = 15.0f + 1.0f * f;
    ASSERT_TRUE(field.update(test::top_down(x, 100.0f, 40.0f, kSmall), f, kDt).ok());
    if (x + half_view > 85.0f + 2.0f) break;
  }
  EXPECT_GT(count_near(85, 95), 5u) << "frame " << f;
}

// ---------------------------------------------------------------------------------------------
// Life cycle

TEST(Particles, RemovedParticlesFadeOutAndNewOnesFadeIn) {
  const GridRiver r = test::plane(300.0f, 61);
  ParticleParams params = small_params();
  params.fade_in_seconds = 0.1f;
  params.fade_out_seconds = 0.1f;
  ParticleField field = make_field(r, params);
  std::map<uint32_t, Particle> last;
  size_t fading_out_seen = 0, fade_ins_completed = 0;
  for (uint64_t f = 0; f < 40; ++f) {
    // Climb: the pattern shrinks on screen, so particles are thinned.
    ASSERT_TRUE(field.update(test::top_down(0.0f, 0.0f, 20.0f + 0.5f * f, kSmall), f, 0.02f).ok());
    if (f % 5 == 0) expect_min_distance(field);
    std::map<uint32_t, Particle> now;
    for (const Particle& p : field.particles()) {
      now[p.id] = p;
      const auto it = last.find(p.id);
      if (it == last.end()) {
        if (f > 0) {
          EXPECT_EQ(p.state, ParticleState::kFadingIn);
          EXPECT_EQ(p.fade, 0.0f);
        }
        continue;
      }
      const Particle& before = it->second;
      if (p.state == ParticleState::kFadingOut) {
        ++fading_out_seen;
        // Fading out continues from where the fade was (a fading-in one first steps up).
        if (before.state == ParticleState::kFadingOut) {
          EXPECT_LT(p.fade, before.fade);
        }
      }
      if (before.state == ParticleState::kFadingIn && p.state == ParticleState::kActive) {
        ++fade_ins_completed;
        EXPECT_EQ(p.fade, 1.0f);
      }
    }
    // A particle that vanished had faded out, or left the culled region.
    for (const auto& [id, p] : last) {
      if (now.count(id)) continue;
      const bool faded = p.state == ParticleState::kFadingOut && p.fade <= 0.2f + 1e-5f;
      EXPECT_TRUE(faded || field.stats().culled > 0) << "particle " << id << " popped";
    }
    last = std::move(now);
  }
  EXPECT_GT(fading_out_seen, 50u);
  EXPECT_GT(fade_ins_completed, 50u);
}

TEST(Particles, AdvectionCarriesParticlesAlongTheFlow) {
  const GridRiver r = test::straight_channel(200.0f, 400.0f, 21, 41, 2.0f);
  ParticleParams params = small_params();
  params.advect = true;
  ParticleField field = make_field(r, params);
  const ScreenCamera cam = test::top_down(0.0f, 100.0f, 40.0f, kSmall);
  ASSERT_TRUE(field.update(cam, 0, 0.1f).ok());
  std::map<uint32_t, glm::vec3> start;
  for (const Particle& p : field.particles()) start[p.id] = p.world;
  ASSERT_TRUE(field.update(cam, 1, 0.1f).ok());
  size_t moved = 0;
  for (const Particle& p : field.particles()) {
    const auto it = start.find(p.id);
    if (it == start.end()) continue;
    EXPECT_NEAR(p.world.z - it->second.z, 0.2f, 1e-4f);
    EXPECT_NEAR(p.world.x, it->second.x, 1e-4f);
    EXPECT_NEAR(p.world.y, 0.0f, 1e-5f);
    ++moved;
  }
  EXPECT_GT(moved, 100u);
  expect_min_distance(field);
}

// ---------------------------------------------------------------------------------------------
// Determinism

ScreenCamera path(uint64_t f) {
  const float t = static_cast<float>(f);
  const glm::vec3 eye(3.0f * std::sin(0.05f * t), 10.0f + 0.05f * t, -5.0f + 0.8f * t);
  return test::look_at(eye, eye + glm::vec3(0.3f * std::sin(0.11f * t), -0.4f, 1.0f), kSmall);
}

bool same(const Particle& a, const Particle& b) {
  return a.id == b.id && a.slot == b.slot && a.state == b.state && a.fade == b.fade &&
         a.world == b.world && a.screen == b.screen && a.vertex == b.vertex && a.flow == b.flow &&
         a.speed == b.speed && a.depth == b.depth && a.slope == b.slope;
}

TEST(Particles, DeterministicWhateverFrameTheRunStartsFrom) {
  const GridRiver r = test::straight_channel(40.0f, 400.0f, 21, 201, 1.0f, 0.3f);
  const GridRiver copy = r;  // a separately built river and BVH: no shared state
  constexpr uint64_t kStart = 17, kEnd = 45;

  // Run A: frames 0..kEnd, packing the flow textures every frame (packing must not matter).
  ParticleField a = make_field(r, small_params(11));
  FlowTextures textures;
  ASSERT_TRUE(FlowTextures::create(a, 4, &textures).ok());
  std::vector<std::byte> staging(textures.layout().total_bytes);
  std::vector<std::vector<Particle>> frames_a;
  for (uint64_t f = 0; f <= kEnd; ++f) {
    ASSERT_TRUE(a.update(path(f), f, kDt).ok());
    ASSERT_TRUE(textures.pack(a, staging).ok());
    frames_a.emplace_back(a.particles().begin(), a.particles().end());
  }
  // Run B: a capture starting at kStart advances the simulation without rendering first.
  ParticleField b = make_field(copy, small_params(11));
  for (uint64_t f = 0; f < kStart; ++f) ASSERT_TRUE(b.update(path(f), f, kDt).ok());
  for (uint64_t f = kStart; f <= kEnd; ++f) {
    ASSERT_TRUE(b.update(path(f), f, kDt).ok());
    const auto pb = b.particles();
    const auto& pa = frames_a[f];
    ASSERT_EQ(pb.size(), pa.size()) << "frame " << f;
    for (size_t i = 0; i < pa.size(); ++i) ASSERT_TRUE(same(pa[i], pb[i])) << "frame " << f << " #" << i;
  }
  // reset() replays identically; another seed gives another pattern.
  b.reset();
  for (uint64_t f = 0; f <= 5; ++f) ASSERT_TRUE(b.update(path(f), f, kDt).ok());
  ASSERT_EQ(b.particles().size(), frames_a[5].size());
  for (size_t i = 0; i < frames_a[5].size(); ++i) EXPECT_TRUE(same(frames_a[5][i], b.particles()[i]));
  ParticleField c = make_field(r, small_params(12));
  ASSERT_TRUE(c.update(path(0), 0, kDt).ok());
  bool differs = c.particles().size() != frames_a[0].size();
  for (size_t i = 0; !differs && i < frames_a[0].size(); ++i) differs = !same(frames_a[0][i], c.particles()[i]);
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace siviflow
