// The water's debug views (siviflow::DebugView in renderer.h), drawn by the flow material in
// place of the water's look: what the material reads, made visible.
//   1 flow direction: the pixel's particle flow as a colour (hue = direction in the world's x/z
//     plane, brightness = speed) with one white arrow per Tiled Directional Flow tile along the
//     flow that tile scrolls its ripples by (tile table);
//   2 particles: each particle's pixels in a colour of its own, darker as it fades;
//   3 tile grid: the water's look with the tiles of the first grid outlined, and the half-tile
//     offset grids' edges fainter.
// Requires: tdf_tile_table.glsl (the tile table layout and tdf_texel_flow).
#ifndef SIVIFLOW_WATER_DEBUG_VIEWS_GLSL
#define SIVIFLOW_WATER_DEBUG_VIEWS_GLSL

const int kDebugViewNone = 0;
const int kDebugViewFlowDirection = 1;
const int kDebugViewParticles = 2;
const int kDebugViewTileGrid = 3;

const float kDebugTwoPi = 6.28318531;
const float kDebugSpeedFull = 1.5;  // m/s shown at full brightness (kTdfSpeedFast)

vec3 debug_hue(float hue) {
  vec3 k = clamp(abs(fract(hue + vec3(0.0, 2.0, 1.0) / 3.0) * 6.0 - 3.0) - 1.0, 0.0, 1.0);
  return k;
}

// Hue of a flow's direction: fract(atan2(z, x) / 2 pi), so +x is red, +z is green-yellow...
vec3 debug_flow_colour(vec3 flow) {
  float speed = length(flow.xz);
  if (speed < kTdfMinSpeed) return vec3(0.02);
  float hue = fract(atan(flow.z, flow.x) / kDebugTwoPi);
  return debug_hue(hue) * (0.25 + 0.75 * clamp(speed / kDebugSpeedFull, 0.0, 1.0));
}

// How far marks drawn per tile show: none where a tile is a few pixels across (they would fill
// it), whole from eight.
float debug_tile_visibility(vec2 u) {
  return smoothstep(3.0, 8.0, 1.0 / max(length(fwidth(u)), 1e-6));
}

// Coverage (0..1) of the lines at whole values of u (in tile units), about 1.5 pixels wide.
float debug_grid_line(vec2 u) {
  vec2 to_line = abs(fract(u + 0.5) - 0.5) / max(fwidth(u), vec2(1e-6));
  return (1.0 - smoothstep(0.75, 1.5, min(to_line.x, to_line.y))) * debug_tile_visibility(u);
}

// Coverage (0..1) of the arrow of the first grid's tile holding u (tile units): along the
// tile's flow, as long as its speed makes it; none for still water.
float debug_tile_arrow(vec2 u, float repeat_tiles, usampler2D tile_table) {
  ivec2 lattice = 2 * ivec2(floor(u)) + ivec2(1);
  uvec4 tile = texelFetch(tile_table, lattice & (textureSize(tile_table, 0) - 1), 0);
  vec2 ab = uintBitsToFloat(tile.rg);
  float scale = length(ab) * repeat_tiles;  // kTdfScaleStill .. kTdfScaleFast with speed
  float fast = (scale - kTdfScaleStill) / (kTdfScaleFast - kTdfScaleStill);
  if (fast < 0.01) return 0.0;
  vec2 dir = normalize(ab);
  vec2 p = fract(u) - 0.5;
  float along = dot(p, dir);
  float across = abs(dot(p, vec2(-dir.y, dir.x)));
  float half_length = 0.15 + 0.25 * clamp(fast, 0.0, 1.0);
  float head = 0.14;
  float base = half_length - head;  // where the shaft meets the head
  float shaft = max(across - 0.03, max(-half_length - along, along - base));
  float tip = max(base - along, across - 0.1 * (half_length - along) / head);
  float distance = min(shaft, tip);  // < 0 inside (near enough a distance for the edge's blur)
  float pixel = length(fwidth(u));
  return (1.0 - smoothstep(0.0, pixel, distance)) * debug_tile_visibility(u);
}

// A colour per particle slot, bright and far from its neighbours' slots.
vec3 debug_particle_colour(uint id, float fade) {
  if (id == SIVIFLOW_PARTICLE_NONE) return vec3(0.0);
  uint h = id * 2654435761u;
  h ^= h >> 15;
  h *= 2246822519u;
  h ^= h >> 13;
  float hue = float(h & 1023u) / 1024.0;
  float value = 0.55 + 0.45 * float((h >> 10) & 3u) / 3.0;
  return debug_hue(hue) * value * mix(0.3, 1.0, fade);
}

// The colour (rgb, alpha) the debug view `mode` draws in place of the water's `look`.
//   texel: the pixel's flow texel; fade: its particle's; world: the fragment on the water.
vec4 debug_view_colour(int mode, vec4 look, uvec4 texel, float fade, vec3 world,
                       float tile_size_m, float repeat_tiles, usampler2D tile_table) {
  vec2 u = world.xz / tile_size_m;
  if (mode == kDebugViewFlowDirection) {
    vec3 base = texel.r == SIVIFLOW_PARTICLE_NONE ? vec3(0.02) : debug_flow_colour(tdf_texel_flow(texel));
    return vec4(mix(base, vec3(1.0), debug_tile_arrow(u, repeat_tiles, tile_table)), 1.0);
  }
  if (mode == kDebugViewParticles) return vec4(debug_particle_colour(texel.r, fade), 1.0);
  if (mode == kDebugViewTileGrid) {
    float main_grid = debug_grid_line(u);
    float offset_grids = 0.5 * debug_grid_line(u + 0.5);
    vec4 lined = mix(look, vec4(0.0, 0.9, 1.0, 1.0), offset_grids);
    return mix(lined, vec4(1.0, 0.85, 0.0, 1.0), main_grid);
  }
  return look;
}

#endif  // SIVIFLOW_WATER_DEBUG_VIEWS_GLSL
