#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "sky_common.glsl"

layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = 0) in vec2 in_ndc;
layout(location = 0) out vec4 out_color;

void main() {
  // Unproject the far-plane point of this pixel to get the world-space view direction.
  vec4 world = inverse(scene.view_proj) * vec4(in_ndc, 1.0, 1.0);
  vec3 direction = normalize(world.xyz / world.w - scene.camera_position.xyz);
  out_color = vec4(sky_radiance(direction, scene.sun_direction.xyz, scene.sun_direction.w), 1.0);
}
