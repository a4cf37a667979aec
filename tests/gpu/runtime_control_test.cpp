// What a host changes on a running renderer, seen in the frames: obstacles added, moved and
// removed between frames re-route the next frame's flow as a fresh solve would, and its
// particles carry it; the water's
// look changes the picture as intended and equals the same look from a scene file; bad values
// are refused by name and change nothing.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "render_frames.h"
#include "renderer_inspect.h"
#include "scene/default_scene.h"
#include "siviflow/scene_file.h"

namespace siviflow::testing {
namespace {

// The default scene as a scene file: the default river, its obstacles, plus `extra` ones.
SceneFile default_scene_file(const std::vector<Obstacle>& extra = {}) {
  SceneFile scene;
  scene.path = "default-as-file.json";
  scene.rivers[0].procedural = default_river_params();
  scene.obstacles = default_scene_obstacles(ProceduralRiver(default_river_params()));
  scene.obstacles.insert(scene.obstacles.end(), extra.begin(), extra.end());
  scene.camera.fov_y_deg = default_camera(ProceduralRiver(default_river_params()), 0.0).fov_y_deg;
  return scene;
}

class RuntimeControlTest : public RenderTest {
 protected:
  // A boat-sized circle on the water where the camera of frame 1 looks.
  WaterObstacle boat() {
    const Camera camera = world_->scene_camera(1.0 / 30.0);
    WaterObstacle obstacle;
    obstacle.centre = {camera.target.x, 0.0f, camera.target.z};
    obstacle.radius = 2.5f;
    return obstacle;
  }

  // The river's flow per vertex as the renderer last solved it.
  std::vector<glm::vec3> river_flow() const {
    const RiverFlowField& field = flow_field(*renderer_);
    return {field.flow.begin(), field.flow.end()};
  }

  std::vector<Frame> render_with(const CreateInfo& info, uint32_t first, uint32_t end,
                                 const SceneFile* scene = nullptr) {
    renderer_.reset();
    world_.reset();
    const Status status = create_renderer(info, scene);
    EXPECT_TRUE(status.ok()) << status.message();
    return render(first, end);
  }
};

// How many bytes of two read-back images differ (they are the same size).
template <typename T>
size_t differing(const std::vector<T>& a, const std::vector<T>& b) {
  EXPECT_EQ(a.size(), b.size());
  size_t count = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) count += a[i] != b[i] ? 1 : 0;
  return count;
}

// Mean of (red - blue) over the water's pixels, and how many there are.
double mean_red_minus_blue(const Frame& frame, size_t* water) {
  double sum = 0.0;
  *water = 0;
  for (size_t i = 0; i < frame.water_mask.size(); ++i) {
    if (frame.water_mask[i] != 1.0f) continue;
    sum += frame.rgba[i * 4] - frame.rgba[i * 4 + 2];
    ++*water;
  }
  return *water == 0 ? 0.0 : sum / static_cast<double>(*water);
}

TEST_F(RuntimeControlTest, ObstacleAddedAtRuntimeReroutesTheNextFrameAsAFreshSolve) {
  const std::vector<Frame> plain = render_with(make_create_info(kWidth, kHeight), 0, 3);
  const std::vector<glm::vec3> plain_flow = river_flow();
  const WaterObstacle added = boat();
  Obstacle as_scene;
  as_scene.centre = added.centre;
  as_scene.radius = added.radius;
  const SceneFile with_boat = default_scene_file({as_scene});
  const std::vector<Frame> fresh = render_with(make_create_info(kWidth, kHeight), 0, 3, &with_boat);
  const std::vector<glm::vec3> fresh_flow = river_flow();

  // Frame 0 without the boat, frame 1 with it (added between the frames), frame 2 without.
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  std::vector<Frame> live = render(0, 1);
  uint32_t id = 0;
  ASSERT_TRUE(renderer_->add_obstacle(added, &id).ok());
  const std::vector<Frame> with = render(1, 2);
  const std::vector<glm::vec3> with_flow = river_flow();
  ASSERT_TRUE(renderer_->remove_obstacle(id).ok());
  const std::vector<Frame> without = render(2, 3);
  ASSERT_EQ(plain.size(), 3u);
  ASSERT_EQ(fresh.size(), 3u);
  ASSERT_EQ(with.size(), 1u);
  ASSERT_EQ(without.size(), 1u);
  EXPECT_GT(differing(fresh[1].flow_texture, plain[1].flow_texture), 1000u)
      << "the boat is in view and re-routes the flow";
  EXPECT_GT(differing(with[0].flow_texture, plain[1].flow_texture), 1000u)
      << "the particles carry the new flow the next frame";
  EXPECT_EQ(differing(with_flow, fresh_flow), 0u) << "added at runtime = solved with it";
  EXPECT_EQ(differing(river_flow(), plain_flow), 0u) << "removed: the flow returns";
  EXPECT_FALSE(renderer_->remove_obstacle(id).ok()) << "gone";
}

TEST_F(RuntimeControlTest, MovedAndTurnedObstacleEqualsOneSolvedWhereItEnds) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  WaterObstacle hull = boat();
  hull.radius = 0.0f;
  hull.polygon = {{-1.0f, -3.0f}, {1.0f, -3.0f}, {1.0f, 3.0f}, {-1.0f, 3.0f}};
  const glm::vec3 start = hull.centre;
  uint32_t id = 0;
  ASSERT_TRUE(renderer_->add_obstacle(hull, &id).ok());
  render(0, 1);
  const glm::vec3 end = start + glm::vec3(1.0f, 0.0f, 2.0f);
  ASSERT_TRUE(renderer_->move_obstacle(id, end, 0.6f).ok());
  const std::vector<Frame> moved = render(1, 2);
  const std::vector<glm::vec3> moved_flow = river_flow();

  WaterObstacle placed = hull;
  placed.centre = end;
  placed.rotation_rad = 0.6f;
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  ASSERT_TRUE(renderer_->add_obstacle(placed, &id).ok());
  const std::vector<Frame> direct = render(0, 2);
  ASSERT_EQ(moved.size(), 1u);
  ASSERT_EQ(direct.size(), 2u);
  EXPECT_EQ(differing(moved_flow, river_flow()), 0u);
}

TEST_F(RuntimeControlTest, LookChangesTheWaterOnlyAndEqualsTheSceneFileLook) {
  const std::vector<Frame> plain = render_with(make_create_info(kWidth, kHeight), 0, 2);
  WaterLook peat;  // a peat-brown river
  peat.water_color = {0.30f, 0.16f, 0.06f};
  peat.deep_color = {0.12f, 0.05f, 0.01f};
  peat.absorption_per_metre = 3.0f;
  // Switched to at run time, the material's pipeline is compiled for the frame that first draws
  // with it; from the scene file, at create: the same frame either way.
  peat.material = WaterMaterial::kFlowMap;
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  render(0, 1);
  ASSERT_TRUE(renderer_->set_look(peat).ok());
  const std::vector<Frame> runtime = render(1, 2);

  SceneFile scene = default_scene_file();
  scene.look = peat;
  const std::vector<Frame> file = render_with(make_create_info(kWidth, kHeight), 0, 2, &scene);
  ASSERT_EQ(plain.size(), 2u);
  ASSERT_EQ(runtime.size(), 1u);
  ASSERT_EQ(file.size(), 2u);

  size_t water = 0;
  const double before = mean_red_minus_blue(plain[1], &water);
  ASSERT_GT(water, 1000u);
  const double after = mean_red_minus_blue(runtime[0], &water);
  EXPECT_LT(before, 0.0) << "the default water is green-blue";
  EXPECT_GT(after, before + 0.05) << "the peat look turns the water brown";
  size_t changed_dry = 0;
  for (size_t i = 0; i < plain[1].water_mask.size(); ++i) {
    if (plain[1].water_mask[i] == 0.0f &&
        std::memcmp(&plain[1].rgba[i * 4], &runtime[0].rgba[i * 4], 4 * sizeof(float)) != 0) {
      ++changed_dry;
    }
  }
  EXPECT_EQ(changed_dry, 0u) << "off the water the host's colour is untouched";
  EXPECT_EQ(differing(runtime[0].rgba, file[1].rgba), 0u)
      << "the same look from the scene file: the same frame";
}

// Luminance of the water's pixels in the middle ninth of the picture (mid-river, away from the
// shallows where the bed shows through), sorted.
std::vector<double> water_luminances(const Frame& frame) {
  std::vector<double> values;
  for (size_t i = 0; i < frame.water_mask.size(); ++i) {
    const size_t x = i % kWidth, y = i / kWidth;
    if (x < kWidth / 3 || x >= 2 * kWidth / 3 || y < kHeight / 3 || y >= 2 * kHeight / 3) continue;
    if (frame.water_mask[i] != 1.0f) continue;
    const float* p = &frame.rgba[i * 4];
    values.push_back(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
  }
  std::sort(values.begin(), values.end());
  return values;
}

TEST_F(RuntimeControlTest, SunGlintsOnlyWhereTheWaterMirrorsIt) {
  // Calm water seen steeply from above (no bright horizon mirrored at grazing angles): with the
  // sun where the camera's middle ray reflects to, the brightest water is far above the median;
  // with the sun behind the camera, the water has no highlight.
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  Camera camera;
  camera.target = boat().centre;  // on the water, in mid-river
  camera.position = camera.target + glm::vec3(0.0f, 10.0f, -5.0f);
  const glm::vec3 ray = glm::normalize(camera.target - camera.position);
  WaterLook calm;
  calm.ripple_strength = 0.05f;
  calm.foam_amount = 0.0f;  // foam is brighter than the water without being a glint
  double ratio[2] = {};
  const glm::vec3 suns[2] = {{ray.x, -ray.y, ray.z}, {-ray.x, -ray.y, -ray.z}};
  for (int i = 0; i < 2; ++i) {
    calm.sun_direction = suns[i];
    ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
    ASSERT_TRUE(renderer_->set_look(calm).ok());
    const std::vector<Frame> frames =
        render_views(0, 1, kWidth, kHeight, [&](double) { return camera_view(camera, {kWidth, kHeight}); });
    ASSERT_EQ(frames.size(), 1u);
    const std::vector<double> water = water_luminances(frames[0]);
    ASSERT_GT(water.size(), 2000u) << "mid-river fills the middle of the picture";
    const double brightest = water[water.size() - 1 - water.size() / 1000];  // 99.9th percentile
    ratio[i] = brightest / water[water.size() / 2];
  }
  std::printf("brightest / median water: sun mirrored %.2f, sun behind %.2f\n", ratio[0], ratio[1]);
  EXPECT_GT(ratio[0], 5.0) << "the sun's glint in the mirror direction";
  EXPECT_LT(ratio[1], 2.0) << "no glint with the sun behind the camera";
}

TEST_F(RuntimeControlTest, BadObstaclesAndLooksAreRefusedByNameAndChangeNothing) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  uint32_t id = 0;
  const auto refused = [](const Status& status, std::initializer_list<std::string> parts) {
    ASSERT_FALSE(status.ok());
    for (const std::string& part : parts) {
      EXPECT_NE(status.message().find(part), std::string::npos)
          << "missing '" << part << "' in: " << status.message();
    }
  };
  WaterObstacle nan_centre = boat();
  nan_centre.centre.x = NAN;
  refused(renderer_->add_obstacle(nan_centre, &id), {"add_obstacle", "obstacle 1", "centre"});
  WaterObstacle no_radius = boat();
  no_radius.radius = -2.0f;
  refused(renderer_->add_obstacle(no_radius, &id), {"add_obstacle", "radius -2"});
  WaterObstacle flat = boat();
  flat.polygon = {{0.0f, 0.0f}, {1.0f, 0.0f}, {2.0f, 0.0f}};
  refused(renderer_->add_obstacle(flat, &id), {"add_obstacle", "zero area"});
  WaterObstacle spun = boat();
  spun.polygon = {{-1.0f, -1.0f}, {1.0f, -1.0f}, {0.0f, 1.0f}};
  spun.rotation_rad = INFINITY;
  refused(renderer_->add_obstacle(spun, &id), {"rotation_rad inf"});
  refused(renderer_->move_obstacle(7, {0.0f, 0.0f, 0.0f}), {"move_obstacle", "no obstacle with id 7"});
  refused(renderer_->remove_obstacle(7), {"remove_obstacle", "id 7"});
  ASSERT_TRUE(renderer_->add_obstacle(boat(), &id).ok());
  EXPECT_EQ(id, 1u) << "refused obstacles took no id";
  refused(renderer_->move_obstacle(id, {NAN, 0.0f, 0.0f}), {"move_obstacle", "centre"});

  WaterLook bad;
  bad.fresnel_f0 = 1.5f;
  refused(renderer_->set_look(bad), {"set_look", "WaterLook::fresnel_f0", "1.5 is outside [0, 1]"});
  bad = WaterLook{};
  bad.material = static_cast<WaterMaterial>(7);
  refused(renderer_->set_look(bad), {"set_look", "WaterLook::material", "7 is not a WaterMaterial"});
  bad = WaterLook{};
  bad.tile_size_m = NAN;
  refused(renderer_->set_look(bad), {"tile_size_m", "nan"});
  bad = WaterLook{};
  bad.water_color.g = -0.1f;
  refused(renderer_->set_look(bad), {"water_color", "component 1", "-0.1"});
  EXPECT_EQ(renderer_->look().fresnel_f0, WaterLook{}.fresnel_f0) << "the look stayed";
  EXPECT_EQ(renderer_->look().tile_size_m, WaterLook{}.tile_size_m);
  // And the renderer renders on.
  EXPECT_EQ(render(0, 1).size(), 1u);
}

}  // namespace
}  // namespace siviflow::testing
