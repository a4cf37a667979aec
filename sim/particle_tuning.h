// Every constant that tunes the River Particle Processor and the Flow Texture Mapper (paper
// §2.2.2-3.2, Algorithm 2; algorithms.md §1.2, §1.4), in one place. Pixels are output pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

namespace siviflow {

// --- Poisson-disk spacing -------------------------------------------------------------------
// Minimum screen distance between live particles: 24 px at 720 lines, scaled with the height
// (algorithms.md §1.4: ~600 particles over a 1024x768 screen at a 15 px radius).
inline constexpr float kDefaultMinDistancePx = 24.0f;
inline constexpr float kDefaultMinDistanceHeight = 720.0f;
// The fill places new particles this multiple of the minimum distance apart where there is
// room, so a pair survives some perspective squeeze (a pan, a turn) before it is thinned; the
// gaps this leaves are then filled at kTightSpacing, which keeps the cover within the minimum
// distance.
inline constexpr float kDefaultFillSpacing = 1.15f;
// Second-tier spacing: just above 1 so float noise in re-projection never thins a fresh pair.
inline constexpr float kTightSpacing = 1.001f;
// Second-tier spacing while the camera moves: a gap is filled once it is this much wider than
// the minimum distance, so the filler has room to survive the next frames' squeeze.
inline constexpr float kMovingCoverFactor = 1.1f;
// A second-tier particle is pushed out from its parent by up to this fraction of the spacing
// (< 1, so it still covers the gap point it was made for), to the point of the gap farthest
// from every particle, tried in this many steps.
inline constexpr float kGapDeepening = 0.9f;
inline constexpr int kGapDeepeningSteps = 9;

// The camera counts as still while its matrix stays within this relative rounding (8 float
// epsilons of each column's largest entry) of the one its epoch began with: the same camera
// recomputed by another code path (constant folding, FMA, libm) differs by a few ulps, which
// moves no particle more than the re-projection's own rounding does.
inline constexpr float kStillCameraEpsilon = 8.0f * std::numeric_limits<float>::epsilon();

// --- Screen margins, as multiples of the minimum distance ----------------------------------
// New particles are made up to this far outside the viewport, so a pan brings in particles
// that have already faded in and the edge texels have a particle on their outer side.
inline constexpr float kFillMarginFactor = 1.0f;
// Particles farther than this outside the viewport are deleted at once (they can own no on-
// screen texel); the band between the two margins is hysteresis against pan jitter.
inline constexpr float kCullMarginFactor = 2.0f;

// --- Life cycle (seconds; Proland fades over 0.5-5 s, a frame budget wants short) -------------
inline constexpr float kDefaultFadeInSeconds = 0.25f;
inline constexpr float kDefaultFadeOutSeconds = 0.25f;

// --- Conversion ------------------------------------------------------------------------------
// Radius (metres) searched for the nearest river vertex; beyond it the hit triangle's nearest
// vertex is used. Large against any sane triangle, so the result is the true nearest vertex.
inline constexpr float kDefaultVertexSearchRadius = 16.0f;

// --- Upkeep caching (what keeps a moving camera's frame cheap) -------------------------------
// The angular sectors of a particle's fill circle; a ray that misses the water marks its sector
// dry, so an edge particle does not re-cast the same miss every frame.
inline constexpr uint32_t kDrySectors = 32;
// With the camera moving, a particle's free arcs are recomputed every this many frames (staggered
// by id): perspective opens gaps slowly; removals and screen edges trigger a recheck at once.
inline constexpr uint32_t kArcRecheckFrames = 8;
// With the camera moving, dry sectors are forgotten every this many frames (staggered by id).
inline constexpr uint32_t kDryRecheckFrames = 16;
// Where an obstacle's footprint moved, came or went, the particles whose fill circles (this many
// of them, in the screen's scale at the particle) reach its old or new bounds recheck them; at
// least this many metres, at most that many (a particle at the horizon).
inline constexpr float kDryRecheckCircles = 2.0f;
inline constexpr double kDryRecheckMarginM = 1.0;
inline constexpr double kDryRecheckMaxM = 50.0;
inline constexpr float kScaleProbeM = 0.1f;  // metres stepped to measure the screen's scale
// A sight line from the water to the eye meets the occluders only beyond this many metres: the
// ground that meets the water at the shore must not hide the water it touches.
inline constexpr double kSightLineSkipM = 0.01;
// Seeding (finding water not connected on screen to any particle): a fill-domain cell is
// re-tested every this many frames when the camera moves; cells on the domain border (where a
// pan brings new water in) more often.
inline constexpr uint32_t kSeedRecheckFramesInterior = 32;
inline constexpr uint32_t kSeedRecheckFramesBorder = 4;
// A frame that culls more than this fraction of the live particles is a cut: everything is
// rechecked and every seed cell tested at once.
inline constexpr float kCutCulledFraction = 0.5f;

// --- Ids and capacity -------------------------------------------------------------------------
// Slot 0 means "no particle" in the flow texture, so a frame holds at most 65535 particles.
inline constexpr uint32_t kMaxParticleSlots = 65535;
// Slots = this x the densest packing of live particles in the culled region; the rest hold the
// fading-out ones (the most faded is evicted early if they ever run out).
inline constexpr float kSlotsPerLiveBound = 2.0f;

// --- Flow texture (paper §3.2) ----------------------------------------------------------------
// One flow texel per this many pixels square (SIVIFLOW_FLOW_TEXEL_PX in shaders/shared.h).
inline constexpr uint32_t kDefaultFlowTexelPx = 4;
// A texel takes the nearest particle within this multiple of the cover radius: > 1 so texels at
// the banks, past the last particle's disc, still get a flow (measured: every water pixel of a
// moving view within 1.05 x the minimum distance of some particle). Cost grows with it.
inline constexpr float kFlowCoverRadiusFactor = 1.25f;
// Byte alignment of the aux block inside the staging block (>= every texel size, and the
// optimalBufferCopyOffsetAlignment of common devices).
inline constexpr size_t kStagingBlockAlignment = 256;

}  // namespace siviflow
