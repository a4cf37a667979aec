#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"
// Terrain, riverbed, boulders and trees: vertex colours, or the ground's colours from its height
// above the water (SIVIFLOW_GROUND_VERTEX), broken up by a procedural detail texture.

layout(push_constant) uniform Push { SceneConstants scene; };
layout(set = 0, binding = 0) uniform sampler2D ground_detail;
layout(location = 0) in vec4 in_surface;  // scene.vert's
layout(location = 1) in vec4 in_lit;
layout(location = 2) in vec3 in_haze;
layout(location = 0) out vec4 out_color;

const vec3 kRiverbed = vec3(0.30, 0.27, 0.21);
const vec3 kSand = vec3(0.62, 0.55, 0.42);
const vec3 kGrass = vec3(0.13, 0.24, 0.07);
const vec3 kRock = vec3(0.42, 0.40, 0.38);

// The ground's colour at `above` metres above the water: riverbed under it, sand darkened where
// the water wets it, then grass; `rock` of it bare rock. `wobble` (-0.5..0.5) moves the borders
// so they wander as real ones do.
vec3 ground_albedo(float above, float rock, float wobble) {
  float h = above + 0.35 * wobble;
  vec3 c = mix(kRiverbed, kSand, smoothstep(-0.6, 0.05, h));
  c *= mix(0.72, 1.0, smoothstep(0.0, 0.3, h));  // wet sand just above the waterline
  c = mix(c, kGrass, smoothstep(0.5, 0.7, h));
  return mix(c, kRock, rock);
}

void main() {
  // Two scales of the tileable detail texture, in world metres, break up the colours.
  vec2 fine = texture(ground_detail, in_surface.xy * 0.25).rg;
  float coarse = texture(ground_detail, in_surface.xy * 0.031).g;
  float detail = fine.r * 0.6 + coarse * 0.4;
  // (Interpolated, only the ground's w is negative.)
  vec3 base = in_lit.w < 0.0 ? ground_albedo(in_surface.z, in_surface.w, fine.g + coarse - 1.0)
                             : vec3(in_surface.zw, in_lit.w);
  vec3 albedo = base * mix(0.75, 1.25, detail);
  out_color = vec4(shade_scene(albedo, in_lit.rgb, in_haze), 1.0);
}
