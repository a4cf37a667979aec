#include "sim/particles.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

namespace siviflow {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kTwoPi = 2.0f * kPi;
// Free arcs narrower than this (radians) are float dust, not room for a particle.
constexpr float kMinArc = 1e-6f;
// Half-width (radians) removed around every placement, whatever the new particle's disc covers.
constexpr float kMinProgressArc = 1e-3f;
// Largest viewport side accepted (beyond any swapchain or capture we make).
constexpr uint32_t kMaxViewportSide = 16384;

// atan2 to ~1e-5 rad (a minimax polynomial on the first octant): a few times cheaper than libm,
// and the error moves a fill point by well under 1e-3 px (the hard distance check is exact).
float fast_atan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (mx == 0.0f) return 0.0f;
  const float a = mn / mx, s = a * a;
  float r = ((((-0.0117212f * s + 0.05265332f) * s - 0.11643287f) * s + 0.19354346f) * s -
             0.33262347f) * s * a + 0.99997726f * a;
  if (ay > ax) r = 1.57079637f - r;
  if (x < 0.0f) r = 3.14159274f - r;
  return y < 0.0f ? -r : r;
}

// acos(k) for k in [-1, 1], through fast_atan2.
float fast_acos(float k) { return fast_atan2(std::sqrt(std::max(0.0f, 1.0f - k * k)), k); }

// SplitMix64: tiny, fast and the same on every platform (std distributions are not).
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }  // [0, 1)

 private:
  uint64_t state_;
};

// The generator of one frame depends on (seed, frame) only, never on earlier frames' draws.
uint64_t frame_seed(uint64_t seed, uint64_t frame) {
  Rng a(seed);
  Rng b(a.next() ^ (frame * 0xd1b54a32d192ed03ull));
  return b.next();
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// World -> screen pixels; false behind the eye or outside the depth range [0, w].
bool project(const glm::mat4& vp, const glm::vec2& size, const glm::vec3& w, glm::vec2* s) {
  const glm::vec4 c = vp * glm::vec4(w, 1.0f);
  if (!(c.w > 0.0f) || c.z < 0.0f || c.z > c.w) return false;
  const float inv = 1.0f / c.w;
  *s = glm::vec2((c.x * inv * 0.5f + 0.5f) * size.x, (c.y * inv * 0.5f + 0.5f) * size.y);
  return std::isfinite(s->x) && std::isfinite(s->y);
}

// Whether a projection maps the near plane to depth 1 (reverse-Z): the depth-0 point of the
// centre pixel is at infinity, or farther from the eye than the depth-1 point. The eye is
// where view_proj sends (0, 0, z, 0) back from: inverse * (0, 0, 1, 0).
bool is_reverse_z(const glm::dmat4& inv_vp) {
  const glm::dvec4 zero = inv_vp * glm::dvec4(0.0, 0.0, 0.0, 1.0);
  const glm::dvec4 one = inv_vp * glm::dvec4(0.0, 0.0, 1.0, 1.0);
  const glm::dvec4 eye = inv_vp * glm::dvec4(0.0, 0.0, 1.0, 0.0);
  if (std::fabs(zero.w) <= 1e-12 * std::fabs(one.w)) return true;
  if (std::fabs(one.w) <= 1e-12 * std::fabs(zero.w)) return false;
  const glm::dvec3 e = glm::dvec3(eye) / eye.w;
  return glm::length(glm::dvec3(zero) / zero.w - e) > glm::length(glm::dvec3(one) / one.w - e);
}

// Whether `a` is `b` up to float rounding: every entry within kStillCameraEpsilon of its column's
// largest (a column scales one world coordinate, so rounding is relative to it, not to the entry).
bool same_camera(const glm::mat4& a, const glm::mat4& b) {
  for (int c = 0; c < 4; ++c) {
    float scale = 0.0f, diff = 0.0f;
    for (int r = 0; r < 4; ++r) {
      scale = std::max({scale, std::fabs(a[c][r]), std::fabs(b[c][r])});
      diff = std::max(diff, std::fabs(a[c][r] - b[c][r]));
    }
    if (!(diff <= kStillCameraEpsilon * scale)) return false;
  }
  return true;
}

float dist2(const glm::vec2& a, const glm::vec2& b) {
  const glm::vec2 e = a - b;
  return e.x * e.x + e.y * e.y;
}

struct Rect {
  float x0, y0, x1, y1;
  bool contains(const glm::vec2& p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
};

// The free part of a particle's fill circle: sorted, disjoint [begin, end) angle pairs in
// [0, 2 pi). Subtracting only ever shrinks it, which is what makes the fill terminate.
class Arcs {
 public:
  Arcs(std::vector<float>& storage, std::vector<float>& scratch) : a_(storage), tmp_(scratch) {
    a_.assign({0.0f, kTwoPi});
  }
  bool empty() const { return a_.empty(); }
  void clear() { a_.clear(); }
  // Removes the angles within `half` of `centre`.
  void subtract(float centre, float half) {
    if (a_.empty() || !(half > 0.0f)) return;
    if (half >= kPi) {
      a_.clear();
      return;
    }
    if (centre < 0.0f) centre += kTwoPi;  // callers pass (-2 pi, 2 pi)
    if (centre >= kTwoPi) centre -= kTwoPi;
    const float lo = centre - half, hi = centre + half;
    if (lo < 0.0f) {
      subtract_linear(lo + kTwoPi, kTwoPi);
      subtract_linear(0.0f, hi);
    } else if (hi > kTwoPi) {
      subtract_linear(lo, kTwoPi);
      subtract_linear(0.0f, hi - kTwoPi);
    } else {
      subtract_linear(lo, hi);
    }
  }
  // Removes the angles theta with cos(theta - centre) > k (a cap of the circle).
  void subtract_cap(float centre, float k) {
    if (k >= 1.0f) return;
    if (k <= -1.0f) {
      a_.clear();
      return;
    }
    subtract(centre, fast_acos(k));
  }
  float total() const {
    float t = 0.0f;
    for (size_t i = 0; i < a_.size(); i += 2) t += a_[i + 1] - a_[i];
    return t;
  }
  // Maps u in [0, 1) uniformly onto the free angles.
  float sample(float u) const {
    float rest = u * total();
    for (size_t i = 0; i < a_.size(); i += 2) {
      const float len = a_[i + 1] - a_[i];
      if (rest < len) return a_[i] + rest;
      rest -= len;
    }
    return a_[a_.size() - 2];  // u * total rounded up past the end
  }

 private:
  void subtract_linear(float lo, float hi) {
    tmp_.clear();
    for (size_t i = 0; i < a_.size(); i += 2) {
      const float a = a_[i], b = a_[i + 1];
      if (b <= lo || a >= hi) {
        tmp_.push_back(a);
        tmp_.push_back(b);
        continue;
      }
      if (lo - a > kMinArc) {
        tmp_.push_back(a);
        tmp_.push_back(lo);
      }
      if (b - hi > kMinArc) {
        tmp_.push_back(hi);
        tmp_.push_back(b);
      }
    }
    a_.swap(tmp_);
  }
  std::vector<float>& a_;
  std::vector<float>& tmp_;
};

}  // namespace

const char* to_string(ParticleState state) {
  switch (state) {
    case ParticleState::kActive: return "active";
    case ParticleState::kFadingIn: return "fading_in";
    case ParticleState::kFadingOut: return "fading_out";
  }
  return "unknown";
}

namespace {

// The smallest spacing whose slot bound (slots_for in check_inputs) fits kMaxParticleSlots on
// viewport vp, up to rounding: with k = kSlotsPerLiveBound * 2 / sqrt(3) and the cull region
// (w + c d) x (h + c d), solves k (w + c d)(h + c d) = n d^2 for d, n leaving room for the ceils.
float min_spacing_for_slots(glm::uvec2 vp) {
  const double k = kSlotsPerLiveBound * 2.0 / std::sqrt(3.0);
  const double c = 2.0 * kCullMarginFactor + 1.0;
  const double w = vp.x, h = vp.y, n = kMaxParticleSlots - 2.0 * kSlotsPerLiveBound;
  const double qa = n - k * c * c, qb = -k * c * (w + h), qc = -k * w * h;  // qa d^2 + qb d + qc
  if (!(qa > 0.0)) return std::numeric_limits<float>::infinity();
  return static_cast<float>((-qb + std::sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa));
}

// Everything create() can refuse before building anything; the spacing and slot count.
Status check_inputs(const RiverFlowField& river, const ParticleParams& params, float* min_distance,
                    uint32_t* slot_count) {
  const size_t n = river.positions.size();
  if (n == 0) return Status::error("particles: the river has no vertices");
  if (river.flow.size() != n) {
    return Status::error("particles: the river has " + std::to_string(n) + " positions but " +
                         std::to_string(river.flow.size()) + " flow vectors");
  }
  const auto check_scalars = [n](const auto& s, const char* what) {
    if (!s.empty() && s.size() != n) {
      return Status::error(std::string("particles: the river has ") + std::to_string(n) +
                           " positions but " + std::to_string(s.size()) + " " + what +
                           " values (give one per vertex, or none)");
    }
    for (size_t i = 0; i < s.size(); ++i) {
      if (!std::isfinite(s[i])) {
        return Status::error(std::string("particles: ") + what + " of vertex " +
                             std::to_string(i) + " is not finite");
      }
    }
    return Status::success();
  };
  SIVIFLOW_TRY(check_scalars(river.speed, "speed"));
  SIVIFLOW_TRY(check_scalars(river.depth, "depth"));
  SIVIFLOW_TRY(check_scalars(river.slope, "slope"));
  SIVIFLOW_TRY(check_scalars(river.foam, "foam"));
  for (size_t i = 0; i < n; ++i) {
    if (!finite(river.flow[i])) {
      return Status::error("particles: flow of vertex " + std::to_string(i) + " is not finite");
    }
  }

  const glm::uvec2 vp = params.viewport;
  if (vp.x == 0 || vp.y == 0 || vp.x > kMaxViewportSide || vp.y > kMaxViewportSide) {
    return Status::error("particles: viewport " + std::to_string(vp.x) + "x" +
                         std::to_string(vp.y) + " is empty or larger than " +
                         std::to_string(kMaxViewportSide));
  }
  if (!std::isfinite(params.min_distance_px) || params.min_distance_px < 0.0f) {
    return Status::error("particles: min_distance_px must be finite and >= 0 (0: default)");
  }
  // Slots for spacing d: kSlotsPerLiveBound x the densest packing of discs of diameter d centred
  // in the culled region (live particles are pairwise >= d apart, so there are never more).
  const auto slots_for = [vp](double d) {
    const double cull_margin = kCullMarginFactor * d;
    const double a = static_cast<double>(vp.x) + 2.0 * cull_margin + d;
    const double b = static_cast<double>(vp.y) + 2.0 * cull_margin + d;
    const double live_bound = std::ceil(a * b * (2.0 / std::sqrt(3.0)) / (d * d));
    return std::ceil(live_bound * kSlotsPerLiveBound);
  };
  float d = params.min_distance_px;
  if (d == 0.0f) {
    // Automatic: scaled with the height, but at least 1 px and sparse enough for 16-bit ids, so
    // tiny and very wide outputs work (an explicit spacing is refused instead).
    d = std::max(1.0f, kDefaultMinDistancePx * static_cast<float>(vp.y) / kDefaultMinDistanceHeight);
    d = std::max(d, min_spacing_for_slots(vp));
    while (slots_for(d) > kMaxParticleSlots) d *= 1.0001f;  // the closed form's rounding
  }
  if (d < 1.0f) return Status::error("particles: min_distance_px below 1 pixel");
  if (!(params.fill_spacing >= 1.0f && params.fill_spacing <= 2.0f)) {
    return Status::error("particles: fill_spacing must be in [1, 2]");
  }
  if (!(params.fade_in_seconds >= 0.0f) || !std::isfinite(params.fade_in_seconds) ||
      !(params.fade_out_seconds >= 0.0f) || !std::isfinite(params.fade_out_seconds)) {
    return Status::error("particles: fade durations must be finite and >= 0");
  }
  if (!(params.vertex_search_radius >= 0.0f) || !std::isfinite(params.vertex_search_radius)) {
    return Status::error("particles: vertex_search_radius must be finite and >= 0");
  }
  if (!std::isfinite(params.advection_scale)) {
    return Status::error("particles: advection_scale must be finite");
  }

  const double slots = slots_for(d);
  if (!(slots <= kMaxParticleSlots)) {
    return Status::error("particles: min_distance_px " + std::to_string(d) + " is too small for a " +
                         std::to_string(vp.x) + "x" + std::to_string(vp.y) + " viewport (needs " +
                         std::to_string(static_cast<uint64_t>(slots)) + " particle slots, at most " +
                         std::to_string(kMaxParticleSlots) + " fit 16-bit ids)");
  }
  *min_distance = d;
  *slot_count = static_cast<uint32_t>(slots);
  return Status::success();
}

}  // namespace

struct ParticleField::Frame {
  glm::mat4 vp{1.0f};
  glm::dmat4 inv_vp{1.0};
  bool reverse_z = false;  // window depth 1 is the near plane, 0 the far
  glm::vec2 size{0.0f};
  uint64_t index = 0;
  Rng rng{0};
  bool camera_changed = false;
  bool cut = false;
  bool slots_exhausted = false;
  Rect fill{};
  Rect cull{};
  float cover = 0.0f;  // px: the fill's second tier, the cover radius it keeps this frame
};

Status ParticleField::create(const RiverFlowField& river, const ParticleParams& params,
                             ParticleField* out) {
  float d = 0.0f;
  uint32_t slot_count = 0;
  SIVIFLOW_TRY(check_inputs(river, params, &d, &slot_count));  // before the costly build
  auto bvh = std::make_shared<TriangleBvh>();
  SIVIFLOW_TRY(TriangleBvh::build(river.positions, river.indices, bvh.get()));
  return create(river, std::move(bvh), params, out);
}

Status ParticleField::create(const RiverFlowField& river, std::shared_ptr<const TriangleBvh> bvh,
                             const ParticleParams& params, ParticleField* out) {
  if (!bvh || bvh->positions().data() != river.positions.data() ||
      bvh->positions().size() != river.positions.size() ||
      bvh->indices().data() != river.indices.data() ||
      bvh->indices().size() != river.indices.size() || bvh->triangle_count() == 0) {
    return Status::error("particles: the BVH was not built on this river's positions and indices");
  }
  float d = 0.0f;
  uint32_t slot_count = 0;
  SIVIFLOW_TRY(check_inputs(river, params, &d, &slot_count));
  const float spacing = d * params.fill_spacing;
  const float cull_margin = kCullMarginFactor * d;
  const glm::uvec2 vp = params.viewport;

  ParticleField f;
  f.bvh_ = std::move(bvh);
  f.river_ = river;
  f.params_ = params;
  f.min_distance_ = d;
  f.spacing_ = spacing;
  f.tight_spacing_ = std::min(spacing, d * kTightSpacing);
  f.moving_spacing_ = std::min(spacing, d * std::max(kTightSpacing, kMovingCoverFactor));
  f.fill_margin_ = kFillMarginFactor * d;
  f.cull_margin_ = cull_margin;
  f.slot_count_ = slot_count;
  f.grid_origin_ = glm::vec2(-cull_margin);
  f.grid_w_ = static_cast<int>(std::ceil((vp.x + 2.0f * cull_margin) / d));
  f.grid_h_ = static_cast<int>(std::ceil((vp.y + 2.0f * cull_margin) / d));
  f.grid_head_.assign(static_cast<size_t>(f.grid_w_) * f.grid_h_, -1);
  f.seed_epoch_.assign(f.grid_head_.size(), 0);
  // Entries per frame: the survivors (<= slots) plus the births (<= slots): no reallocation.
  f.particles_.reserve(2 * size_t{f.slot_count_} + 1);
  f.grid_next_.assign(2 * size_t{f.slot_count_} + 1, -1);
  f.slots_.resize(size_t{f.slot_count_} + 1);
  f.queue_.reserve(2 * size_t{f.slot_count_} + 1);
  f.arcs_.reserve(256);
  f.arcs_tmp_.reserve(256);
  f.clear_state();
  *out = std::move(f);
  return Status::success();
}

void ParticleField::clear_state() {
  particles_.clear();
  std::fill(slots_.begin(), slots_.end(), SlotData{});
  free_slots_.resize(slot_count_);
  // Ascending order is already a min-heap under std::greater.
  for (uint32_t s = 0; s < slot_count_; ++s) free_slots_[s] = static_cast<uint16_t>(s + 1);
  std::fill(seed_epoch_.begin(), seed_epoch_.end(), 0u);
  next_id_ = 1;
  next_frame_ = 0;
  camera_epoch_ = 0;
  epoch_view_proj_ = glm::mat4(0.0f);
  dry_.clear();
  any_dry_hides_ = false;
  stats_ = {};
}

bool ParticleField::take_dry(std::span<const DryFootprint> dry) {
  dry_changed_.clear();
  dry_changed_hides_ = false;
  for (size_t i = dry.size(); i < dry_.size(); ++i) {
    dry_changed_.push_back({dry_[i].lo, dry_[i].hi});
    dry_changed_hides_ = dry_changed_hides_ || dry_[i].hides();
  }
  const size_t before = dry_.size();
  dry_.resize(dry.size());
  for (size_t i = 0; i < dry.size(); ++i) {
    PlacedFootprint& placed = dry_[i];
    const Obstacle& o = *dry[i].obstacle;
    if (i < before && placed.centre_xz == dry[i].centre_xz && placed.top_y == dry[i].top_y &&
        placed.obstacle.radius == o.radius && placed.obstacle.polygon == o.polygon) {
      continue;
    }
    if (i < before) {
      dry_changed_.push_back({placed.lo, placed.hi});
      dry_changed_hides_ = dry_changed_hides_ || placed.hides();
    }
    placed.obstacle.radius = o.radius;
    placed.obstacle.polygon = o.polygon;
    placed.centre_xz = dry[i].centre_xz;
    placed.top_y = dry[i].top_y;
    footprint_bounds(placed.obstacle, placed.centre_xz, &placed.lo, &placed.hi);
    dry_changed_.push_back({placed.lo, placed.hi});
    dry_changed_hides_ = dry_changed_hides_ || placed.hides();
  }
  any_dry_hides_ = std::any_of(dry_.begin(), dry_.end(), [](const PlacedFootprint& d) { return d.hides(); });
  return !dry_changed_.empty();
}

void ParticleField::recheck_around_changed_footprints(const Frame& f) {
  for (Particle& p : particles_) {
    if (p.slot == 0) continue;
    // How far this particle's fill circle reaches on the water: the circle's pixels over the
    // screen's scale there (along the more foreshortened of x and z), at least a margin.
    double reach = kDryRecheckMarginM;
    glm::vec2 along_x, along_z;
    if (project(f.vp, f.size, p.world + glm::vec3(kScaleProbeM, 0.0f, 0.0f), &along_x) &&
        project(f.vp, f.size, p.world + glm::vec3(0.0f, 0.0f, kScaleProbeM), &along_z)) {
      const float pixels_per_metre =
          std::min(glm::length(along_x - p.screen), glm::length(along_z - p.screen)) / kScaleProbeM;
      if (pixels_per_metre > 0.0f) {
        reach = std::clamp(double(kDryRecheckCircles * spacing_ / pixels_per_metre), reach,
                           kDryRecheckMaxM);
      }
    }
    const glm::dvec2 xz(p.world.x, p.world.z);
    for (const auto& [lo, hi] : dry_changed_) {
      if (glm::all(glm::greaterThanEqual(xz, lo - reach)) && glm::all(glm::lessThanEqual(xz, hi + reach))) {
        slots_[p.slot].dry_mask = 0;
        slots_[p.slot].dirty = true;
        break;
      }
    }
  }
}

bool ParticleField::hidden_by_occluder(const glm::dvec3& eye, const glm::vec3& p) const {
  if (occluders_ == nullptr) return false;
  // From the water towards the eye, leaving out the first few centimetres: ground that meets
  // the water at the shore must not hide the water it touches.
  const glm::dvec3 to_eye = eye - glm::dvec3(p);
  const double length = glm::length(to_eye);
  if (!(length > kSightLineSkipM)) return false;
  return occluders_->any_hit(p, glm::vec3(to_eye), float(kSightLineSkipM / length), 1.0f);
}

void ParticleField::set_occluders(std::shared_ptr<const TriangleBvh> occluders) {
  occluders_changed_ = occluders_changed_ || occluders != occluders_;
  occluders_ = std::move(occluders);
}

bool ParticleField::hidden_by_obstacle(const glm::dvec3& eye, const glm::vec3& p) const {
  if (!any_dry_hides_) return false;
  for (const PlacedFootprint& d : dry_) {
    if (!(d.top_y > p.y)) continue;  // no higher than the water here: hides nothing
    // The part of the sight line below the obstacle's top, seen from above.
    const double t = eye.y > d.top_y ? (eye.y - d.top_y) / (eye.y - double(p.y)) : 0.0;
    const glm::dvec3 from = eye + t * (glm::dvec3(p) - eye);
    const glm::dvec2 a(from.x, from.z), b(p.x, p.z);
    if (std::max(a.x, b.x) < d.lo.x || std::min(a.x, b.x) > d.hi.x ||
        std::max(a.y, b.y) < d.lo.y || std::min(a.y, b.y) > d.hi.y) {
      continue;
    }
    if (footprint_overlaps_segment(d.obstacle, d.centre_xz, a, b)) return true;
  }
  return false;
}

void ParticleField::pixel_ray(const Frame& f, const glm::vec2& screen, glm::dvec3* origin,
                              glm::dvec3* dir, float* t_max) {
  // From the near plane to the far plane (or towards infinity).
  const double nx = 2.0 * screen.x / f.size.x - 1.0, ny = 2.0 * screen.y / f.size.y - 1.0;
  const double near_depth = f.reverse_z ? 1.0 : 0.0;
  const glm::dvec4 a = f.inv_vp * glm::dvec4(nx, ny, near_depth, 1.0);
  const glm::dvec4 b = f.inv_vp * glm::dvec4(nx, ny, 1.0 - near_depth, 1.0);
  *origin = glm::dvec3(a) / a.w;
  *t_max = 1.0f;
  if (std::fabs(b.w) > 1e-12 * std::fabs(a.w) && (b.w > 0.0) == (a.w > 0.0)) {
    *dir = glm::dvec3(b) / b.w - *origin;
  } else {  // infinite far plane
    const glm::dvec4 m = f.inv_vp * glm::dvec4(nx, ny, 0.5, 1.0);
    *dir = glm::dvec3(m) / m.w - *origin;
    *t_max = std::numeric_limits<float>::max();
  }
}

bool ParticleField::on_dry_ground(const glm::vec3& p) const {
  const glm::dvec2 xz(p.x, p.z);
  for (const PlacedFootprint& d : dry_) {
    if (xz.x < d.lo.x || xz.y < d.lo.y || xz.x > d.hi.x || xz.y > d.hi.y) continue;
    if (footprint_distance(d.obstacle, d.centre_xz, xz) < 0.0) return true;
  }
  return false;
}

void ParticleField::reset() { clear_state(); }

bool ParticleField::acquire_slot(uint16_t* slot) {
  if (free_slots_.empty()) {
    // Evict the most faded fading-out particle (ties: the oldest): the least visible pop.
    int32_t victim = -1;
    for (size_t i = 0; i < particles_.size(); ++i) {
      const Particle& p = particles_[i];
      if (p.slot == 0 || p.state != ParticleState::kFadingOut) continue;
      if (victim < 0 || p.fade < particles_[victim].fade) victim = static_cast<int32_t>(i);
    }
    if (victim < 0) return false;
    release_slot(particles_[victim].slot);
    particles_[victim].slot = 0;
    stats_.evicted++;
  }
  std::pop_heap(free_slots_.begin(), free_slots_.end(), std::greater<uint16_t>());
  *slot = free_slots_.back();
  free_slots_.pop_back();
  slots_[*slot] = SlotData{};
  return true;
}

void ParticleField::release_slot(uint16_t slot) {
  free_slots_.push_back(slot);
  std::push_heap(free_slots_.begin(), free_slots_.end(), std::greater<uint16_t>());
}

void ParticleField::remove_dead() {
  particles_.erase(std::remove_if(particles_.begin(), particles_.end(),
                                  [](const Particle& p) { return p.slot == 0; }),
                   particles_.end());
}

void ParticleField::convert(Particle& p, const RayHit& hit) const {
  p.world = hit.position;
  p.vertex = bvh_->nearest_vertex(hit.position, params_.vertex_search_radius, hit.triangle);
}

void ParticleField::take_vertex_attributes(Particle& p) const {
  const uint32_t v = p.vertex;
  p.flow = river_.flow[v];
  p.speed = river_.speed.empty() ? glm::length(p.flow) : river_.speed[v];
  p.depth = river_.depth.empty() ? 0.0f : river_.depth[v];
  p.slope = river_.slope.empty() ? 0.0f : river_.slope[v];
  p.foam = river_.foam.empty() ? 0.0f : river_.foam[v];
}

void ParticleField::refresh_attributes() {
  for (Particle& p : particles_) take_vertex_attributes(p);
}

void ParticleField::advance_fades(float dt) {
  const float in_step = params_.fade_in_seconds > 0.0f ? dt / params_.fade_in_seconds : 1.0f;
  const float out_step = params_.fade_out_seconds > 0.0f ? dt / params_.fade_out_seconds : 1.0f;
  for (Particle& p : particles_) {
    if (p.state == ParticleState::kFadingIn) {
      p.fade = std::min(1.0f, p.fade + in_step);
      if (p.fade >= 1.0f) p.state = ParticleState::kActive;
    } else if (p.state == ParticleState::kFadingOut) {
      p.fade = std::max(0.0f, p.fade - out_step);
      if (p.fade <= 0.0f) {
        release_slot(p.slot);
        p.slot = 0;
        stats_.expired++;
      }
    }
  }
}

void ParticleField::advect(float dt) {
  for (Particle& p : particles_) {
    if (p.slot == 0) continue;
    const glm::vec3 step = p.flow * (params_.advection_scale * dt);
    const glm::vec3 moved = p.world + step;
    // Snap back onto the surface with a vertical ray (+Y up) long enough for the step's slope.
    const float reach = 1.0f + 2.0f * glm::length(step);
    RayHit hit;
    if (finite(moved) &&
        bvh_->intersect(moved + glm::vec3(0.0f, reach, 0.0f), glm::vec3(0.0f, -2.0f * reach, 0.0f),
                       1.0f, &hit)) {
      convert(p, hit);
      continue;
    }
    stats_.left_river++;
    if (p.state != ParticleState::kFadingOut) {
      if (params_.fade_out_seconds > 0.0f) {
        p.state = ParticleState::kFadingOut;
      } else {
        release_slot(p.slot);
        p.slot = 0;
      }
    }
  }
}

void ParticleField::project_and_cull(Frame& f) {
  removed_at_.clear();
  for (Particle& p : particles_) {
    if (p.slot == 0) continue;
    glm::vec2 s;
    const bool in_view = project(f.vp, f.size, p.world, &s) && f.cull.contains(s);
    bool unseen = in_view && on_dry_ground(p.world);  // covered or hidden by an obstacle
    // The occluders are static: only what counts as a camera move (f.camera_changed: the
    // camera, advection, a hiding obstacle moving, new occluders) can make them hide one.
    const bool check_occluders = occluders_ != nullptr && f.camera_changed;
    if (in_view && !unseen && (any_dry_hides_ || check_occluders)) {
      glm::dvec3 origin, dir;
      float t_max = 0.0f;
      pixel_ray(f, s, &origin, &dir, &t_max);
      unseen = hidden_by_obstacle(origin, p.world) ||
               (check_occluders && hidden_by_occluder(origin, p.world));
    }
    if (in_view && !unseen) {
      p.screen = s;
      continue;
    }
    release_slot(p.slot);
    p.slot = 0;
    (unseen ? stats_.dry : stats_.culled)++;
  }
}

void ParticleField::build_grid() { std::fill(grid_head_.begin(), grid_head_.end(), -1); }

void ParticleField::grid_insert(uint32_t index) {
  const glm::vec2 g = (particles_[index].screen - grid_origin_) / min_distance_;
  const int cx = std::clamp(static_cast<int>(std::floor(g.x)), 0, grid_w_ - 1);
  const int cy = std::clamp(static_cast<int>(std::floor(g.y)), 0, grid_h_ - 1);
  const size_t c = static_cast<size_t>(cy) * grid_w_ + cx;
  grid_next_[index] = grid_head_[c];
  grid_head_[c] = static_cast<int32_t>(index);
}

namespace {
// Cells of `cell`-sized grid overlapped by the square of half-size r around p.
struct CellRange {
  int x0, y0, x1, y1;
};
CellRange cells_around(const glm::vec2& p, float r, const glm::vec2& origin, float cell, int w,
                       int h) {
  const glm::vec2 lo = (p - r - origin) / cell, hi = (p + r - origin) / cell;
  return {std::clamp(static_cast<int>(std::floor(lo.x)), 0, w - 1),
          std::clamp(static_cast<int>(std::floor(lo.y)), 0, h - 1),
          std::clamp(static_cast<int>(std::floor(hi.x)), 0, w - 1),
          std::clamp(static_cast<int>(std::floor(hi.y)), 0, h - 1)};
}
}  // namespace

bool ParticleField::any_live_within(const glm::vec2& p, float radius, uint32_t except) const {
  const float r2 = radius * radius;
  const CellRange c = cells_around(p, radius, grid_origin_, min_distance_, grid_w_, grid_h_);
  for (int y = c.y0; y <= c.y1; ++y) {
    for (int x = c.x0; x <= c.x1; ++x) {
      for (int32_t j = grid_head_[static_cast<size_t>(y) * grid_w_ + x]; j >= 0; j = grid_next_[j]) {
        if (static_cast<uint32_t>(j) != except && dist2(particles_[j].screen, p) < r2) return true;
      }
    }
  }
  return false;
}

void ParticleField::mark_dirty_around(const glm::vec2& p, float radius) {
  const float r2 = radius * radius;
  const CellRange c = cells_around(p, radius, grid_origin_, min_distance_, grid_w_, grid_h_);
  for (int y = c.y0; y <= c.y1; ++y) {
    for (int x = c.x0; x <= c.x1; ++x) {
      for (int32_t j = grid_head_[static_cast<size_t>(y) * grid_w_ + x]; j >= 0; j = grid_next_[j]) {
        if (dist2(particles_[j].screen, p) < r2) slots_[particles_[j].slot].dirty = true;
      }
    }
  }
}

void ParticleField::thin_and_revive(Frame& f) {
  build_grid();
  // Oldest first: the particle that has been on screen longest keeps its place.
  for (uint32_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    if (p.slot == 0 || !p.live()) continue;
    if (!any_live_within(p.screen, min_distance_, i)) {
      grid_insert(i);
      continue;
    }
    stats_.thinned++;
    removed_at_.push_back(p.screen);
    if (params_.fade_out_seconds > 0.0f) {
      p.state = ParticleState::kFadingOut;
    } else {
      release_slot(p.slot);
      p.slot = 0;
    }
  }
  // A fading-out particle whose spot is free again (by the fill spacing, so a pair jittering
  // around the minimum distance does not flip every frame) fades back in instead of a new one.
  for (uint32_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    if (p.slot == 0 || p.state != ParticleState::kFadingOut) continue;
    if (!f.fill.contains(p.screen) || any_live_within(p.screen, spacing_, i)) continue;
    p.state = ParticleState::kFadingIn;
    slots_[p.slot].dirty = true;
    grid_insert(i);
    stats_.revived++;
  }
  // Only a circle the removed disc overlapped can have opened (coverage is the second tier).
  for (const glm::vec2& at : removed_at_) mark_dirty_around(at, 2.0f * f.cover);
}

bool ParticleField::try_create(Frame& f, const glm::vec2& screen, uint32_t* index) {
  if (f.slots_exhausted || !f.fill.contains(screen)) return false;
  glm::dvec3 origin, dir;
  float t_max = 1.0f;
  pixel_ray(f, screen, &origin, &dir, &t_max);
  stats_.rays++;
  RayHit hit;
  if (!bvh_->intersect(glm::vec3(origin), glm::vec3(dir), t_max, &hit)) {
    stats_.ray_misses++;
    return false;
  }
  if (on_dry_ground(hit.position)) {  // as a miss: no water to be seen there
    stats_.dry_hits++;
    return false;
  }
  if (hidden_by_obstacle(origin, hit.position) || hidden_by_occluder(origin, hit.position)) {
    stats_.hidden_hits++;
    return false;
  }
  // Distances are checked at the re-projected hit, the position every later frame will use.
  glm::vec2 s;
  if (!project(f.vp, f.size, hit.position, &s) || !f.fill.contains(s) ||
      any_live_within(s, min_distance_, std::numeric_limits<uint32_t>::max())) {
    return false;
  }
  uint16_t slot = 0;
  if (!acquire_slot(&slot)) {
    f.slots_exhausted = true;
    return false;
  }
  Particle p;
  p.id = next_id_++;
  p.slot = slot;
  const bool fades = params_.fade_in_seconds > 0.0f;
  p.state = fades ? ParticleState::kFadingIn : ParticleState::kActive;
  p.fade = fades ? 0.0f : 1.0f;
  p.screen = s;
  convert(p, hit);
  take_vertex_attributes(p);
  *index = static_cast<uint32_t>(particles_.size());
  particles_.push_back(p);
  grid_insert(*index);
  stats_.born++;
  return true;
}

ParticleField::Neighbour ParticleField::neighbour(const glm::vec2& c, const glm::vec2& q) {
  const glm::vec2 e = q - c;
  return {fast_atan2(e.y, e.x), std::sqrt(e.x * e.x + e.y * e.y)};
}

// Dunbar-Humphreys boundary sampling around one live particle: the free arcs of its circle
// (not inside a neighbour's disc, the fill domain or a dry sector) get new particles at random
// angles until none is left; each new particle is queued to be grown in turn.
void ParticleField::grow(Frame& f, uint32_t index) {
  const glm::vec2 c = particles_[index].screen;
  SlotData& sd = slots_[particles_[index].slot];
  stats_.arc_checks++;
  const float sector = kTwoPi / kDrySectors;
  // Two tiers: first the preferred spacing (pairs that survive some perspective squeeze), then
  // the minimum distance for the gaps the first tier leaves, so the water is covered within it.
  const float tiers[2] = {spacing_, f.cover};
  // The live neighbours that can cover part of either tier's circle, measured once.
  neighbours_.clear();
  const float reach2 = 4.0f * spacing_ * spacing_;
  const CellRange cr = cells_around(c, 2.0f * spacing_, grid_origin_, min_distance_, grid_w_, grid_h_);
  for (int y = cr.y0; y <= cr.y1; ++y) {
    for (int x = cr.x0; x <= cr.x1; ++x) {
      for (int32_t j = grid_head_[static_cast<size_t>(y) * grid_w_ + x]; j >= 0; j = grid_next_[j]) {
        if (static_cast<uint32_t>(j) == index) continue;
        const glm::vec2 q = particles_[j].screen;
        if (dist2(q, c) < reach2) neighbours_.push_back(neighbour(c, q));
      }
    }
  }
  for (int tier = 0; tier < 2 && !f.slots_exhausted; ++tier) {
    const float rho = tiers[tier];
    if (tier == 1 && !(rho < tiers[0])) break;
    Arcs arcs(arcs_, arcs_tmp_);
    // The fill domain's outside.
    arcs.subtract_cap(kPi, (c.x - f.fill.x0) / rho);
    arcs.subtract_cap(0.0f, (f.fill.x1 - c.x) / rho);
    arcs.subtract_cap(1.5f * kPi, (c.y - f.fill.y0) / rho);
    arcs.subtract_cap(0.5f * kPi, (f.fill.y1 - c.y) / rho);
    // Every live neighbour's disc: points of the circle closer than rho to it.
    const auto subtract_neighbour = [&](const Neighbour& n) {
      if (n.distance >= 2.0f * rho) return;
      if (n.distance <= 0.0f) {
        arcs.clear();
        return;
      }
      arcs.subtract_cap(n.angle, n.distance / (2.0f * rho));
    };
    for (size_t k = 0; k < neighbours_.size() && !arcs.empty(); ++k) subtract_neighbour(neighbours_[k]);
    for (uint32_t k = 0; k < kDrySectors && !arcs.empty(); ++k) {
      if (sd.dry_mask & (1u << k)) arcs.subtract((k + 0.5f) * sector, 0.5f * sector);
    }
    bool near_ready = false;
    while (!arcs.empty() && !f.slots_exhausted) {
      const float theta = arcs.sample(f.rng.uniform());
      const glm::vec2 u(std::cos(theta), std::sin(theta));
      const glm::vec2 at = c + rho * u;
      uint32_t born = 0;
      bool made = false;
      if (tier == 1 && !near_ready) {  // the particles a gap filler is pushed away from
        near_ready = true;
        near_.clear();
        const float reach = kGapDeepening * rho + 2.0f * rho;
        const CellRange nr = cells_around(c, reach, grid_origin_, min_distance_, grid_w_, grid_h_);
        for (int y = nr.y0; y <= nr.y1; ++y) {
          for (int x = nr.x0; x <= nr.x1; ++x) {
            for (int32_t j = grid_head_[static_cast<size_t>(y) * grid_w_ + x]; j >= 0;
                 j = grid_next_[j]) {
              near_.push_back(particles_[j].screen);  // includes c itself, at distance t
            }
          }
        }
      }
      if (tier == 1) {
        // A gap filler placed on the circle would sit at the minimum distance from c and be
        // thinned by the first squeeze; push it out along the ray to the point of the gap
        // farthest from every particle (still covering `at`, so the arc always shrinks).
        float best_t = rho, best_m = 0.0f;
        for (int k = 0; k <= kGapDeepeningSteps; ++k) {
          const float t = rho * (1.0f + kGapDeepening * static_cast<float>(k) / kGapDeepeningSteps);
          const glm::vec2 q = c + t * u;
          if (!f.fill.contains(q)) break;
          float m2 = std::numeric_limits<float>::infinity();
          for (const glm::vec2& n : near_) m2 = std::min(m2, dist2(n, q));
          if (m2 > best_m) {
            best_m = m2;
            best_t = t;
          }
        }
        if (best_t > rho) made = try_create(f, c + best_t * u, &born);
      }
      if (made || try_create(f, at, &born)) {
        const Neighbour n = neighbour(c, particles_[born].screen);
        neighbours_.push_back(n);
        subtract_neighbour(n);
        arcs.subtract(theta, kMinProgressArc);  // progress even if float put it out of reach
        if (tier == 1) near_.push_back(particles_[born].screen);
        queue_.push_back(born);
        continue;
      }
      if (f.slots_exhausted) break;
      // No water there (or no room once re-projected): that sector is spent for this camera.
      const uint32_t k = std::min(kDrySectors - 1, static_cast<uint32_t>(theta / sector));
      sd.dry_mask |= 1u << k;
      sd.dry_epoch = camera_epoch_;
      arcs.subtract((k + 0.5f) * sector, 0.5f * sector);
    }
  }
  if (!f.slots_exhausted) {
    sd.settled = true;
    sd.settled_epoch = camera_epoch_;
    sd.dirty = false;
    sd.tight = f.cover <= tight_spacing_;
  }
}

void ParticleField::fill(Frame& f) {
  queue_.clear();
  const float rho = spacing_;
  for (uint32_t i = 0; i < particles_.size(); ++i) {
    const Particle& p = particles_[i];
    if (p.slot == 0 || !p.live()) continue;
    SlotData& sd = slots_[p.slot];
    const bool stale = sd.settled_epoch != camera_epoch_;
    if (f.cut || (sd.dry_mask != 0 && sd.dry_epoch != camera_epoch_ &&
                  (f.index + p.id) % kDryRecheckFrames == 0)) {
      sd.dry_mask = 0;
      sd.dirty = true;
    }
    const bool near_edge = p.screen.x - rho < f.fill.x0 || p.screen.x + rho > f.fill.x1 ||
                           p.screen.y - rho < f.fill.y0 || p.screen.y + rho > f.fill.y1;
    // A circle settled while the camera moved (looser cover) is redone once it stops.
    const bool need = f.cut || !sd.settled || sd.dirty || (!f.camera_changed && !sd.tight) ||
                      (stale && ((f.index + p.id) % kArcRecheckFrames == 0 || near_edge));
    if (need) queue_.push_back(i);
  }
  for (size_t q = 0; q < queue_.size() && !f.slots_exhausted; ++q) grow(f, queue_[q]);
}

void ParticleField::seed(Frame& f) {
  const float cell = min_distance_;
  for (int cy = 0; cy < grid_h_ && !f.slots_exhausted; ++cy) {
    for (int cx = 0; cx < grid_w_ && !f.slots_exhausted; ++cx) {
      const glm::vec2 lo = grid_origin_ + cell * glm::vec2(cx, cy);
      const glm::vec2 centre = lo + 0.5f * cell;
      if (!f.fill.contains(centre)) continue;
      const size_t c = static_cast<size_t>(cy) * grid_w_ + cx;
      if (!f.cut) {
        if (seed_epoch_[c] == camera_epoch_) continue;
        const bool border = lo.x < f.fill.x0 || lo.y < f.fill.y0 || lo.x + cell > f.fill.x1 ||
                            lo.y + cell > f.fill.y1;
        const uint32_t period = border ? kSeedRecheckFramesBorder : kSeedRecheckFramesInterior;
        const uint64_t stagger = (static_cast<uint64_t>(c) * 2654435761u) >> 7;
        if ((f.index + stagger) % period != 0) continue;
      }
      seed_epoch_[c] = camera_epoch_;
      stats_.seed_tests++;
      glm::vec2 at = lo + cell * glm::vec2(f.rng.uniform(), f.rng.uniform());
      at = glm::clamp(at, glm::vec2(f.fill.x0, f.fill.y0), glm::vec2(f.fill.x1, f.fill.y1));
      if (any_live_within(at, f.cover, std::numeric_limits<uint32_t>::max())) continue;
      uint32_t born = 0;
      if (!try_create(f, at, &born)) continue;
      // Grow the new region at once, so the next cells of the grid find it covered.
      queue_.clear();
      queue_.push_back(born);
      for (size_t q = 0; q < queue_.size() && !f.slots_exhausted; ++q) grow(f, queue_[q]);
    }
  }
}

Status ParticleField::update(const ScreenCamera& camera, uint64_t frame_index, float dt_seconds,
                             std::span<const DryFootprint> dry) {
  if (grid_head_.empty()) return Status::error("particles: update on a field create() did not make");
  if (camera.viewport != params_.viewport) {
    return Status::error("particles: camera viewport " + std::to_string(camera.viewport.x) + "x" +
                         std::to_string(camera.viewport.y) + " differs from the field's " +
                         std::to_string(params_.viewport.x) + "x" +
                         std::to_string(params_.viewport.y));
  }
  if (frame_index != next_frame_) {
    return Status::error("particles: frame " + std::to_string(frame_index) + " is not the next one (" +
                         std::to_string(next_frame_) +
                         "); to start at a later frame, update every earlier frame first");
  }
  if (!std::isfinite(dt_seconds) || dt_seconds < 0.0f) {
    return Status::error("particles: dt must be finite and >= 0");
  }
  for (size_t i = 0; i < dry.size(); ++i) {
    if (dry[i].obstacle == nullptr || !std::isfinite(dry[i].centre_xz.x) ||
        !std::isfinite(dry[i].centre_xz.y) || std::isnan(dry[i].top_y)) {
      return Status::error("particles: dry footprint " + std::to_string(i) +
                           " has no obstacle, a centre that is not finite or a top that is NaN");
    }
  }
  Frame f;
  f.vp = camera.view_proj;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(f.vp[c][r])) return Status::error("particles: view_proj is not finite");
    }
  }
  const glm::dmat4 vpd(f.vp);
  const double det = glm::determinant(vpd);
  if (!std::isfinite(det) || std::fabs(det) < 1e-300) {
    return Status::error("particles: view_proj is singular");
  }
  f.inv_vp = glm::inverse(vpd);
  f.reverse_z = is_reverse_z(f.inv_vp);
  f.size = glm::vec2(params_.viewport);
  f.index = frame_index;
  f.rng = Rng(frame_seed(params_.seed, frame_index));
  const float m = fill_margin_, cm = cull_margin_;
  f.fill = {-m, -m, f.size.x + m, f.size.y + m};
  f.cull = {-cm, -cm, f.size.x + cm, f.size.y + cm};

  stats_ = {};
  // Advection moves the particles on screen just as a camera move does, and so does an obstacle
  // that hides water moving (what it uncovers may lie far behind it on screen), and so do new
  // occluders; a flat footprint moving only concerns the particles around it
  // (recheck_around_changed_footprints).
  // Compared with the camera the epoch began with, not last frame's, so a drift within the
  // tolerance cannot add up; exact equality would call a recomputed matrix's rounding a move.
  const bool dry_changed = take_dry(dry);
  f.camera_changed = next_frame_ == 0 || !same_camera(f.vp, epoch_view_proj_) ||
                     (params_.advect && dt_seconds > 0.0f) || (dry_changed && dry_changed_hides_) ||
                     occluders_changed_;
  occluders_changed_ = false;
  if (f.camera_changed) {
    ++camera_epoch_;
    epoch_view_proj_ = f.vp;
  }

  advance_fades(dt_seconds);
  if (params_.advect && dt_seconds > 0.0f) advect(dt_seconds);
  uint32_t live_before = 0;
  for (const Particle& p : particles_) live_before += p.slot != 0 && p.live();
  project_and_cull(f);
  if (dry_changed) recheck_around_changed_footprints(f);
  uint32_t live_after = 0;
  for (const Particle& p : particles_) live_after += p.slot != 0 && p.live();
  remove_dead();
  f.cut = next_frame_ == 0 || live_after == 0 ||
          static_cast<float>(live_before - live_after) > kCutCulledFraction * live_before;
  stats_.cut = f.cut;
  // Gaps are closed to the exact cover when the camera is still or cut, and only once they
  // exceed the moving cover while it moves: a gap that just opened, filled at once, would get
  // a particle squeezed against its neighbours and thinned again by the next frame's motion.
  f.cover = f.camera_changed && !f.cut ? moving_spacing_ : tight_spacing_;
  refresh_attributes();
  thin_and_revive(f);
  fill(f);
  seed(f);
  remove_dead();

  for (const Particle& p : particles_) {
    if (p.live()) {
      stats_.live++;
    } else {
      stats_.fading_out++;
    }
  }
  ++next_frame_;
  return Status::success();
}

}  // namespace siviflow
