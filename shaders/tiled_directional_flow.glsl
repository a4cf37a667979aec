// Tiled Directional Flow (van Hoesel 2010; algorithms.md §2.1), fed by SiViFlow's screen-space
// flow texture (algorithms.md §2.2 option (a): the flow texture is the flow map).
//
// Design. The tiles live on the river surface in world space: tile coordinates are world x/z
// divided by the tile size, so they do not swim when the camera moves. Each of the four grids
// (offsets (0,0), (.5,0), (0,.5), (.5,.5) tiles) reads ONE flow per tile, at the tile centre.
// All tile centres lie on a lattice of half-tile spacing (shared.h, the tile table), so the work
// is split in two:
//   - per frame, per lattice point (flow_tiles.comp; tdf_encode_tile in tdf_tile_table.glsl):
//     the centre, at the water's height there, is projected with view_proj to a pixel and the
//     flow texel under it is read; if it holds no particle (off screen, behind the camera, on
//     land, occluded) the nearest of the eight lattice neighbours that has one gives the flow,
//     else the water is still. From the flow: a rotation-plus-scale M, the scroll phase and a
//     hashed offset, stored in the table.
//   - per water fragment (tdf_normal): for each grid, its tile's table texel, one normal-map
//     sample at M * (T - centre) + offset, then van Hoesel's blend.
// Per tile, as van Hoesel: a rotation-plus-scale M from the flow direction and speed, one
// normal-map sample, blended with his weights ff = 0.5 - 4 g^3 and rescaled by
// sqrt(ff^2 + (1 - ff)^2) per axis, then scaled by `strength` (his 0.3 * transp^2) and completed
// with z = sqrt(1 - |N|^2). Three deliberate differences, each for a reason:
//   - M rotates about the tile centre and each tile adds a hashed offset into the (tileable)
//     map: a flow sample that changes (another particle covers the centre) then moves the
//     pattern by a fraction of a tile instead of by hundreds of repeats, and the four blended
//     signals are uncorrelated, which is what the sqrt(ff^2 + (1-ff)^2) rescale assumes.
//   - Each sampled normal's xy is rotated back by the tile's rotation, so the result is a
//     world-space normal consistent with the rotated ripples (needed for the `normal` AOV).
//   - Each grid's tile is chosen once for each 2x2 quad of pixels (at its first pixel), so
//     that within a quad the map coordinate is one affine map of the position, M (u - centre),
//     and the sampler's own derivatives give the footprint's level of detail. Chosen per pixel,
//     a quad straddling a tile edge would see the coordinate jump and read the 1x1 mip; now its
//     pixels past the edge take the tile beside them a pixel further, where that grid's weight
//     is next to zero. An explicit level of detail (textureLod, textureGrad) cost lavapipe 11
//     to 22 % more of the material, its mip levels picked per pixel instead of per quad.
// Scroll: phase = fract(time * rate), with the rate quantised to whole cycles per
// SIVIFLOW_TDF_TIME_PERIOD, so time wrapped to [0, period) on the CPU (in double) is seamless
// at the wrap and precision never decays.
//
// Requires: GL_GOOGLE_include_directive in the including shader; shared.h (included here).
// Call tdf_normal from a fragment shader, in uniform control flow (before any discard): it takes
// derivatives (dFdx, dFdy, and the normal map's implicit level of detail).
// Bindings expected by the caller: the tile table as a usampler2D (texelFetch only) and the
// water normal map (engine/scene/water_normal_map.h: RGBA8 UNORM, mipmapped) as a sampler2D with
// REPEAT addressing and linear filtering.
#ifndef SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL
#define SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL

#include "shared.h"
#include "tdf_tile_table.glsl"

struct TdfResult {
  vec3 normal;  // final water normal, world space, unit length (the `normal` AOV)
  vec2 tilt;    // blended, rescaled, strength-scaled N.xy along world x and z (|tilt| <= 0.95):
                // the natural input of a screen-space reflection offset
  float foam;          // the tiles' foam (0..1), blended as the ripples are
  float foam_pattern;  // the ripples' height (normal map A, 0..1, mean 0.5) through the same
                       // tiles, contrast restored: foam drawn from it moves with the ripples
};

// One tile of one grid: its normal-map sample, as a tangent tilt along world x/z (xy), the
// tile's foam (z) and the ripple height there (w).
//   u: the fragment in tile units; lattice: the tile centre's lattice point, one for the quad.
//   wrap: the tile table's size - 1 (a power of two less one: lattice points wrap by masking)
vec4 tdf_tile_sample(vec2 u, ivec2 lattice, ivec2 wrap, usampler2D tile_table,
                     sampler2D normal_map) {
  uvec4 tile = texelFetch(tile_table, lattice & wrap, 0);
  vec2 ab = uintBitsToFloat(tile.rg);
  vec3 offset_and_foam = tdf_tile_offset_and_foam(tile.b);
  vec2 back = uintBitsToFloat(tile.a) * ab;
  mat2 m = mat2(ab.x, -ab.y, ab.y, ab.x);
  vec2 s = m * (u - 0.5 * vec2(lattice)) + offset_and_foam.xy;
  vec4 texel = texture(normal_map, s);
  vec2 n = texel.rg * 2.0 - 1.0;
  return vec4(mat2(back.x, back.y, -back.y, back.x) * n, offset_and_foam.z, texel.a);
}

// The Tiled Directional Flow normal of a water fragment.
//   world          fragment on the river surface, world metres (y up)
//   surface_normal geometric normal of the river surface (unit; (0,1,0) for flat water)
//   strength       van Hoesel's 0.3 * transp^2: fold fade, shore and depth in (0 = flat mirror)
//   tile_size_m    tile side in metres
TdfResult tdf_normal(vec3 world, vec3 surface_normal, float strength, float tile_size_m,
                     usampler2D tile_table, sampler2D normal_map) {
  vec2 u = world.xz / tile_size_m;
  // u at the first pixel of this fragment's 2x2 quad (quads start at even pixels): the tiles are
  // chosen there, one for the whole quad.
  vec2 in_quad = vec2(ivec2(gl_FragCoord.xy) & 1);
  vec2 u_quad = u - in_quad.x * dFdx(u) - in_quad.y * dFdy(u);
  // Grid k's tile holding u is cell floor(u + offset_k); its centre, in half tiles, is
  // 2 cell + 1 - 2 offset_k.
  const vec2 kOffsets[4] = vec2[4](vec2(0.0), vec2(0.5, 0.0), vec2(0.0, 0.5), vec2(0.5));
  const ivec2 kCentres[4] = ivec2[4](ivec2(1), ivec2(0, 1), ivec2(1, 0), ivec2(0));
  ivec2 wrap = textureSize(tile_table, 0) - 1;
  vec4 n[4];
  for (int k = 0; k < 4; ++k) {
    ivec2 lattice = 2 * ivec2(floor(u_quad + kOffsets[k])) + kCentres[k];
    n[k] = tdf_tile_sample(u, lattice, wrap, tile_table, normal_map);
  }
  // van Hoesel's weights: ff = 1 at the centre of grid A's tile, 0 at its edges (per axis).
  vec2 g = abs(2.0 * fract(u) - 1.0) - 0.5;
  vec2 ff = 0.5 - 4.0 * g * g * g;
  vec4 n_ab = ff.x * n[0] + (1.0 - ff.x) * n[1];
  vec4 n_cd = ff.x * n[2] + (1.0 - ff.x) * n[3];
  vec4 blended = ff.y * n_ab + (1.0 - ff.y) * n_cd;
  // Restore the contrast the blend of uncorrelated samples took away: per axis
  // sqrt(ff^2 + (1 - ff)^2), both axes under one root. 0.5: van Hoesel's N is rg - 0.5.
  vec2 ff_sq = ff * ff + (1.0 - ff) * (1.0 - ff);
  float contrast = inversesqrt(ff_sq.x * ff_sq.y);
  vec2 tilt = blended.xy * (0.5 * strength * contrast);
  float len_sq = dot(tilt, tilt);
  if (len_sq > kTdfMaxTilt * kTdfMaxTilt) {
    tilt *= kTdfMaxTilt * inversesqrt(len_sq);
    len_sq = kTdfMaxTilt * kTdfMaxTilt;
  }
  float z = sqrt(max(1.0 - len_sq, 0.0));
  // Tangent frame of the surface: x and z axes projected onto it (x, up, z for flat water). The
  // frame is orthonormal and |(tilt, z)| = 1, so the normal needs no normalize.
  vec3 up = normalize(surface_normal);
  vec3 tx = normalize(vec3(1.0, 0.0, 0.0) - up * up.x);
  vec3 tz = cross(tx, up);
  TdfResult result;
  result.normal = tx * tilt.x + tz * tilt.y + up * z;
  result.tilt = tilt;
  result.foam = blended.z;
  result.foam_pattern = clamp(0.5 + (blended.w - 0.5) * contrast, 0.0, 1.0);
  return result;
}

#endif  // SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL
