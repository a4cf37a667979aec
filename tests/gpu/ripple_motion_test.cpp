// The ripples move with the flow: under a still camera over a straight channel with a boulder,
// the water's normal pattern (the `normal` AOV) is tracked between frames a few frames apart by
// phase correlation in a small window around each particle, and its motion compared with the
// particle's flow projected to the screen, for both materials: Tiled Directional Flow and the
// two-phase flow-map baseline. Floating bodies drifted by the gameplay queries (siviflow/drift.h)
// move the way the ripples under them do. About an island, the ripples follow its two arms.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/geometric.hpp>
#include <map>
#include <vector>

#include "phase_correlation.h"
#include "renderer_inspect.h"
#include "shaders/shared.h"
#include "sim/flow_textures.h"
#include "siviflow/drift.h"
#include "straight_channel.h"

namespace siviflow::testing {
namespace {

constexpr VkExtent2D kView{640, 360};
constexpr size_t kWindow = 32;   // pixels a side
constexpr uint32_t kFirst = 12;  // frames: the particles have faded in
constexpr uint32_t kApart = 3;   // frames between the two images compared: at most 6 px of
                                 // motion at the boulder's shoulders, which the windows track
constexpr double kFps = 30.0;
constexpr double kMinShift = 1.0;  // pixels: slower water is too still to measure a direction

struct Motion {
  glm::dvec2 measured;      // pixels over kApart frames
  glm::dvec2 expected;      // the particle's flow over the same time, projected
  double boulder_distance;  // metres from the boulder's centre
  glm::vec2 at;             // x and z of the particle
};

// A float's screen motion over kApart frames and the ripples' under it.
struct FloatMotion {
  glm::vec3 release{0.0f};
  glm::dvec2 measured{0.0};
  glm::dvec2 drifted{0.0};
};

struct Summary {
  size_t windows = 0;
  double angle_deg = 0.0;    // median angular error
  double speed_ratio = 0.0;  // median |measured| / |expected|
  size_t near_windows = 0;
  double near_angle_deg = 0.0;  // the same where the flow turns round the boulder
};

// The angle between two screen motions, in degrees.
double degrees_apart(const glm::dvec2& a, const glm::dvec2& b) {
  const double cosine = glm::dot(a, b) / std::max(glm::length(a) * glm::length(b), 1e-9);
  return glm::degrees(std::acos(std::clamp(cosine, -1.0, 1.0)));
}

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

class RippleMotionTest : public StraightChannelTest {
 protected:
  static constexpr glm::vec3 kBoulder{0.0f, 0.0f, 0.0f};

  // The normal's x and z (world tilt) of the window of `frame` whose top-left is `corner`;
  // false when it leaves the image or holds anything but water.
  bool window(const Frame& frame, glm::ivec2 corner, Window* out) const {
    if (corner.x < 0 || corner.y < 0 || corner.x + int(kWindow) > int(kView.width) ||
        corner.y + int(kWindow) > int(kView.height)) {
      return false;
    }
    out->size = kWindow;
    out->channels.assign(2, std::vector<double>(kWindow * kWindow));
    for (size_t y = 0; y < kWindow; ++y) {
      for (size_t x = 0; x < kWindow; ++x) {
        const size_t i = size_t(corner.y + y) * kView.width + size_t(corner.x + x);
        if (frame.water_mask[i] != 1.0f) return false;
        out->channels[0][y * kWindow + x] = frame.normal[i * 4 + 0];
        out->channels[1][y * kWindow + x] = frame.normal[i * 4 + 2];
      }
    }
    return true;
  }

  // The pattern's shift from `a` to `b` in the window centred on `centre`: measured once, then
  // again with b's window moved by the whole pixels of the first estimate (phase_correlation.h).
  bool track(const Frame& a, const Frame& b, glm::dvec2 centre, glm::dvec2* shift) const {
    const glm::ivec2 corner = glm::ivec2(glm::round(centre)) - glm::ivec2(kWindow / 2);
    Window first, second;
    if (!window(a, corner, &first) || !window(b, corner, &second)) return false;
    const glm::ivec2 moved = glm::ivec2(glm::round(phase_correlation_shift(first, second)));
    if (!window(b, corner + moved, &second)) return false;
    *shift = glm::dvec2(moved) + phase_correlation_shift(first, second);
    return true;
  }

  // Every particle of frame `a` whose window is all water, its motion to frame `b`.
  std::vector<Motion> motions(const Frame& a, const Frame& b) const {
    const FlowTextureLayout& layout = flow_texture_layout(*renderer_);
    struct Cells {
      glm::dvec2 sum{0.0};
      size_t count = 0;
      glm::vec3 flow{0.0f};
    };
    std::map<uint32_t, Cells> particles;
    for (uint32_t ty = 0; ty < layout.flow_extent.y; ++ty) {
      for (uint32_t tx = 0; tx < layout.flow_extent.x; ++tx) {
        gpu::FlowTexel texel{};
        std::memcpy(
            &texel,
            a.flow_texture.data() + (size_t{ty} * layout.flow_extent.x + tx) * sizeof(texel),
            sizeof(texel));
        if (texel.id == SIVIFLOW_PARTICLE_NONE) continue;
        Cells& cells = particles[texel.id];
        cells.sum += (glm::dvec2(tx, ty) + 0.5) * double(layout.texel_px) - 0.5;
        ++cells.count;
        cells.flow = decode_flow(texel);
      }
    }
    std::vector<Motion> out;
    const double seconds = kApart / kFps;
    for (const auto& [id, cells] : particles) {
      const glm::dvec2 centre = cells.sum / double(cells.count);
      const glm::vec2 xz = water_point(centre.x, centre.y);
      const glm::vec3 p(xz.x, 0.0f, xz.y);
      Motion motion;
      motion.expected = pixel_of(p + cells.flow * float(seconds)) - pixel_of(p);
      motion.boulder_distance = glm::distance(xz, glm::vec2(boulder_.x, boulder_.z));
      motion.at = xz;
      if (glm::length(motion.expected) < kMinShift) continue;
      if (!track(a, b, centre, &motion.measured)) continue;
      out.push_back(motion);
    }
    return out;
  }

  // The motions of the ripples and of the particles' flow, between frames kFirst, kFirst +
  // kApart and kFirst + 2 kApart of the channel with its boulder at `boulder` and `islands`.
  std::vector<Motion> render_motions(WaterMaterial material, const glm::vec3& boulder,
                                     const std::vector<ProceduralIsland>& islands = {},
                                     const std::optional<ProceduralConfluence>& confluence = {}) {
    WaterLook look;
    look.material = material;
    boulder_ = boulder;
    set_camera({0.0f, 9.0f, -4.5f}, {0.0f, 0.0f, 2.5f}, kView);
    const Status status =
        create_channel(make_create_info(kView.width, kView.height), boulder, look, {}, islands, confluence);
    EXPECT_TRUE(status.ok()) << status.message();
    frames_ = render_still(0, kFirst + 2 * kApart + 1);
    const std::vector<Frame>& frames = frames_;
    EXPECT_EQ(frames.size(), kFirst + 2 * kApart + 1);
    if (frames.size() != kFirst + 2 * kApart + 1) return {};
    std::vector<Motion> all = motions(frames[kFirst], frames[kFirst + kApart]);
    const std::vector<Motion> later = motions(frames[kFirst + kApart], frames[kFirst + 2 * kApart]);
    all.insert(all.end(), later.begin(), later.end());
    return all;
  }

  Summary measure(WaterMaterial material) {
    const std::vector<Motion> all = render_motions(material, kBoulder);
    std::vector<double> angles, ratios, near;
    for (const Motion& m : all) {
      const double angle = degrees_apart(m.measured, m.expected);
      angles.push_back(angle);
      ratios.push_back(glm::length(m.measured) / glm::length(m.expected));
      if (m.boulder_distance < 2.5 * kBoulderRadius) near.push_back(angle);
    }
    return {angles.size(), median(angles), median(ratios), near.size(), median(near)};
  }

  // Floats released across the channel, upstream of the boulder, beside it and past it, drifted
  // through the frames measure() rendered by the renderer's own queries; their motion over
  // kApart frames from each of kApart + 1 frames on, and the ripples' under them (the median of
  // those shifts: one window can lock onto the wrong peak).
  std::vector<FloatMotion> float_motions() const {
    if (frames_.size() != kFirst + 2 * kApart + 1) return {};  // measure() failed, and said why
    const WaterQueryFunction ask = [this](std::span<const glm::vec3> p, std::span<WaterSample> s) {
      return renderer_->query_water(p, s);
    };
    std::vector<FloatMotion> out;
    for (const glm::vec3 release :
         {glm::vec3(-1.5f, 0.0f, -2.0f), glm::vec3(1.5f, 0.0f, -2.0f), glm::vec3(-2.2f, 0.0f, 0.5f),
          glm::vec3(2.2f, 0.0f, 0.5f), glm::vec3(-3.0f, 0.0f, 2.0f), glm::vec3(3.0f, 0.0f, 2.0f),
          glm::vec3(-1.5f, 0.0f, 3.0f), glm::vec3(1.5f, 0.0f, 3.0f)}) {
      std::vector<FloatingBody> body(1);
      body[0].position = release;
      body[0].radius = 0.1f;
      body[0].drag = 40.0f;  // a leaf: it takes the water's velocity within a frame
      body[0].velocity = ask_velocity(release);
      std::vector<glm::vec3> path{release};  // at frames kFirst, kFirst + 1, ...
      for (uint32_t i = 0; i < 2 * kApart; ++i) {
        EXPECT_TRUE(drift_bodies(body, float(1.0 / kFps), ask).ok());
        path.push_back(body[0].position);
      }
      EXPECT_FALSE(body[0].stranded)
          << "a float released at x " << release.x << ", z " << release.z;
      FloatMotion motion;
      motion.release = release;
      std::vector<double> xs, ys;
      for (uint32_t i = 0; i <= kApart; ++i) {
        const glm::dvec2 from = pixel_of(path[i]);
        motion.drifted += (pixel_of(path[i + kApart]) - from) / double(kApart + 1);
        glm::dvec2 shift;
        if (!track(frames_[kFirst + i], frames_[kFirst + i + kApart], from, &shift)) continue;
        xs.push_back(shift.x);
        ys.push_back(shift.y);
      }
      EXPECT_GE(xs.size(), kApart)
          << "no water round the float released at x " << release.x << ", z " << release.z;
      if (xs.empty()) continue;
      motion.measured = {median(xs), median(ys)};
      out.push_back(motion);
    }
    return out;
  }

  glm::vec3 ask_velocity(const glm::vec3& at) const {
    WaterSample sample;
    EXPECT_TRUE(renderer_->query_water(std::span(&at, 1), std::span(&sample, 1)).ok());
    return sample.velocity;
  }

  std::vector<Frame> frames_;  // measure()'s
  glm::vec3 boulder_ = kBoulder;
};

void expect_moves_with_the_flow(const char* material, const Summary& s) {
  std::printf(
      "%s: %zu windows, median angular error %.1f deg, median speed ratio %.2f; "
      "%zu windows round the boulder, median angular error %.1f deg\n",
      material, s.windows, s.angle_deg, s.speed_ratio, s.near_windows, s.near_angle_deg);
  EXPECT_GT(s.windows, 100u) << material;
  EXPECT_GT(s.near_windows, 10u) << material;
  EXPECT_LE(s.angle_deg, 10.0) << material;
  EXPECT_NEAR(s.speed_ratio, 1.0, 0.2) << material;
  EXPECT_LE(s.near_angle_deg, 15.0) << material;
}

TEST_F(RippleMotionTest, TiledDirectionalFlowRipplesMoveWithTheFlow) {
  expect_moves_with_the_flow("tiled directional flow",
                             measure(WaterMaterial::kTiledDirectionalFlow));
  // The floats go where the ripples under them go.
  const std::vector<FloatMotion> floats = float_motions();
  EXPECT_EQ(floats.size(), 8u);
  for (const FloatMotion& f : floats) {
    const double angle = degrees_apart(f.measured, f.drifted);
    std::printf(
        "float released at x %.1f, z %.1f: drifted (%.2f, %.2f) px, ripples (%.2f, %.2f) "
        "px, %.1f deg apart\n",
        double(f.release.x), double(f.release.z), f.drifted.x, f.drifted.y, f.measured.x,
        f.measured.y, angle);
    // Where the flow turns round the boulder within a tile, the ripples' tolerance (as for the
    // particles above).
    const bool near = glm::distance(glm::vec2(f.release.x, f.release.z),
                                    glm::vec2(kBoulder.x, kBoulder.z)) < 2.5f * kBoulderRadius;
    EXPECT_LT(angle, near ? 15.0 : 10.0)
        << "the float released at x " << f.release.x << ", z " << f.release.z;
  }
}

TEST_F(RippleMotionTest, FlowMapRipplesMoveWithTheFlow) {
  expect_moves_with_the_flow("flow map", measure(WaterMaterial::kFlowMap));
}

// Ripples measured over a river part (an island, a junction): printed, and held to following
// the flow: over 10 windows on each side (`left`, `right`) and in `focus` (where the flow turns),
// the median angular error at most 10 degrees (15 in the focus), the median speed ratio 1 +- 0.2.
void expect_ripples_follow(const std::vector<Motion>& all, const char* where,
                           const std::function<bool(glm::vec2)>& left,
                           const std::function<bool(glm::vec2)>& right,
                           const std::function<bool(glm::vec2)>& focus, const char* focus_name) {
  std::vector<double> angles, ratios, focused;
  size_t on_left = 0, on_right = 0;
  for (const Motion& m : all) {
    const double angle = degrees_apart(m.measured, m.expected);
    angles.push_back(angle);
    ratios.push_back(glm::length(m.measured) / glm::length(m.expected));
    on_left += left(m.at) ? 1 : 0;
    on_right += right(m.at) ? 1 : 0;
    if (focus(m.at)) focused.push_back(angle);
  }
  std::printf("%s: %zu windows (%zu on the left, %zu on the right), median angular error %.1f deg, "
              "median speed ratio %.2f; %zu %s, %.1f deg\n",
              where, angles.size(), on_left, on_right, median(angles), median(ratios), focused.size(),
              focus_name, median(focused));
  EXPECT_GT(on_left, 10u);
  EXPECT_GT(on_right, 10u);
  EXPECT_GT(focused.size(), 10u);
  EXPECT_LE(median(angles), 10.0);
  EXPECT_NEAR(median(ratios), 1.0, 0.2);
  EXPECT_LE(median(focused), 15.0);
}

// An island in mid-stream parts the flow (the boulder moved far downstream, out of view): the
// ripples go where the flow goes in both its arms and where the flow turns at its head and tail.
TEST_F(RippleMotionTest, RipplesFollowTheFlowAroundAnIsland) {
  const ProceduralIsland island{3.0f, 0.0f, 10.0f, 3.0f};  // z from -2 to 8, x from -1.5 to 1.5
  expect_ripples_follow(
      render_motions(WaterMaterial::kTiledDirectionalFlow, {0.0f, 0.0f, 50.0f}, {island}),
      "around the island", [](glm::vec2 at) { return at.y > -2.0f && at.y < 8.0f && at.x > 1.5f; },
      [](glm::vec2 at) { return at.y > -2.0f && at.y < 8.0f && at.x < -1.5f; },
      [](glm::vec2 at) { return std::abs(at.y + 2.0f) < 2.0f || std::abs(at.y - 8.0f) < 2.0f; },
      "at its head and tail");
}

// Two tributaries, 30 degrees apart, join at z = 0 (the channel's 12 m split 6 and 6 above it):
// the ripples in each tributary, in the river below and where they meet follow the flow.
TEST_F(RippleMotionTest, RipplesFollowTheFlowWhereTwoTributariesJoin) {
  const ProceduralConfluence confluence{0.0f, 0.0f, 30.0f};
  expect_ripples_follow(
      render_motions(WaterMaterial::kTiledDirectionalFlow, {0.0f, 0.0f, 50.0f}, {}, confluence),
      "where two tributaries join", [](glm::vec2 at) { return at.y < -0.5f && at.x > 0.5f; },
      [](glm::vec2 at) { return at.y < -0.5f && at.x < -0.5f; },
      [](glm::vec2 at) { return at.y > -1.0f && at.y < 3.0f; }, "within 3 m below the tip");
}

}  // namespace
}  // namespace siviflow::testing
