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

// Flow texel decode (shared.h). False when no particle covers the texel.
bool tdf_fetch_flow(usampler2D flow_tex, ivec2 texel, out vec3 flow) {
  uvec4 t = texelFetch(flow_tex, texel, 0);
  flow = vec3(unpackHalf2x16(t.g | (t.b << 16)), unpackHalf2x16(t.a).x);
  return t.r != SIVIFLOW_PARTICLE_NONE;
}

// The flow at a world point: projected to the output (Vulkan clip space, +Y down, origin top
// left, as sim/particles.h) and looked up in the flow texture; `fallback` when none is there.
vec3 tdf_flow_at(vec3 world, vec3 fallback, mat4 view_proj, vec2 viewport_px, float texel_px,
                 usampler2D flow_tex) {
  vec4 clip = view_proj * vec4(world, 1.0);
  if (clip.w <= 1e-6) return fallback;
  vec2 ndc = clip.xy / clip.w;
  if (any(greaterThan(abs(ndc), vec2(1.0)))) return fallback;
  ivec2 texel = ivec2((ndc * 0.5 + 0.5) * viewport_px / texel_px);
  texel = clamp(texel, ivec2(0), textureSize(flow_tex, 0) - 1);
  vec3 flow;
  return tdf_fetch_flow(flow_tex, texel, flow) ? flow : fallback;
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
//   u: the fragment in tile units; cell, centre_u: the tile; flow: its flow (world m/s).
vec2 tdf_tile_sample(vec2 u, vec2 cell, vec2 centre_u, int grid, vec3 flow, float time,
                     float repeat_m, vec2 du_dx, vec2 du_dy, sampler2D normal_map) {
  float speed = length(flow.xz);
  vec2 dir = speed > kTdfMinSpeed ? flow.xz / speed : vec2(1.0, 0.0);
  float fast = clamp(speed / kTdfSpeedFast, 0.0, 1.0);
  float scale = mix(kTdfScaleStill, kTdfScaleFast, fast);
  // M = scale * R(-angle): the world flow direction maps to the map's +U (column-major mat2).
  mat2 m = (scale / kTdfRepeatTiles) * mat2(dir.x, -dir.y, dir.y, dir.x);
  // Pattern world speed = rate * repeat_m / scale; whole cycles per period keep the wrap seamless.
  float rate = kTdfAdvection * speed * scale / repeat_m * kTdfGridSpeed[grid];
  rate = round(rate * SIVIFLOW_TDF_TIME_PERIOD) / SIVIFLOW_TDF_TIME_PERIOD;
  float phase = fract(time * rate + kTdfGridPhase[grid]);
  // Subtracting the phase after M moves the pattern along +dir, i.e. downstream.
  vec2 s = m * (u - centre_u) + tdf_tile_offset(cell, grid) - vec2(phase, 0.0);
  vec2 n = textureGrad(normal_map, s, m * du_dx, m * du_dy).rg * 2.0 - 1.0;
  float roughness = mix(kTdfStillRoughness, 1.0, fast);
  // R(+angle): the sampled tilt back into world x/z, matching the rotated ripples.
  return roughness * (mat2(dir.x, dir.y, -dir.y, dir.x) * n);
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
  float repeat_m = tile_size_m * kTdfRepeatTiles;
  const vec2 kOffsets[4] = vec2[4](vec2(0.0), vec2(0.5, 0.0), vec2(0.0, 0.5), vec2(0.5));
  vec2 n[4];
  for (int k = 0; k < 4; ++k) {
    vec2 cell = floor(u + kOffsets[k]);
    vec2 centre_u = cell + 0.5 - kOffsets[k];
    vec3 centre = vec3(centre_u.x * tile_size_m, world.y, centre_u.y * tile_size_m);
    vec3 flow = tdf_flow_at(centre, own_flow, view_proj, viewport_px, texel_px, flow_tex);
    n[k] = tdf_tile_sample(u, cell, centre_u, k, flow, time, repeat_m, du_dx, du_dy, normal_map);
  }
  // van Hoesel's weights: ff = 1 at the centre of grid A's tile, 0 at its edges (per axis).
  vec2 g = abs(2.0 * fract(u) - 1.0) - 0.5;
  vec2 ff = 0.5 - 4.0 * g * g * g;
  vec2 n_ab = ff.x * n[0] + (1.0 - ff.x) * n[1];
  vec2 n_cd = ff.x * n[2] + (1.0 - ff.x) * n[3];
  vec2 tilt = ff.y * n_ab + (1.0 - ff.y) * n_cd;
  // Restore the contrast the blend of uncorrelated samples took away.
  vec2 ff_scale = sqrt(ff * ff + (1.0 - ff) * (1.0 - ff));
  tilt *= 0.5 * strength / (ff_scale.x * ff_scale.y);  // 0.5: van Hoesel's N is rg - 0.5
  float len = length(tilt);
  if (len > kTdfMaxTilt) tilt *= kTdfMaxTilt / len;
  float z = sqrt(max(1.0 - dot(tilt, tilt), 0.0));
  // Tangent frame of the surface: x and z axes projected onto it (x, up, z for flat water).
  vec3 up = normalize(surface_normal);
  vec3 tx = normalize(vec3(1.0, 0.0, 0.0) - up * up.x);
  vec3 tz = cross(tx, up);
  TdfResult result;
  result.normal = normalize(tx * tilt.x + tz * tilt.y + up * z);
  result.tilt = tilt;
  return result;
}

#endif  // SIVIFLOW_TILED_DIRECTIONAL_FLOW_GLSL
