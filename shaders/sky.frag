#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "sky_common.glsl"

layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = 0) in vec4 in_far_point;
layout(location = 0) out vec4 out_color;

void main() {
  // The far point minus the camera, times w (its sign undone): also a direction when the far
  // point is at infinity (w = 0, an infinite reverse-Z projection).
  vec3 direction = normalize(in_far_point.xyz - scene.camera_position.xyz * in_far_point.w) *
                   (in_far_point.w < 0.0 ? -1.0 : 1.0);
  out_color = vec4(sky_radiance(direction, scene.sun_direction.xyz, scene.sun_direction.w), 1.0);
}
