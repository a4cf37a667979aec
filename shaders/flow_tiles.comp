#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "tdf_tile_table.glsl"
// The tile table of this frame (shared.h): per lattice point near the camera, the flow and foam
// at the tile centre and what the water material derives from them (tdf_encode_tile). One invocation
// per table texel.
layout(local_size_x = 8, local_size_y = 8) in;
layout(push_constant) uniform Push { FlowTileConstants tiles; };
layout(set = 0, binding = 0) uniform usampler2D flow_texture;   // shared.h layout, texelFetch only
layout(set = 0, binding = 1) uniform sampler2D water_heights;   // R32_SFLOAT, texelFetch only
layout(set = 0, binding = 2, rgba32ui) uniform writeonly uimage2D tile_table;
layout(set = 0, binding = 3) uniform sampler2D particle_aux;    // shared.h layout, texelFetch only

// The point itself, then its axis neighbours, then the diagonal ones, and what each weighs when
// the point itself has no particle (nearer counts more).
const ivec2 kSearch[9] = ivec2[9](ivec2(0, 0), ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
                                  ivec2(1, 1), ivec2(-1, 1), ivec2(1, -1), ivec2(-1, -1));
const float kNeighbourWeight[9] = float[9](1.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.5, 0.5, 0.5);

// The foam of a flow texel's particle (slot 0, no particle, reads the aux texture's all-zero
// texel 0: no foam).
float texel_foam(uint slot) {
  return texelFetch(particle_aux, SIVIFLOW_AUX_TEXEL(slot), 0).b;
}

void main() {
  // The lattice point of this texel: the one congruent to it (mod the table size) in the window.
  ivec2 size = textureSize(flow_texture, 0);
  ivec2 table = ivec2(tiles.lattice.zw);
  ivec2 corner = ivec2(tiles.lattice.xy);
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, table))) return;
  ivec2 lattice = corner + ((texel - corner) & (table - 1));
  float half_tile = 0.5 * tiles.heights.w;
  vec2 centre = vec2(lattice) * half_tile;
  ivec2 height_texel = clamp(ivec2(round((centre - tiles.heights.xy) / tiles.heights.z)), ivec2(0),
                             textureSize(water_heights, 0) - 1);
  float height = texelFetch(water_heights, height_texel, 0).r;

  // The lattice around this point at its water height, projected to flow texels (times w).
  vec2 texels = tiles.screen.xy / tiles.screen.z;
  vec4 origin = tiles.view_proj * vec4(centre.x, height, centre.y, 1.0);
  vec4 per_x = tiles.view_proj[0] * half_tile;
  vec4 per_z = tiles.view_proj[2] * half_tile;
  // The particle under the point gives its flow and foam. Where there is none (off screen, on
  // land, hidden, on an obstacle's dry ground) the neighbours that have one give their weighted
  // mean: around an obstacle they flow round both sides, and their mean is the water's way past
  // it, not one side's turn. None at all: still water.
  vec4 sum = vec4(0.0);  // flow xyz and foam, weighted
  float weight = 0.0;
  // Far from water no fragment reads this point: no search (whole blocks of texels skip it).
  int candidates = height < SIVIFLOW_FAR_FROM_WATER ? 9 : 0;
  for (int i = 0; i < candidates; ++i) {
    vec4 clip = origin + float(kSearch[i].x) * per_x + float(kSearch[i].y) * per_z;
    vec2 at = (clip.xy / clip.w * 0.5 + 0.5) * texels;
    bool inside = clip.w > 1e-6 && all(greaterThanEqual(at, vec2(0.0))) && all(lessThan(at, texels));
    uvec4 t = texelFetch(flow_texture, clamp(ivec2(at), ivec2(0), size - 1), 0);
    if (!inside || t.r == SIVIFLOW_PARTICLE_NONE) continue;
    sum += kNeighbourWeight[i] * vec4(tdf_texel_flow(t), texel_foam(t.r));
    weight += kNeighbourWeight[i];
    if (i == 0) break;
  }
  if (weight > 0.0) sum /= weight;
  vec3 flow = sum.xyz;
  float foam = sum.w;
  float cycles_per_mps =
      kTdfAdvection * SIVIFLOW_TDF_TIME_PERIOD / (tiles.heights.w * tiles.ripples.x);
  imageStore(tile_table, texel,
             tdf_encode_tile(lattice, flow, foam, tiles.screen.w / SIVIFLOW_TDF_TIME_PERIOD, cycles_per_mps,
                             tiles.ripples.x));
}
