#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "tdf_tile_table.glsl"
// The flow pass's floor, for `siviflow bench`: drawn with the water's geometry, depth test and
// blending into the same colour format (flow.vert), so over the same pixels and written the same
// way, the same texture reads as the water material (1 flow texel fetch, 1 aux fetch, 4 tile
// table fetches, 2 host depth fetches, 1 reflection, 1 refraction and 4 normal-map reads at an
// explicit level of detail, each tile's offset added) and next to no arithmetic, so flow / floor
// tells what the material's own maths costs.
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
  // The four tiles' texels around the fragment, as the material addresses them, with the level
  // of detail each gives its normal-map read.
  ivec2 lattice = ivec2(floor(2.0 * in_world.xz / flow.water.z));
  ivec2 wrap = textureSize(tile_table, 0) - 1;
  float lod_offset[4];
  for (int i = 0; i < 4; ++i) {
    uvec4 tile = texelFetch(tile_table, (lattice + ivec2(i & 1, i >> 1)) & wrap, 0);
    slots += tile.r;
    lod_offset[i] = unpackHalf2x16(tile.a).y;
  }
  vec4 aux = texelFetch(particle_aux, ivec2(int(slots % SIVIFLOW_AUX_WIDTH), 0), 0);
  vec2 uv = pixel * flow.screen.zw;
  vec3 sum = texture(reflection_map, uv).rgb + texelFetch(refraction_map, ivec2(pixel), 0).rgb +
             texelFetch(host_depth, ivec2(gl_FragCoord.xy), 0).r +
             texelFetch(host_depth, min(ivec2(gl_FragCoord.xy) + 1, textureSize(host_depth, 0) - 1), 0).r;
  // Normal-map coordinates at the material's map scale (its mid-speed scale), at the level of
  // detail the material computes once per fragment, so the reads come from the same mip levels.
  vec2 u = in_world.xz / flow.water.z;
  vec2 tile = u * (0.5 * (kTdfScaleStill + kTdfScaleFast) / look.surface.y);
  vec2 du_dx = dFdx(u);
  vec2 du_dy = dFdy(u);
  float map_size = float(textureSize(normal_map, 0).x);
  float lod_base = 0.5 * log2(max(dot(du_dx, du_dx), dot(du_dy, du_dy)) * map_size * map_size);
  for (int i = 0; i < 4; ++i) {
    sum += textureLod(normal_map, tile + 0.25 * float(i), lod_base + lod_offset[i]).rgb;
  }
  // Every read kept alive, blended over the target like the water.
  out_value = vec4(0.5) + (sum.x + sum.y + sum.z + aux.x + float(slots)) * 1e-6;
}
