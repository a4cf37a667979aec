// River Particle Generator (paper §2.2.2-2.2.3, Algorithm 2; algorithms.md §1.2): a screen-space
// Poisson-disk set of particles over the visible water, each anchored at a world point of the
// river surface and carrying the flow data of its nearest river vertex.
//
// Every update (one frame):
//   1. fades advance; a particle whose fade-out ends is deleted;
//   2. (option) particles advect along the flow and are snapped back onto the surface;
//   3. every particle is re-projected; those outside the view frustum (plus a margin) go at once;
//   4. thinning: live particles (active or fading in), oldest first, closer than min_distance_px
//      to an older kept one start fading out; fading-out ones are ignored by this test, and one
//      whose spot has become free again fades back in (no id churn under jitter);
//   5. fill: Dunbar-Humphreys boundary sampling grows new particles from the live ones next to a
//      gap, plus seeds tried on a coarse grid for water not connected on screen to any particle;
//      in two tiers: first at the preferred spacing (fill_spacing x min distance), then the gaps
//      left, each filler pushed to the point of its gap farthest from every particle. With the
//      camera still (and on a cut) the fill closes every gap wider than the minimum distance;
//      while it moves, only those wider than kMovingCoverFactor x it, so the fillers have room
//      to survive the motion instead of being thinned again the next frame (churn). "Still":
//      the matrix equals the one the camera last settled on up to rounding (kStillCameraEpsilon);
//   6. conversion: a new particle's pixel ray is cast into the river (BVH); a miss makes none,
//      and so does a hit inside an obstacle's dry footprint (the water there is not seen and
//      its flow is the still water of a wall), behind an obstacle the ray meets first (its
//      footprint raised to its top) or behind the host's occluders (its ground and objects);
//      a particle a footprint comes to cover or hide goes, and so does one the occluders come to
//      hide as the camera moves.
// Fill method: Dunbar & Humphreys boundary sampling, not Bridson's dart throwing. It only works
// at the boundary of the covered region (cost scales with the gap, not the screen), it yields
// a maximal set (no point of the water is left farther than the spacing from a particle, which
// the flow texture needs), and each try removes a fixed angular range of a particle's circle so
// it terminates without a retry budget; Bridson's k random tries can leave holes and cost k rays.
// Cost: a still camera casts no ray and recomputes no circle; a moving one recomputes the
// circles of new particles, of the neighbours of removed ones, of those near the screen edge and
// 1/kArcRecheckFrames of the rest, and caches rays that missed the water (dry sectors, seed cells).
//
// Determinism: the state after frame N is a function of (river, params, seed, cameras of frames
// 0..N, dt of frames 0..N). Every random number of frame N comes from a generator seeded with
// (seed, N), and everything is processed in id order. To start a run at frame N, call update()
// for frames 0..N-1 first (no packing, no rendering needed); that is what makes frame N the same
// whatever frame the run started from. update() refuses a frame index that is not the next one.
//
// Memory is bounded by the screen: particles, slots and grids are sized from the viewport and
// the spacing, never from the river (the BVH is the only per-river structure).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "sim/half_float.h"
#include "sim/particle_tuning.h"
#include "sim/triangle_bvh.h"
#include "siviflow/sim/obstacle.h"
#include "siviflow/status.h"

namespace siviflow {

// The per-vertex river data the particles consume (the River Surface Generator's and the stream
// function's output, or any mesh with the same data). Spans into caller-owned arrays: they must
// outlive the ParticleField. Positions and indices must not change after create() (the BVH is
// built on them); flow, speed, depth, slope and foam may change between updates (they are re-read
// every update, so a re-solved flow reaches the particles the next frame). Depth and slope are
// binary16: a long river keeps them for its whole life, and its textures carry no more.
struct RiverFlowField {
  std::span<const glm::vec3> positions;  // world space, metres, +Y up
  std::span<const uint32_t> indices;     // 3 per triangle; empty: every 3 positions are one
  std::span<const glm::vec3> flow;       // flow vector per vertex (direction, or velocity)
  std::span<const float> speed;          // m/s per vertex; empty: |flow|
  HalfValues depth;                      // water depth per vertex, metres; empty: 0
  HalfValues slope;                      // riverbed slope per vertex; empty: 0
  std::span<const float> foam;           // foam per vertex, 0..1 (sim/foam.h); empty: 0
};

// What the particles see through: a world -> clip matrix in Vulkan conventions (clip depth 0..1,
// +Y down, i.e. the projection built with projection[1][1] *= -1) and the output size. Screen
// positions are in pixels of that output, origin top-left, pixel centres at +0.5.
struct ScreenCamera {
  glm::mat4 view_proj{1.0f};
  glm::uvec2 viewport{0u};
};

struct ParticleParams {
  uint64_t seed = 0;
  glm::uvec2 viewport{1280u, 720u};
  // Minimum screen distance between live particles; 0: kDefaultMinDistancePx scaled from 720
  // lines to the viewport height, raised to at least 1 px and to what fits kMaxParticleSlots
  // (tiny or very wide outputs). An explicit value below 1 px or needing more slots is refused.
  float min_distance_px = 0.0f;
  // New particles are placed this multiple of min_distance_px apart where there is room (>= 1);
  // the gaps left are then filled at the minimum distance, so the cover stays within it.
  float fill_spacing = kDefaultFillSpacing;
  float fade_in_seconds = kDefaultFadeInSeconds;    // 0: born active
  float fade_out_seconds = kDefaultFadeOutSeconds;  // 0: removed at once
  float vertex_search_radius = kDefaultVertexSearchRadius;  // metres
  // Advection along the flow (Yu et al.); off in the paper. A particle moves by
  // flow * advection_scale * dt and is snapped back onto the surface (one vertical ray and one
  // nearest-vertex query per particle per frame: not within the 1 ms budget at 1080p).
  bool advect = false;
  float advection_scale = 1.0f;
};

// An obstacle where it stands this frame: its footprint is dry ground in the river, and up to
// its top it hides the water behind it.
struct DryFootprint {
  const Obstacle* obstacle = nullptr;  // read during the update only
  glm::dvec2 centre_xz{0.0};
  // World height of its top: it hides the water behind it below there (-inf: flat, hides none).
  double top_y = -std::numeric_limits<double>::infinity();
};

enum class ParticleState : uint8_t { kActive, kFadingIn, kFadingOut };
// "active", "fading_in", "fading_out" (the `state` column of the particle dumps).
const char* to_string(ParticleState state);

struct Particle {
  uint32_t id = 0;    // unique over the run, from 1, in order of birth
  uint16_t slot = 0;  // 1..slot_count(): the GPU index (flow texture id, aux texel); reused
  ParticleState state = ParticleState::kFadingIn;
  float fade = 0.0f;         // 0..1: 0 invisible, 1 fully in
  glm::vec3 world{0.0f};     // on the river surface
  glm::vec2 screen{0.0f};    // this frame, pixels
  uint32_t vertex = 0;       // nearest river vertex: flow, speed, depth, slope, foam are its own
  glm::vec3 flow{0.0f};
  float speed = 0.0f;
  float depth = 0.0f;
  float slope = 0.0f;
  float foam = 0.0f;
  // Live particles take part in the Poisson-disk test; fading-out ones do not.
  bool live() const { return state != ParticleState::kFadingOut; }
};

// What the last update did (for tests, logs and the benchmark).
struct ParticleStats {
  uint32_t live = 0;
  uint32_t fading_out = 0;
  uint32_t born = 0;
  uint32_t expired = 0;   // fade-out finished
  uint32_t culled = 0;    // outside the frustum + margin
  uint32_t thinned = 0;   // started fading out: too close to an older live particle
  uint32_t revived = 0;   // fading out, spot free again: fading back in
  uint32_t evicted = 0;   // fading out, slot taken early because the slots ran out
  uint32_t left_river = 0;  // advection carried it off the water
  uint32_t dry = 0;       // a footprint or an occluder came to cover or hide it (removed at once)
  uint32_t dry_hits = 0;  // pixel rays that met the river inside a footprint (no particle)
  uint32_t hidden_hits = 0;  // pixel rays that met an obstacle or occluder before the river
  uint32_t rays = 0;      // pixel rays cast (conversion and seeding)
  uint32_t ray_misses = 0;
  uint32_t arc_checks = 0;  // particles whose fill circle was recomputed
  uint32_t seed_tests = 0;  // seed cells tested
  bool cut = false;         // the frame rebuilt everything (first frame or camera cut)
};

class ParticleField {
 public:
  // Validates the river (sizes of the per-vertex spans, indices, finite positions) and the
  // parameters, builds the BVH (O(n log n) in the triangles, done once) and sizes every buffer
  // from the viewport. Fails with a message naming what is wrong; `out` is untouched then.
  static Status create(const RiverFlowField& river, const ParticleParams& params,
                       ParticleField* out);
  // The same with a BVH already built on river.positions / river.indices (the same spans), so
  // a new viewport or a second view of a large river does not rebuild it.
  static Status create(const RiverFlowField& river, std::shared_ptr<const TriangleBvh> bvh,
                       const ParticleParams& params, ParticleField* out);

  // Advances one frame (Algorithm 2). `camera.viewport` must equal params.viewport and
  // `frame_index` must be next_frame(); dt_seconds >= 0 drives the fades and the advection;
  // `dry`: the obstacles' footprints where they stand this frame (a change re-examines the
  // cover as a camera move does). On failure nothing changes.
  Status update(const ScreenCamera& camera, uint64_t frame_index, float dt_seconds,
                std::span<const DryFootprint> dry = {});
  // Back to the state before frame 0 (ids restart at 1).
  void reset();

  // Static geometry that can stand between the camera and the water (the host's ground and
  // objects; the obstacles come with update()): no particle is made on water it hides, and the
  // next update re-examines every particle as a camera move does. Null: none.
  void set_occluders(std::shared_ptr<const TriangleBvh> occluders);
  const std::shared_ptr<const TriangleBvh>& occluders() const { return occluders_; }

  // In id order (ascending), so in birth order.
  std::span<const Particle> particles() const { return particles_; }
  const ParticleStats& stats() const { return stats_; }
  uint64_t next_frame() const { return next_frame_; }

  const ParticleParams& params() const { return params_; }
  float min_distance_px() const { return min_distance_; }
  // With the camera still (or on the first frame, or a cut) the fill leaves no point of the
  // visible water (away from its edges) farther than this from a live particle: the minimum
  // distance plus a hair against float noise. While the camera moves, gaps are filled once
  // they exceed moving_cover_radius_px() (hysteresis against churn); the frame it stops, the
  // exact cover is restored.
  float cover_radius_px() const { return tight_spacing_; }
  float moving_cover_radius_px() const { return moving_spacing_; }
  // Slots run from 1 to slot_count() (0 is "no particle"): the aux data needs slot_count() + 1
  // entries. Fixed by the viewport and the spacing.
  uint32_t slot_count() const { return slot_count_; }
  const TriangleBvh& bvh() const { return *bvh_; }
  std::shared_ptr<const TriangleBvh> shared_bvh() const { return bvh_; }
  const RiverFlowField& river() const { return river_; }

 private:
  // Per-slot upkeep caches; a slot belongs to one particle for its whole life.
  struct SlotData {
    uint32_t dry_mask = 0;       // sectors of the fill circle whose ray missed the water
    uint32_t dry_epoch = 0;      // camera epoch the dry sectors were found in
    uint32_t settled_epoch = 0;  // camera epoch the fill circle was last found full in
    bool settled = false;        // the fill circle had no free arc left
    bool dirty = true;           // a neighbour went away: recompute the fill circle
    bool tight = false;          // settled to the exact cover (camera still), not the moving one
  };
  struct Frame;  // per-update scratch: camera, generator, domains
  struct Neighbour {
    float angle;     // of the direction from the particle being grown, radians
    float distance;  // pixels
  };
  static Neighbour neighbour(const glm::vec2& c, const glm::vec2& q);

  void clear_state();
  // Takes this frame's footprints (with bounds); true when they differ from the last frame's.
  bool take_dry(std::span<const DryFootprint> dry);
  bool on_dry_ground(const glm::vec3& p) const;
  // Whether the sight line from `eye` to the water at `p` passes through an obstacle's solid
  // (its footprint from the water up to its top).
  bool hidden_by_obstacle(const glm::dvec3& eye, const glm::vec3& p) const;
  // Whether it meets one of the occluders' triangles.
  bool hidden_by_occluder(const glm::dvec3& eye, const glm::vec3& p) const;
  // The point where the pixel ray through `screen` starts (the near plane), and its direction.
  static void pixel_ray(const Frame& f, const glm::vec2& screen, glm::dvec3* origin, glm::dvec3* dir,
                        float* t_max);
  // The particles whose fill circles reach where a footprint was or now is look at them again:
  // water a footprint left is covered at once, even under a still camera.
  void recheck_around_changed_footprints(const Frame& f);
  void take_vertex_attributes(Particle& p) const;
  void advance_fades(float dt);
  void advect(float dt);
  void project_and_cull(Frame& f);
  void refresh_attributes();
  void build_grid();
  void grid_insert(uint32_t index);
  bool any_live_within(const glm::vec2& p, float radius, uint32_t except) const;
  void mark_dirty_around(const glm::vec2& p, float radius);
  void thin_and_revive(Frame& f);
  void fill(Frame& f);
  void grow(Frame& f, uint32_t index);
  void seed(Frame& f);
  bool try_create(Frame& f, const glm::vec2& screen, uint32_t* index);
  bool acquire_slot(uint16_t* slot);
  void release_slot(uint16_t slot);
  void convert(Particle& p, const RayHit& hit) const;
  void remove_dead();

  RiverFlowField river_;
  ParticleParams params_;
  std::shared_ptr<const TriangleBvh> bvh_;
  std::shared_ptr<const TriangleBvh> occluders_;
  bool occluders_changed_ = false;  // since the last update: look at every particle again
  float min_distance_ = 0.0f;  // px
  float spacing_ = 0.0f;        // px: preferred placement distance of the fill (first tier)
  float tight_spacing_ = 0.0f;  // px: placement distance of the second tier (the gaps)
  float moving_spacing_ = 0.0f; // px: the same while the camera moves (kMovingCoverFactor)
  float fill_margin_ = 0.0f;
  float cull_margin_ = 0.0f;
  uint32_t slot_count_ = 0;

  // Screen grid of live particles over the cull domain: cells of min_distance_ pixels, each a
  // linked list through grid_next_ (indices into particles_). Also the seed grid.
  glm::vec2 grid_origin_{0.0f};
  int grid_w_ = 0;
  int grid_h_ = 0;
  std::vector<int32_t> grid_head_;
  std::vector<int32_t> grid_next_;
  std::vector<uint32_t> seed_epoch_;  // per cell: camera epoch of its last seed test (+1)

  std::vector<Particle> particles_;
  std::vector<SlotData> slots_;        // indexed by slot
  std::vector<uint16_t> free_slots_;   // min-heap: the lowest free slot is reused first
  std::vector<uint32_t> queue_;        // fill candidates (indices into particles_)
  std::vector<glm::vec2> removed_at_;  // screen positions of this frame's thinned particles
  std::vector<float> arcs_;            // scratch: free arcs as [begin, end) pairs of angles
  std::vector<float> arcs_tmp_;        // scratch of the arc subtraction
  std::vector<glm::vec2> near_;        // scratch: screen positions around a gap being filled
  std::vector<Neighbour> neighbours_;  // scratch: the live neighbours of the particle grown

  uint32_t next_id_ = 1;
  uint64_t next_frame_ = 0;
  uint32_t camera_epoch_ = 0;  // bumps whenever the camera changes (moves beyond float noise)
  glm::mat4 epoch_view_proj_{0.0f};  // the camera the current epoch began with
  struct PlacedFootprint {
    Obstacle obstacle;  // a copy: the caller's may change in place between frames
    glm::dvec2 centre_xz{0.0};
    double top_y = 0.0;
    glm::dvec2 lo{0.0}, hi{0.0};
    bool hides() const { return top_y > -std::numeric_limits<double>::infinity(); }
  };
  std::vector<PlacedFootprint> dry_;  // this frame's
  std::vector<std::pair<glm::dvec2, glm::dvec2>> dry_changed_;  // bounds where they changed
  bool dry_changed_hides_ = false;  // one of those stands above the water (or stood)
  bool any_dry_hides_ = false;      // some footprint of this frame stands above the water
  ParticleStats stats_;
};

}  // namespace siviflow
