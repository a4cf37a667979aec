#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
// The flow pass's floor, for `siviflow bench`: drawn with the water's geometry and depth test
// (flow.vert), so over the same pixels, the same texture reads as the water material (5 flow
// texel fetches, 1 aux fetch, 1 reflection and 4 normal-map reads with gradients) and next to no
// arithmetic, so flow / floor tells what the material's own maths costs.
layout(push_constant) uniform Push { FlowConstants flow; };
layout(set = 0, binding = 0) uniform usampler2D flow_texture;
layout(set = 0, binding = 1) uniform sampler2D particle_aux;
layout(set = 0, binding = 2) uniform sampler2D reflection_map;
layout(set = 0, binding = 3) uniform sampler2D normal_map;
layout(location = 0) in vec3 in_world;
layout(location = 1) in float in_depth;
layout(location = 0) out float out_value;

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy / flow.water.w);
  uint slots = 0u;
  ivec2 last = textureSize(flow_texture, 0) - 1;
  for (int i = 0; i < 5; ++i) {
    slots += texelFetch(flow_texture, clamp(texel + ivec2(i & 1, i >> 1), ivec2(0), last), 0).r;
  }
  vec4 aux = texelFetch(particle_aux, ivec2(int(slots % SIVIFLOW_AUX_WIDTH), 0), 0);
  vec2 uv = gl_FragCoord.xy * flow.screen.zw;
  vec3 sum = texture(reflection_map, uv).rgb;
  // Tile coordinates in world metres, with the world position's gradients, as the material.
  vec2 tile = in_world.xz / flow.water.z;
  vec2 dx = dFdx(tile);
  vec2 dy = dFdy(tile);
  for (int i = 0; i < 4; ++i) sum += textureGrad(normal_map, tile + 0.25 * float(i), dx, dy).rgb;
  out_value = (sum.x + sum.y + sum.z + aux.x + float(slots) + in_depth) * 1e-6;  // keeps every read alive
}
