#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
// The flow pass's floor, for `siviflow bench`: drawn with the water's geometry, depth test and
// blending into the same colour format (flow.vert), so over the same pixels and written the same
// way, the same texture reads as the water material (1 flow texel fetch, 1 aux fetch, 4 tile
// table fetches, 2 host depth fetches, 1 reflection, 1 refraction and 4 normal-map reads at the
// level of detail their own derivatives give, each scaled by its tile's map transform) and next
// to no arithmetic, so flow / floor tells what the material's own maths costs.
layout(push_constant) uniform Push { FlowConstants flow; };
layout(set = 0, binding = 0) uniform usampler2D flow_texture;
layout(set = 0, binding = 1) uniform sampler2D particle_aux;
layout(set = 0, binding = 2) uniform sampler2D reflection_map;
layout(set = 0, binding = 3) uniform sampler2D normal_map;
layout(set = 0, binding = 4) uniform usampler2D tile_table;
layout(set = 0, binding = 5) uniform sampler2D host_depth;
layout(set = 0, binding = 6) uniform Look { WaterLookConstants look; };
layout(set = 0, binding = 7) uniform sampler2D refraction_map;
layout(location = 0) in vec3 in_world;
layout(location = 0) out vec4 out_value;

void main() {
  vec2 pixel = gl_FragCoord.xy - flow.screen.xy;
  uint slots = texelFetch(flow_texture, ivec2(pixel / flow.water.w), 0).r;
  // The four tiles' texels around the fragment, as the material addresses them, with the map
  // repeats per tile each scales its normal-map read by.
  ivec2 lattice = ivec2(floor(2.0 * in_world.xz / flow.water.z));
  ivec2 wrap = textureSize(tile_table, 0) - 1;
  float scale[4];
  for (int i = 0; i < 4; ++i) {
    uvec4 tile = texelFetch(tile_table, (lattice + ivec2(i & 1, i >> 1)) & wrap, 0);
    slots += tile.r;
    scale[i] = length(uintBitsToFloat(tile.rg));
  }
  vec4 aux = texelFetch(particle_aux, ivec2(int(slots % SIVIFLOW_AUX_WIDTH), 0), 0);
  vec2 uv = pixel * flow.screen.zw;
  vec3 sum = texture(reflection_map, uv).rgb + texelFetch(refraction_map, ivec2(pixel), 0).rgb +
             texelFetch(host_depth, ivec2(gl_FragCoord.xy), 0).r +
             texelFetch(host_depth, min(ivec2(gl_FragCoord.xy) + 1, textureSize(host_depth, 0) - 1), 0).r;
  // Normal-map coordinates scaled as the material's (|M| u), so the reads come from the same
  // mip levels.
  vec2 u = in_world.xz / flow.water.z;
  for (int i = 0; i < 4; ++i) {
    sum += texture(normal_map, u * scale[i] + 0.25 * float(i)).rgb;
  }
  // Every read kept alive, blended over the target like the water.
  out_value = vec4(0.5) + (sum.x + sum.y + sum.z + aux.x + float(slots)) * 1e-6;
}
