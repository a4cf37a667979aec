#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"
// Terrain and riverbed: vertex colours broken up by a procedural detail texture.

layout(push_constant) uniform Push { SceneConstants scene; };
layout(set = 0, binding = 0) uniform sampler2D ground_detail;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_irradiance;
layout(location = 2) in vec4 in_color;
layout(location = 4) in vec4 in_fog;
layout(location = 0) out vec4 out_color;

void main() {
  // Two scales of the tileable detail texture, in world metres, break up the vertex colours.
  float detail = texture(ground_detail, in_world.xz * 0.25).r * 0.6 +
                 texture(ground_detail, in_world.xz * 0.031).g * 0.4;
  vec3 albedo = in_color.rgb * mix(0.75, 1.25, detail);
  out_color = vec4(shade_scene(albedo, in_irradiance, in_fog), 1.0);
}
