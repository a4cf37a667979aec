// The per-tile half of Tiled Directional Flow (see tiled_directional_flow.glsl): its tunables and
// the tile table texel of one tile, made per frame by flow_tiles.comp. Any stage may include it.
#ifndef SIVIFLOW_TDF_TILE_TABLE_GLSL
#define SIVIFLOW_TDF_TILE_TABLE_GLSL

#include "shared.h"

// ---- Tunables (one place; the scroll period SIVIFLOW_TDF_TIME_PERIOD is in shared.h) ------
const float kTdfScaleStill = 1.0;        // map repeats per repeat length in still water
const float kTdfScaleFast = 1.5;         // ... in fast water: shorter, choppier ripples
const float kTdfSpeedFast = 1.5;         // m/s at which fast-water scale and roughness are reached
const float kTdfStillRoughness = 0.4;    // ripple amplitude of still water relative to fast
const float kTdfAdvection = 0.9;         // ripple pattern speed / surface flow speed
const float kTdfMinSpeed = 1e-3;         // m/s below which the flow has no direction
const float kTdfMaxTilt = 0.95;          // |N.xy| cap, so z = sqrt(1 - |N|^2) stays real
const vec4 kTdfGridSpeed = vec4(1.0, 1.06, 1.33, 1.24);  // van Hoesel's per-grid speeds c_k
const vec4 kTdfGridPhase = vec4(0.0, 0.62, 0.27, 0.0);   // van Hoesel's start offsets e_k

// The flow of a flow texel (shared.h layout); t.r == SIVIFLOW_PARTICLE_NONE: no particle there.
vec3 tdf_texel_flow(uvec4 t) {
  return vec3(unpackHalf2x16(t.g | (t.b << 16)), unpackHalf2x16(t.a).x);
}

// Per-tile offset into the tileable map, [0,1)^2, from the tile's integer cell and grid.
vec2 tdf_tile_offset(ivec2 cell, int grid) {
  uvec2 v = uvec2(cell) * uvec2(1664525u, 1013904223u) + uint(grid) * 2654435769u;
  v.x ^= v.y >> 16;
  v.y ^= v.x << 5;
  v = v * 747796405u + 2891336453u;
  v ^= v >> 16;
  return vec2(v >> 8) * (1.0 / 16777216.0);
}

// The tile table texel (shared.h) of the tile centred on lattice point `lattice`, whose flow is
// `flow` (world m/s; zero for still water) and foam `foam` (0..1).
//   cycles_per_mps: scroll cycles per period per m/s of scaled speed; periods: time / period;
//   repeat_tiles: tiles per normal-map repeat at scale 1 (the ripples' size).
uvec4 tdf_encode_tile(ivec2 lattice, vec3 flow, float foam, float periods, float cycles_per_mps,
                      float repeat_tiles) {
  // Lattice (2c + 1, .) is grid A's tile c, (2c, .) the grid offset by half a tile, per axis.
  int grid = int((lattice.x & 1) == 0) + 2 * int((lattice.y & 1) == 0);
  ivec2 cell = lattice >> 1;
  float speed = length(flow.xz);
  vec2 dir = speed > kTdfMinSpeed ? flow.xz / speed : vec2(1.0, 0.0);
  float fast = clamp(speed * (1.0 / kTdfSpeedFast), 0.0, 1.0);
  float scale = mix(kTdfScaleStill, kTdfScaleFast, fast);
  // M = scale * R(-angle): the world flow direction maps to the map's +U.
  vec2 ab = (scale / repeat_tiles) * dir;
  // Pattern world speed = rate * repeat_m / scale; whole cycles per period keep the wrap seamless.
  float cycles = round(speed * scale * cycles_per_mps * kTdfGridSpeed[grid]);
  float phase = fract(cycles * periods + kTdfGridPhase[grid]);
  // Subtracting the phase after M moves the pattern along +dir, i.e. downstream.
  // The map tiles, so the offset keeps only its fraction: 12 bits each resolve 1/4096 of it.
  vec2 offset = fract(tdf_tile_offset(cell, grid) - vec2(phase, 0.0));
  uvec2 offset_bits = uvec2(round(offset * 4096.0)) & 0xfffu;
  uint foam_bits = uint(round(clamp(foam, 0.0, 1.0) * 255.0));
  // What every fragment would otherwise derive from (a, b) for each of its four tiles: the
  // factor of R(+angle) by which a sampled tilt turns back into world x/z, scaled by the
  // roughness (repeat / scale, times the roughness of this speed).
  float back = mix(kTdfStillRoughness, 1.0, fast) * repeat_tiles / scale;
  return uvec4(floatBitsToUint(ab), offset_bits.x | (offset_bits.y << 12) | (foam_bits << 24),
               floatBitsToUint(back));
}

// A tile table texel's map offset (xy) and foam (z), unpacked.
vec3 tdf_tile_offset_and_foam(uint bits) {
  return vec3(float(bits & 0xfffu), float((bits >> 12) & 0xfffu), 0.0) * (1.0 / 4096.0) +
         vec3(0.0, 0.0, float(bits >> 24) * (1.0 / 255.0));
}

#endif  // SIVIFLOW_TDF_TILE_TABLE_GLSL
