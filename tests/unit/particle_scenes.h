// Analytic rivers and cameras for the particle and flow-texture tests and the benchmark: grid
// meshes (flat, tilted, bumpy, jittered), straight channels with uniform flow, and cameras in the
// renderer's conventions (Vulkan clip space, depth 0..1, projection[1][1] *= -1).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "sim/half_float.h"
#include "sim/particles.h"

namespace siviflow::test {

struct GridRiver {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<glm::vec3> flow;
  std::vector<float> speed;
  std::vector<uint16_t> depth;  // binary16, as the river keeps them
  std::vector<uint16_t> slope;
  RiverFlowField field() const { return {positions, indices, flow, speed, depth, slope}; }
};

// nx x nz vertices over [lo, hi] in XZ, row-major along X; each vertex gets height(x, z) and
// flow(x, z); speed |flow|, depth and slope from simple analytic profiles. `jitter` (0..0.45)
// moves interior vertices by up to that fraction of a cell, deterministically.
template <class Height, class Flow>
GridRiver grid_river(uint32_t nx, uint32_t nz, glm::vec2 lo, glm::vec2 hi, Height height, Flow flow,
                     float jitter = 0.0f) {
  GridRiver r;
  const glm::vec2 cell = (hi - lo) / glm::vec2(float(nx - 1), float(nz - 1));
  uint64_t state = 12345;
  const auto rnd = [&state]() {  // in [-1, 1)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>(state >> 40) * 0x1.0p-23f - 1.0f;
  };
  r.positions.reserve(size_t{nx} * nz);
  for (uint32_t j = 0; j < nz; ++j) {
    for (uint32_t i = 0; i < nx; ++i) {
      glm::vec2 p = lo + cell * glm::vec2(float(i), float(j));
      const float jx = rnd(), jz = rnd();
      if (jitter > 0.0f && i > 0 && j > 0 && i + 1 < nx && j + 1 < nz) {
        p += jitter * cell * glm::vec2(jx, jz);
      }
      r.positions.push_back({p.x, height(p.x, p.y), p.y});
      const glm::vec3 f = flow(p.x, p.y);
      r.flow.push_back(f);
      r.speed.push_back(glm::length(f));
      const float across = (p.x - lo.x) / (hi.x - lo.x);
      r.depth.push_back(to_half(2.0f * 4.0f * across * (1.0f - across) + 0.01f * float(j % 7)));
      r.slope.push_back(to_half(0.001f * float(1 + (i + 3 * j) % 5)));
    }
  }
  r.indices.reserve(size_t{nx - 1} * (nz - 1) * 6);
  for (uint32_t j = 0; j + 1 < nz; ++j) {
    for (uint32_t i = 0; i + 1 < nx; ++i) {
      const uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      r.indices.insert(r.indices.end(), {a, c, b, b, c, d});
    }
  }
  return r;
}

// A flat straight channel at y = 0: `width` across X centred on 0, from z = 0 to z = length,
// uniform flow (0, 0, speed).
inline GridRiver straight_channel(float width, float length, uint32_t nx, uint32_t nz,
                                  float speed = 1.0f, float jitter = 0.0f) {
  return grid_river(
      nx, nz, {-0.5f * width, 0.0f}, {0.5f * width, length}, [](float, float) { return 0.0f; },
      [speed](float, float) { return glm::vec3(0.0f, 0.0f, speed); }, jitter);
}

// A flat plane at y = 0 over [-half, half]^2 (a view that is all water).
inline GridRiver plane(float half, uint32_t n, float jitter = 0.0f) {
  return grid_river(
      n, n, {-half, -half}, {half, half}, [](float, float) { return 0.0f; },
      [](float x, float z) { return glm::vec3(0.1f * std::sin(0.3f * z), 0.0f, 1.0f + 0.05f * x); },
      jitter);
}

inline ScreenCamera look_at(glm::vec3 eye, glm::vec3 target, glm::uvec2 viewport,
                            float fov_y_deg = 60.0f, glm::vec3 up = {0.0f, 1.0f, 0.0f},
                            float near_plane = 0.1f, float far_plane = 2000.0f) {
  glm::mat4 projection = glm::perspectiveRH_ZO(
      glm::radians(fov_y_deg), float(viewport.x) / float(viewport.y), near_plane, far_plane);
  projection[1][1] *= -1.0f;
  return {projection * glm::lookAtRH(eye, target, up), viewport};
}

// Looking straight down at (x, 0, z) from `height`, +X to the right of the screen.
inline ScreenCamera top_down(float x, float z, float height, glm::uvec2 viewport,
                             float fov_y_deg = 60.0f) {
  return look_at({x, height, z}, {x, 0.0f, z}, viewport, fov_y_deg, {0.0f, 0.0f, -1.0f});
}

// Screen -> world ray in the test's own arithmetic (not the field's), for oracles.
struct TestRay {
  glm::vec3 origin;
  glm::vec3 direction;  // from the near plane to the far plane (t in [0, 1])
};
class PixelRays {
 public:
  explicit PixelRays(const ScreenCamera& cam)
      : inv_(glm::inverse(glm::dmat4(cam.view_proj))), size_(cam.viewport) {}
  TestRay operator()(glm::vec2 px) const {
    const double nx = 2.0 * px.x / size_.x - 1.0, ny = 2.0 * px.y / size_.y - 1.0;
    const glm::dvec4 a = inv_ * glm::dvec4(nx, ny, 0.0, 1.0), b = inv_ * glm::dvec4(nx, ny, 1.0, 1.0);
    const glm::dvec3 pa = glm::dvec3(a) / a.w, pb = glm::dvec3(b) / b.w;
    return {glm::vec3(pa), glm::vec3(pb - pa)};
  }

 private:
  glm::dmat4 inv_;
  glm::dvec2 size_;
};
inline TestRay pixel_ray(const ScreenCamera& cam, glm::vec2 px) { return PixelRays(cam)(px); }

// Where the ray meets the plane y = h (t in [0, 1]), if it does.
inline bool hit_plane_y(const TestRay& ray, float h, glm::vec3* at) {
  if (ray.direction.y == 0.0f) return false;
  const float t = (h - ray.origin.y) / ray.direction.y;
  if (t < 0.0f || t > 1.0f) return false;
  *at = ray.origin + t * ray.direction;
  return true;
}

}  // namespace siviflow::test
