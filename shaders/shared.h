// Layouts shared by GLSL and C++. Every struct here crosses the CPU/GPU boundary; the C++ side
// checks sizes and offsets with static_assert (std430 / push-constant rules: vec4 and mat4 only,
// so no implicit padding can differ between the two languages).
#ifndef SIVIFLOW_SHADERS_SHARED_H
#define SIVIFLOW_SHADERS_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
namespace siviflow::gpu {
using mat4 = glm::mat4;
using vec4 = glm::vec4;
using uint = uint32_t;
#endif

// Vertex input locations of the scene pipeline (terrain and objects).
#define SIVIFLOW_ATTR_POSITION 0
#define SIVIFLOW_ATTR_NORMAL 1
#define SIVIFLOW_ATTR_COLOR 2

// Push constants of the sky and scene pipelines: one block for both, 128 bytes (the guaranteed
// minimum of maxPushConstantsSize).
struct SceneConstants {
  mat4 view_proj;           // world -> clip (Vulkan clip space, depth 0..1)
  vec4 camera_position;     // xyz world position, w unused
  vec4 sun_direction;       // xyz unit vector towards the sun, w sun disc intensity
  vec4 clip_plane;          // world-space plane (n, d): gl_ClipDistance = dot(n, p) + d
  vec4 fog;                 // x density per metre, y height falloff, zw unused
};

#ifdef __cplusplus
static_assert(sizeof(SceneConstants) == 128);
static_assert(offsetof(SceneConstants, camera_position) == 64);
static_assert(offsetof(SceneConstants, sun_direction) == 80);
static_assert(offsetof(SceneConstants, clip_plane) == 96);
static_assert(offsetof(SceneConstants, fog) == 112);
}  // namespace siviflow::gpu
#endif

#endif  // SIVIFLOW_SHADERS_SHARED_H
