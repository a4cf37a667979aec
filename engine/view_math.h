// The maths of a host's view, pure and without a device: what the water needs to know of the
// host's projection (its depth convention, how to turn two depths of one pixel into a distance)
// and the mirrored view of the reflection.
#pragma once

#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "siviflow/status.h"

namespace siviflow {

struct ViewMath {
  glm::mat4 view_proj{1.0f};
  glm::vec3 camera_position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // world direction the view looks along (its -Z axis)
  // Near maps to depth 1 and far to 0: depth tests use GREATER_OR_EQUAL, cleared depth is 0.
  bool reverse_z = false;
  // P[2][2] / P[2][3]: along one pixel's ray, view distances are in the ratio of
  // (depth - depth_ratio_constant) between two depths (see derive_view_math).
  float depth_ratio_constant = 0.0f;
};

// Checks that `projection` is a finite perspective projection (clip w = +-view z, depth a
// function of view z alone) and `view` a finite invertible matrix, and derives the rest. Errors
// name the matrix and what is wrong with it.
Status derive_view_math(const glm::mat4& view, const glm::mat4& projection, ViewMath* out);

// `m` (a projection or view-projection into Vulkan clip space) with its image moved by `pixels`
// on a viewport of `size` pixels (x right, y down): a clip-space shift of 2 pixels / size per
// unit of clip w. A TAA jitter is put in with +jitter and taken out with -jitter.
glm::mat4 shifted_by_pixels(const glm::mat4& m, glm::vec2 pixels, glm::vec2 size);

// The far value of window depth under the convention.
inline float far_depth(bool reverse_z) { return reverse_z ? 0.0f : 1.0f; }

// Whether, under `view` and the perspective `projection` (as derive_view_math takes them), a
// triangle seen from its outside (its corners counter-clockwise about its right-handed normal,
// towards the camera) lands clockwise in Vulkan's framebuffer (x right, y down): the front face
// that culls what is seen from inside. From the matrices' signs alone, so exact at any distance
// from the origin: a mirrored view or a flipped axis lands the other way, the depth convention
// and an off-centre or jittered projection do not change it.
bool outside_lands_clockwise(const glm::mat4& view, const glm::mat4& projection);

// The view mirrored about the horizontal plane y = height, and the camera mirrored with it.
glm::mat4 mirrored_view_proj(const glm::mat4& view_proj, float height);
glm::vec3 mirrored_point(const glm::vec3& point, float height);

}  // namespace siviflow
