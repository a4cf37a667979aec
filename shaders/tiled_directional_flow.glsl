// Tiled Directional Flow (van Hoesel 2010; algorithms.md §2.1), fed by SiViFlow's screen-space
// flow texture (algorithms.md §2.2 option (a): the flow texture is the flow map).
//
// Design. The tiles live on the river surface in world space: tile coordinates are world x/z
// divided by the tile size, so they do not swim when the camera moves. Each of the four grids
// (offsets (0,0), (.5,0), (0,.5), (.5,.5) tiles) reads ONE flow per tile, at the tile centre:
// the centre (at the fragment's water height) is projected with view_proj to a pixel and the
// flow texel under it is fetched. No callback: the caller passes view_proj, the output size and
// the flow texel size, which the flow pass already has in FlowConstants. A tile whose centre is
// off screen, behind the camera or on a texel without particle (slot 0: occluded water, a
// rock) uses the fragment's own flow instead; zero flow gives still water (unrotated, no scroll,
// calmer ripples).
//
// Per tile, as van Hoesel: a rotation-plus-scale M from the flow direction and speed, one
// normal-map sample at M * T - scroll, blended with his weights ff = 0.5 - 4 g^3 and rescaled
// by sqrt(ff^2 + (1 - ff)^2) per axis, then scaled by `strength` (his 0.3 * transp^2) and
// completed with z = sqrt(1 - |N|^2). Three deliberate differences, each for a reason:
//   - M rotates about the tile centre and each tile adds a hashed offset into the (tileable)
//     map: a flow sample that changes (another particle covers the centre) then moves the
//     pattern by a fraction of a tile instead of by hundreds of repeats, and the four blended
//     signals are uncorrelated, which is what the sqrt(ff^2 + (1-ff)^2) rescale assumes.
//   - Each sampled normal's xy is rotated back by the tile's rotation, so the result is a
//     world-space normal consistent with the rotated ripples (needed for the `normal` AOV).
//   - Sampling uses textureGrad with the gradient of the world position (times M): the tile
//     coordinates jump at tile edges, and implicit derivatives there would pick the 1x1 mip.
// Scroll: phase = fract(time * rate), with the rate quantised to whole cycles per
// SIVIFLOW_TDF_TIME_PERIOD, so time wrapped to [0, period) on the CPU (in double) is seamless
// at the wrap and precision never decays.
//
// Requires: GL_GOOGLE_include_directive in the including shader; shared.h (included here).
// Call tdf_normal from uniform control flow (before any discard): it takes dFdx/dFdy.
// Bindings expected by the caller: the flow texture as a usampler2D (R16G16B16A16_UINT, read by
// texelFetch only) and the water normal map (engine/scene/water_normal_map.h: RGBA8 UNORM,
// mipmapped) as a sampler2D with REPEAT addressing and linear filtering.
#ifndef SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL
#define SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL

#include "shared.h"

// ---- Tunables (one place) ----------------------------------------------------------------------
// Seconds; the CPU passes time modulo this. Define it in shared.h to share it with C++.
#ifndef SIVIFLOW_TDF_TIME_PERIOD
#define SIVIFLOW_TDF_TIME_PERIOD 64.0
#endif
const float kTdfRepeatTiles = 3.5;       // normal-map repeat in tiles at scale 1 (van Hoesel 35/10)
const float kTdfScaleStill = 1.0;        // map repeats per repeat length in still water
const float kTdfScaleFast = 1.5;         // ... in fast water: shorter, choppier ripples
const float kTdfSpeedFast = 1.5;         // m/s at which fast-water scale and roughness are reached
const float kTdfStillRoughness = 0.4;    // ripple amplitude of still water relative to fast
const float kTdfAdvection = 0.9;         // ripple pattern speed / surface flow speed
const float kTdfMinSpeed = 1e-3;         // m/s below which the flow has no direction
const float kTdfMaxTilt = 0.95;          // |N.xy| cap, so z = sqrt(1 - |N|^2) stays real
const vec4 kTdfGridSpeed = vec4(1.0, 1.06, 1.33, 1.24);  // van Hoesel's per-grid speeds c_k
const vec4 kTdfGridPhase = vec4(0.0, 0.62, 0.27, 0.0);   // van Hoesel's start offsets e_k

struct TdfResult {
  vec3 normal;  // final water normal, world space, unit length (the `normal` AOV)
  vec2 tilt;    // blended, rescaled, strength-scaled N.xy along world x and z (|tilt| <= 0.95):
                // the natural input of a screen-space reflection offset
};

// The flow of a flow texel (shared.h layout); t.r == SIVIFLOW_PARTICLE_NONE: no particle there.
vec3 tdf_texel_flow(uvec4 t) {
  return vec3(unpackHalf2x16(t.g | (t.b << 16)), unpackHalf2x16(t.a).x);
}

// Where a tile centre falls in the flow texture, as an affine map of tile coordinates: the rows
// x, y, w of view_proj at the fragment's height, x and y remapped from NDC to flow texels (times
// w). Made once per fragment, so a tile centre costs 6 multiply-adds and one divide.
struct TdfProjection {
  vec3 origin;   // (texel.x w, texel.y w, w) of tile coordinates (0, 0)
  vec3 per_u;    // ... per tile along world x
  vec3 per_v;    // ... per tile along world z
  vec2 extent;   // flow texels across the viewport: NDC [-1, 1] is [0, extent]
};

TdfProjection tdf_projection(float height, float tile_size_m, mat4 view_proj, vec2 viewport_px,
                             float texel_px) {
  vec2 half_texels = 0.5 * viewport_px / texel_px;
  // Clip x, y to (NDC * 0.5 + 0.5) * texels, times w: x' = half_texels.x * (x + w).
  mat4 to_texels = mat4(vec4(half_texels.x, 0.0, 0.0, 0.0), vec4(0.0, half_texels.y, 0.0, 0.0),
                        vec4(0.0, 0.0, 1.0, 0.0), vec4(half_texels, 0.0, 1.0)) * view_proj;
  TdfProjection p;
  p.origin = (to_texels[1] * height + to_texels[3]).xyw;
  p.per_u = to_texels[0].xyw * tile_size_m;
  p.per_v = to_texels[2].xyw * tile_size_m;
  p.extent = 2.0 * half_texels;
  return p;
}

// The flow at a tile centre (tile coordinates); `fallback` when off screen, behind the camera or
// on a texel without particle.
vec3 tdf_flow_at(TdfProjection p, vec2 centre_u, vec3 fallback, usampler2D flow_tex) {
  vec3 h = p.origin + centre_u.x * p.per_u + centre_u.y * p.per_v;
  vec2 at = h.xy * (1.0 / h.z);
  bool inside =
      h.z > 1e-6 && all(greaterThanEqual(at, vec2(0.0))) && all(lessThanEqual(at, p.extent));
  ivec2 texel = clamp(ivec2(at), ivec2(0), textureSize(flow_tex, 0) - 1);
  uvec4 t = texelFetch(flow_tex, texel, 0);
  return inside && t.r != SIVIFLOW_PARTICLE_NONE ? tdf_texel_flow(t) : fallback;
}

// Per-tile offset into the tileable map, [0,1)^2, from the tile's integer cell and grid.
vec2 tdf_tile_offset(vec2 cell, int grid) {
  uvec2 v = uvec2(ivec2(cell)) * uvec2(1664525u, 1013904223u) + uint(grid) * 2654435769u;
  v.x ^= v.y >> 16;
  v.y ^= v.x << 5;
  v = v * 747796405u + 2891336453u;
  v ^= v >> 16;
  return vec2(v >> 8) * (1.0 / 16777216.0);
}

// One tile of one grid: its normal-map sample, as a tangent tilt along world x/z.
//   u: the fragment in tile units; cell, centre_u: the tile; flow: its flow (world m/s);
//   cycles_per_mps: scroll cycles per period per m/s of scaled speed; periods: time / period.
vec2 tdf_tile_sample(vec2 u, vec2 cell, vec2 centre_u, int grid, vec3 flow, float periods,
                     float cycles_per_mps, vec2 du_dx, vec2 du_dy, sampler2D normal_map) {
  float speed_sq = dot(flow.xz, flow.xz);
  float inv_speed = inversesqrt(max(speed_sq, 1e-20));  // one root gives speed and direction
  float speed = speed_sq * inv_speed;
  vec2 dir = speed > kTdfMinSpeed ? flow.xz * inv_speed : vec2(1.0, 0.0);
  float fast = clamp(speed * (1.0 / kTdfSpeedFast), 0.0, 1.0);
  float scale = mix(kTdfScaleStill, kTdfScaleFast, fast);
  // M = scale * R(-angle): the world flow direction maps to the map's +U (column-major mat2).
  mat2 m = (scale * (1.0 / kTdfRepeatTiles)) * mat2(dir.x, -dir.y, dir.y, dir.x);
  // Pattern world speed = rate * repeat_m / scale; whole cycles per period keep the wrap seamless.
  float cycles = round(speed * scale * cycles_per_mps * kTdfGridSpeed[grid]);
  float phase = fract(cycles * periods + kTdfGridPhase[grid]);
  // Subtracting the phase after M moves the pattern along +dir, i.e. downstream.
  vec2 s = m * (u - centre_u) + tdf_tile_offset(cell, grid) - vec2(phase, 0.0);
  vec2 n = textureGrad(normal_map, s, m * du_dx, m * du_dy).rg * 2.0 - 1.0;
  // R(+angle) scaled by the roughness: the sampled tilt back into world x/z.
  vec2 back = mix(kTdfStillRoughness, 1.0, fast) * dir;
  return mat2(back.x, back.y, -back.y, back.x) * n;
}

// The Tiled Directional Flow normal of a water fragment.
//   world          fragment on the river surface, world metres (y up)
//   surface_normal geometric normal of the river surface (unit; (0,1,0) for flat water)
//   own_flow       the fragment's own flow texel's flow (world m/s), for tiles without a particle
//   strength       van Hoesel's 0.3 * transp^2: fold fade, shore and depth in (0 = flat mirror)
//   time           seconds, wrapped on the CPU to [0, SIVIFLOW_TDF_TIME_PERIOD)
//   tile_size_m    tile side in metres (the normal map repeats every kTdfRepeatTiles tiles)
//   view_proj      world -> clip of the view the flow texture was made for
//   viewport_px    output size in pixels; texel_px: pixels per flow texel side
TdfResult tdf_normal(vec3 world, vec3 surface_normal, vec3 own_flow, float strength, float time,
                     float tile_size_m, mat4 view_proj, vec2 viewport_px, float texel_px,
                     usampler2D flow_tex, sampler2D normal_map) {
  vec2 u = world.xz / tile_size_m;
  vec2 du_dx = dFdx(u);
  vec2 du_dy = dFdy(u);
  TdfProjection projection = tdf_projection(world.y, tile_size_m, view_proj, viewport_px, texel_px);
  float cycles_per_mps =
      kTdfAdvection * SIVIFLOW_TDF_TIME_PERIOD / (tile_size_m * kTdfRepeatTiles);
  float periods = time * (1.0 / SIVIFLOW_TDF_TIME_PERIOD);
  const vec2 kOffsets[4] = vec2[4](vec2(0.0), vec2(0.5, 0.0), vec2(0.0, 0.5), vec2(0.5));
  vec2 n[4];
  for (int k = 0; k < 4; ++k) {
    vec2 cell = floor(u + kOffsets[k]);
    vec2 centre_u = cell + 0.5 - kOffsets[k];
    vec3 flow = tdf_flow_at(projection, centre_u, own_flow, flow_tex);
    n[k] = tdf_tile_sample(u, cell, centre_u, k, flow, periods, cycles_per_mps, du_dx, du_dy,
                           normal_map);
  }
  // van Hoesel's weights: ff = 1 at the centre of grid A's tile, 0 at its edges (per axis).
  vec2 g = abs(2.0 * fract(u) - 1.0) - 0.5;
  vec2 ff = 0.5 - 4.0 * g * g * g;
  vec2 n_ab = ff.x * n[0] + (1.0 - ff.x) * n[1];
  vec2 n_cd = ff.x * n[2] + (1.0 - ff.x) * n[3];
  vec2 tilt = ff.y * n_ab + (1.0 - ff.y) * n_cd;
  // Restore the contrast the blend of uncorrelated samples took away: per axis
  // sqrt(ff^2 + (1 - ff)^2), both axes under one root. 0.5: van Hoesel's N is rg - 0.5.
  vec2 ff_sq = ff * ff + (1.0 - ff) * (1.0 - ff);
  tilt *= 0.5 * strength * inversesqrt(ff_sq.x * ff_sq.y);
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
  return result;
}

#endif  // SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL
