// Layouts shared by GLSL and C++. Every struct here crosses the CPU/GPU boundary; the C++ side
// checks sizes and offsets with static_assert (std430 / push-constant rules: vec4 and mat4 only,
// so no implicit padding can differ between the two languages).
#ifndef SIVIFLOW_SHADERS_SHARED_H
#define SIVIFLOW_SHADERS_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
namespace siviflow::gpu {
using mat4 = glm::mat4;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uint = uint32_t;
#endif

// Vertex input locations of the scene pipeline (terrain and objects).
#define SIVIFLOW_ATTR_POSITION 0
#define SIVIFLOW_ATTR_NORMAL 1
#define SIVIFLOW_ATTR_COLOR 2
#define SIVIFLOW_ATTR_TEXCOORD 3

// The color.a of ground vertices (terrain, riverbed): the scene shader colours them per fragment
// from texcoord.x, the height above the nearby water (m), and texcoord.y, how much rock shows
// (0..1), so the borders of riverbed, wet sand, sand and grass follow the ground's contours,
// not its grid. Shaders test for a negative alpha (interpolation moves it a hair). Ground has no
// ambient occlusion of its own: 1.
#define SIVIFLOW_GROUND_VERTEX (-1.0)

#ifdef __cplusplus
// One vertex of the scene pipeline's vertex buffer (GLSL reads it through the attributes above).
struct SceneVertex {
  vec3 position;
  vec3 normal;
  vec4 color;  // rgb linear albedo (objects: base-colour factor), a ambient occlusion; ground:
               // a SIVIFLOW_GROUND_VERTEX
  vec2 texcoord;  // objects: base-colour texture coordinates; ground: see SIVIFLOW_GROUND_VERTEX
};
static_assert(sizeof(SceneVertex) == 48);
static_assert(offsetof(SceneVertex, position) == 0);
static_assert(offsetof(SceneVertex, normal) == 12);
static_assert(offsetof(SceneVertex, color) == 24);
static_assert(offsetof(SceneVertex, texcoord) == 40);
#endif

// Push constants of the sky and scene pipelines: one block for both, 128 bytes (the guaranteed
// minimum of maxPushConstantsSize).
struct SceneConstants {
  mat4 view_proj;           // world -> clip (Vulkan clip space, depth 0..1)
  vec4 camera_position;     // xyz world position, w unused
  vec4 sun_direction;       // xyz unit vector towards the sun, w sun disc intensity
  vec4 clip_plane;          // world-space plane (n, d): gl_ClipDistance = dot(n, p) + d
  vec4 fog;                 // x density per metre, y height falloff, z height of the model's
                            // origin (translated instances), w the far plane's window depth
                            // (1, or 0 under reverse-Z)
};

// River particles: flow texture and auxiliary data (paper §3.2; packed by sim/flow_textures.h
// into the frame slot's staging block, flow texels first, aux texels at an aligned offset).
// Flow texture: VK_FORMAT_R16G16B16A16_UINT, ceil(W / n) x ceil(H / n) texels for a W x H output
// (n = SIVIFLOW_FLOW_TEXEL_PX unless configured). Texel (x, y) stands for the pixels
// [x n, x n + n) x [y n, y n + n), origin top-left, and holds the particle nearest to its centre
// ((x + 0.5) n, (y + 0.5) n) among the active and fading ones within the cover radius:
//   .r  particle id: SIVIFLOW_PARTICLE_NONE (0) when none covers the texel, else 1..65535, the
//       particle's slot, i.e. its texel in the aux texture (stable over the particle's life)
//   .g  flow.x  IEEE 754 binary16 bits  (the flow vector of the particle's nearest river
//   .b  flow.y  IEEE 754 binary16 bits   vertex, world space, as the river gives it)
//   .a  flow.z  IEEE 754 binary16 bits
//   GLSL: uvec4 t = texelFetch(flow_tex, p, 0);
//         vec3 flow = vec3(unpackHalf2x16(t.g | (t.b << 16)), unpackHalf2x16(t.a).x);
// Aux texture: VK_FORMAT_R32G32B32A32_SFLOAT, SIVIFLOW_AUX_WIDTH texels wide, as many rows as
// the slots need; id s is texel (s % SIVIFLOW_AUX_WIDTH, s / SIVIFLOW_AUX_WIDTH); texel 0 and
// unused slots are all zero:
//   .r speed (m/s)   .g depth (m)   .b foam (0..1, sim/foam.h)   .a fade (0..1)
// (The paper's aux also holds the riverbed slope; no pass reads it, so foam took its lane.)
#define SIVIFLOW_FLOW_TEXEL_PX 4
#define SIVIFLOW_PARTICLE_NONE 0u
#define SIVIFLOW_AUX_WIDTH 256u
// The aux texel of particle slot s (GLSL).
#define SIVIFLOW_AUX_TEXEL(s) ivec2((s) % SIVIFLOW_AUX_WIDTH, (s) / SIVIFLOW_AUX_WIDTH)

#ifdef __cplusplus
struct FlowTexel {
  uint16_t id;       // slot, 0 = no particle
  uint16_t flow_x;   // binary16 bits
  uint16_t flow_y;
  uint16_t flow_z;
};
static_assert(sizeof(FlowTexel) == 8);
static_assert(offsetof(FlowTexel, flow_x) == 2);
static_assert(offsetof(FlowTexel, flow_y) == 4);
static_assert(offsetof(FlowTexel, flow_z) == 6);
struct ParticleAux {
  float speed;
  float depth;
  float foam;
  float fade;
};
static_assert(sizeof(ParticleAux) == 16);
static_assert(offsetof(ParticleAux, depth) == 4);
static_assert(offsetof(ParticleAux, foam) == 8);
static_assert(offsetof(ParticleAux, fade) == 12);
#endif

// The flow material's uniform buffer (std140), one per frame slot: the water's look
// (siviflow/water_look.h) and what the frame's temporal outputs need.
struct WaterLookConstants {
  vec4 water_color;  // rgb linear colour of shallow water, w absorption per metre of view path
  vec4 deep_color;   // rgb linear colour of deep water, w unused
  vec4 sun_color;    // rgb linear multiplier of the sunlit part, w ripple strength
  vec4 surface;      // x Fresnel reflectance at normal incidence, y normal-map repeat in tiles
                     // (the ripples' size), z the sun glint's strength, w the debug view
                     // (siviflow::DebugView as a float; 0 the water's look)
  vec4 foam;         // rgb linear colour of foam, w foam amount
  vec4 clock;        // x scene time wrapped to SIVIFLOW_TDF_TIME_PERIOD (s): the flow map's
                     // phases; yzw unused
  vec4 refraction;   // rgb opacity per metre of view path per colour channel, w refraction
                     // distortion (uv per unit tilt per metre of water below, up to one)
  vec4 temporal;     // x reactive strength (WaterLook::reactive_strength), yzw unused
  mat4 motion_now;     // river -> clip of this frame's projection without its jitter
  mat4 motion_before;  // the same of the previous frame (motion_now after a camera cut)
};

// Push constants of the flow pass (the water material).
struct FlowConstants {
  mat4 view_proj;        // world -> clip of the host's view
  vec4 camera_position;  // xyz world position, w the projection's P[2][2] / P[2][3]: along a
                         // pixel's ray, view distances are in the ratio of (depth - w)
  vec4 sun_direction;    // xyz unit vector towards the sun
  vec4 water;            // x water level (m), y reflection distortion (uv per unit normal tilt),
                         // z TDF tile size (m), w flow texel size (pixels)
  vec4 screen;           // xy the viewport's offset in the host's images (pixels), zw 1 / its size
};

// The flow pass's tile table (shaders/flow_tiles.comp, read by tiled_directional_flow.glsl).
// Tiled Directional Flow reads one flow per tile of four grids offset by half a tile; all their
// centres lie on one lattice of half-tile spacing: lattice point (i, j) is the world point
// (i, j) * tile_size / 2 in x, z, and belongs to grid (i even) + 2 (j even). Per frame, a pass
// fills each lattice point near the camera with what its tile needs, once, instead of every
// water fragment redoing it for its four tiles. The table is VK_FORMAT_R32G32B32A32_UINT,
// SIVIFLOW_TILE_TABLE_MAX texels a side at most and a power of two; lattice point (i, j) lives
// in texel (i, j) mod size:
//   .r  .g  float bits of (a, b): the tile's map transform M = mat2(a, -b, b, a), its rotation
//           by the flow direction times the map repeats per tile
//   .b      bits 0-11 and 12-23: the map offset at the tile centre (hashed offset minus the
//           scroll, mod 1) in 1/4096; bits 24-31: the foam at the tile centre (0..1, the
//           particle's, sim/foam.h) in 1/255
//   .a      float bits of the factor of (a, b) that turns a sampled tilt back into world x/z,
//           with the roughness of the tile's speed (tdf_encode_tile)
#define SIVIFLOW_TILE_TABLE_MAX 512u
// Water heights (R32_SFLOAT, world-aligned samples, see FlowTileConstants.heights) are this or
// more where no water is near: the lattice points there are no tile of any water fragment.
#define SIVIFLOW_FAR_FROM_WATER 1.0e30

// Push constants of the tile table pass (compute).
struct FlowTileConstants {
  mat4 view_proj;  // world -> clip of the main view
  vec4 lattice;    // xy the lattice point of the table's window corner, zw the table size (all
                   // integers): texel t holds the point corner + ((t - corner) mod size)
  vec4 heights;    // xy world x, z of water height sample (0, 0), z metres between samples,
                   // w tile size (m)
  vec4 screen;     // xy output size (pixels), z flow texel size (pixels), w scene time in
                   // seconds mod SIVIFLOW_TDF_TIME_PERIOD
  vec4 ripples;    // x normal-map repeat in tiles (WaterLookConstants.surface.y), yzw unused
};

// Scene time reaches the tile table pass wrapped to [0, this period) seconds (wrapped on the CPU
// in double): floats keep sub-millisecond steps, and every TDF scroll rate makes whole cycles per
// period, so the wrap is seamless.
#define SIVIFLOW_TDF_TIME_PERIOD 64.0

#ifdef __cplusplus
static_assert(sizeof(FlowConstants) == 128);
static_assert(sizeof(FlowTileConstants) == 128);
static_assert(sizeof(WaterLookConstants) == 256);
static_assert(offsetof(WaterLookConstants, temporal) == 112);
static_assert(offsetof(WaterLookConstants, motion_now) == 128);
static_assert(offsetof(WaterLookConstants, motion_before) == 192);
static_assert(offsetof(FlowTileConstants, lattice) == 64);
static_assert(offsetof(FlowTileConstants, heights) == 80);
static_assert(offsetof(FlowTileConstants, screen) == 96);
static_assert(offsetof(FlowTileConstants, ripples) == 112);
static_assert(offsetof(FlowConstants, camera_position) == 64);
static_assert(offsetof(FlowConstants, water) == 96);
static_assert(offsetof(FlowConstants, screen) == 112);
static_assert(sizeof(SceneConstants) == 128);
static_assert(offsetof(SceneConstants, camera_position) == 64);
static_assert(offsetof(SceneConstants, sun_direction) == 80);
static_assert(offsetof(SceneConstants, clip_plane) == 96);
static_assert(offsetof(SceneConstants, fog) == 112);
}  // namespace siviflow::gpu
#endif

#endif  // SIVIFLOW_SHADERS_SHARED_H
