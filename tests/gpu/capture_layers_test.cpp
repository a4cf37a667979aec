// The capture's layers as a compositor or a dataset builder reads them: names every reader takes,
// the water layers zero off the water, the camera in the file (depth turns back into the world
// points the water was drawn at), and motion vectors that agree with the neighbouring frames'
// cameras.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/mat2x2.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 160;
constexpr int kHeight = 90;

class CaptureLayersTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("capture_layers"); }

  // Captures `args` into a folder of its own named `name`; reads back `frame`.
  ExrImage capture(const std::string& name, const std::string& args, uint32_t frame) {
    const fs::path out = dir_ / name;
    fs::create_directories(out);
    const RunResult r = run_siviflow("capture " + args + " --validation --out " + out.string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return read(name, frame);
  }
  ExrImage read(const std::string& name, uint32_t frame) {
    ExrImage image;
    const Status s = read_exr((dir_ / name / frame_file_name(frame)).string(), &image);
    EXPECT_TRUE(s.ok()) << s.message();
    return image;
  }
  fs::path write_scene(const std::string& name, const std::string& json) {
    const fs::path path = dir_ / (name + ".json");
    std::ofstream(path) << json;
    return path;
  }
  fs::path dir_;
};

glm::mat4 matrix(const float (&m)[16]) {
  glm::mat4 out;
  std::memcpy(&out[0][0], m, sizeof(m));
  return out;
}

// OpenEXR's row-vector convention, p * M, is glm's M * p on the same 16 floats.
glm::vec4 transformed(const float (&m)[16], glm::vec4 p) { return matrix(m) * p; }

// The worked example of docs/output.md: the world point a pixel's depth (distance along the view
// axis) puts it at, from worldToCamera and worldToNDC alone.
glm::vec3 world_point(const ExrImage& image, int x, int y, float depth) {
  const ExrCamera& camera = image.metadata.camera;
  const glm::mat4 camera_to_world = glm::inverse(matrix(camera.world_to_camera));
  const glm::mat4 camera_to_ndc = matrix(camera.world_to_ndc) * camera_to_world;
  const glm::vec2 ndc((x + 0.5f) / image.width, (y + 0.5f) / image.height);
  // ndc * w = xy of (cx, cy, depth, 1) through camera_to_ndc: two equations, linear in cx, cy.
  const glm::vec4 c0 = glm::transpose(camera_to_ndc)[0];  // rows: x, y and w of the NDC point
  const glm::vec4 c1 = glm::transpose(camera_to_ndc)[1];
  const glm::vec4 c3 = glm::transpose(camera_to_ndc)[3];
  const auto row = [&](const glm::vec4& r, float target) {
    return glm::vec3(r.x - target * c3.x, r.y - target * c3.y,
                     -(r.z - target * c3.z) * depth - (r.w - target * c3.w));
  };
  const glm::vec3 a = row(c0, ndc.x);
  const glm::vec3 b = row(c1, ndc.y);
  const glm::vec2 cxy = glm::inverse(glm::mat2(a.x, b.x, a.y, b.y)) * glm::vec2(a.z, b.z);
  return glm::vec3(camera_to_world * glm::vec4(cxy, depth, 1.0f));
}

// Where `image`'s camera sees the world point, in pixels (x right, y down).
glm::vec2 pixel_of(const ExrImage& image, glm::vec3 point) {
  const glm::vec4 ndc = transformed(image.metadata.camera.world_to_ndc, glm::vec4(point, 1.0f));
  return glm::vec2(ndc.x / ndc.w * image.width, ndc.y / ndc.w * image.height);
}

const std::vector<std::string> kWaterChannels = {
    "flow.X",   "flow.Y",   "flow.Z",       "particle.I",   "normal.X",     "normal.Y",
    "normal.Z", "foam.Y",   "reflection.R", "reflection.G", "reflection.B"};

TEST_F(CaptureLayersTest, EveryLayerNamedForEveryReaderAndZeroOffTheWater) {
  const ExrImage image =
      capture("all", "--frames 2 --size 160x90 --aov depth,flow,particles,normal,reflection,"
                     "foam,motion", 1);
  EXPECT_EQ(image.parts, (std::vector<std::string>{"rgba", "depth", "water", "flow", "particle",
                                                   "normal", "reflection", "foam", "motion"}));
  for (const auto& [name, plane] : image.channels) {
    // LAYER.C with a one-letter C, or a bare beauty channel: what Blender's reader takes.
    const size_t dot = name.rfind('.');
    EXPECT_EQ(dot == std::string::npos ? name.size() : name.size() - dot - 1, 1u) << name;
    // Depth alone is FLOAT (half would place a point a kilometre away to half a metre); the ids
    // are UINT.
    const ExrPixelType expected = name == "depth.Z"      ? ExrPixelType::kFloat
                                  : name == "particle.I" ? ExrPixelType::kUint
                                                         : ExrPixelType::kHalf;
    EXPECT_EQ(plane.type, expected) << name;
  }
  const std::vector<float>& mask = *image.find("water.A");
  size_t water = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    ASSERT_TRUE(mask[i] == 0.0f || mask[i] == 1.0f) << "pixel " << i;
    water += mask[i] == 1.0f ? 1 : 0;
    if (mask[i] != 0.0f) continue;
    for (const std::string& channel : kWaterChannels) {
      ASSERT_EQ((*image.find(channel))[i], 0.0f) << channel << " at pixel " << i << " off water";
    }
  }
  EXPECT_GT(water, mask.size() / 10) << "the default frame shows its river";
  EXPECT_LT(water, mask.size()) << "and its banks";
  size_t flowing = 0;
  for (size_t i = 0; i < mask.size(); ++i) flowing += (*image.find("flow.Z"))[i] != 0.0f ? 1 : 0;
  EXPECT_GT(flowing * 10, water * 9) << "flow on the water";
}

// A camera on a keyed path: the frame's worldToCamera, worldToNDC, field of view, clip planes,
// frame rate and time are those of the path at the frame's time, at the --fps asked for.
TEST_F(CaptureLayersTest, TheCameraTravelsWithThePixels) {
  const fs::path scene = write_scene("path", R"({"version":1,"river":{"procedural":{}},
      "camera":{"fov_y_deg":40,"keys":[
        {"t":0,"position":[0,5,-60],"target":[8,0,-20]},
        {"t":1,"position":[24,5,-60],"target":[32,0,-20]}]}})");
  const ExrImage image = capture("path", scene.string() + " --frames 7 --fps 24 --size 160x90", 6);
  EXPECT_EQ(image.metadata.frames_per_second, 24.0);
  EXPECT_NEAR(image.metadata.time_seconds, 6.0f / 24.0f, 1e-6f);
  const ExrCamera& camera = image.metadata.camera;
  ASSERT_TRUE(camera.present);
  EXPECT_EQ(camera.fov_y_deg, 40.0f);
  EXPECT_GT(camera.near_plane, 0.0f);
  EXPECT_GT(camera.far_plane, camera.near_plane);
  // At t = 0.25 s the camera is a quarter of the way along: x 6, target x 14.
  const glm::vec3 position(6.0f, 5.0f, -60.0f);
  const glm::vec3 target(14.0f, 0.0f, -20.0f);
  const glm::vec4 eye = transformed(camera.world_to_camera, glm::vec4(position, 1.0f));
  EXPECT_LT(glm::length(glm::vec3(eye)), 1e-4f) << "the camera sits at camera space's origin";
  const glm::vec4 ahead = transformed(camera.world_to_camera, glm::vec4(target, 1.0f));
  EXPECT_NEAR(ahead.z, glm::length(target - position), 1e-4f) << "+z looks ahead";
  EXPECT_NEAR(ahead.x, 0.0f, 1e-4f);
  EXPECT_NEAR(ahead.y, 0.0f, 1e-4f);
  const glm::vec4 above = transformed(camera.world_to_camera, glm::vec4(target + glm::vec3(0, 1, 0), 1.0f));
  EXPECT_GT(above.y, 0.0f) << "+y is up";
  // Looking down world +z with +y up, world -x is on the camera's right.
  const glm::vec4 right = transformed(camera.world_to_camera, glm::vec4(target - glm::vec3(1, 0, 0), 1.0f));
  EXPECT_GT(right.x, 0.0f) << "+x is right";
  // NDC: the target at the centre, up is towards row 0, and the field of view spans 0..1.
  const glm::vec2 centre = pixel_of(image, target) / glm::vec2(kWidth, kHeight);
  EXPECT_NEAR(centre.x, 0.5f, 1e-5f);
  EXPECT_NEAR(centre.y, 0.5f, 1e-5f);
  EXPECT_LT(pixel_of(image, target + glm::vec3(0, 1, 0)).y, kHeight / 2.0f);
  EXPECT_GT(pixel_of(image, target - glm::vec3(1, 0, 0)).x, kWidth / 2.0f);
  const float half = glm::length(target - position) * std::tan(glm::radians(20.0f));
  const glm::vec3 up = glm::normalize(glm::cross(glm::cross(target - position, glm::vec3(0, 1, 0)),
                                                 target - position));
  EXPECT_NEAR(pixel_of(image, target + up * half).y, 0.0f, 1e-2f) << "the top edge at fov / 2";
}

// The worked example of docs/output.md turns depth back into the world: every water pixel's point
// lies on the water surface (the default river is flat at y = 0) within 1 cm, where 32-bit depth
// resolves that well (the nearest 60 m).
TEST_F(CaptureLayersTest, DepthReprojectsWaterOntoItsSurface) {
  const ExrImage image = capture("depth", "--frames 1 --size 320x180 --aov depth,flow", 0);
  const std::vector<float>& depth = *image.find("depth.Z");
  const std::vector<float>& mask = *image.find("water.A");
  size_t checked = 0;
  float worst = 0.0f;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const size_t i = size_t(y) * image.width + x;
      if (mask[i] != 1.0f || depth[i] > 60.0f) continue;
      const glm::vec3 point = world_point(image, x, y, depth[i]);
      worst = std::max(worst, std::abs(point.y));
      ++checked;
    }
  }
  EXPECT_GT(checked, size_t(image.width * image.height / 20));
  EXPECT_LT(worst, 0.01f) << "metres off the water surface, worst of " << checked << " pixels";
  std::printf("%zu water pixels reprojected, the worst %.4f m off the surface\n", checked, worst);
}

// Motion vectors are where each pixel's surface point was in the previous frame and will be in
// the next, as those frames' own worldToNDC put it; a shard renders the same vectors.
TEST_F(CaptureLayersTest, MotionAgreesWithTheNeighbouringFramesCameras) {
  const fs::path scene = write_scene("pan", R"({"version":1,"river":{"procedural":{}},
      "camera":{"keys":[{"t":0,"position":[-10,6,-60],"target":[0,0,-20]},
                        {"t":2,"position":[30,8,-50],"target":[20,0,-10]}]}})");
  const std::string args = scene.string() + " --size 160x90 --aov depth,motion";
  capture("full", args + " --frames 4", 0);
  const ExrImage before = read("full", 1);
  const ExrImage now = read("full", 2);
  const ExrImage after = read("full", 3);
  const std::vector<float>& depth = *now.find("depth.Z");
  const std::vector<float>* motion[4] = {now.find("motion.X"), now.find("motion.Y"),
                                         now.find("motion.Z"), now.find("motion.W")};
  for (const auto* m : motion) ASSERT_NE(m, nullptr);
  size_t checked = 0;
  float worst = 0.0f;
  float largest = 0.0f;
  for (int y = 0; y < now.height; y += 3) {
    for (int x = 0; x < now.width; x += 3) {
      const size_t i = size_t(y) * now.width + x;
      if (!std::isfinite(depth[i]) || depth[i] > 60.0f) continue;
      const glm::vec3 point = world_point(now, x, y, depth[i]);
      const glm::vec2 here = pixel_of(now, point);
      const glm::vec2 then = pixel_of(before, point);
      const glm::vec2 later = pixel_of(after, point);
      // Blender's layout: previous - now and now - next, y up.
      const glm::vec2 expected_xy(then.x - here.x, here.y - then.y);
      const glm::vec2 expected_zw(here.x - later.x, later.y - here.y);
      const glm::vec2 xy((*motion[0])[i], (*motion[1])[i]);
      const glm::vec2 zw((*motion[2])[i], (*motion[3])[i]);
      worst = std::max({worst, glm::length(xy - expected_xy), glm::length(zw - expected_zw)});
      largest = std::max(largest, glm::length(xy));
      ++checked;
    }
  }
  EXPECT_GT(checked, 200u);
  EXPECT_GT(largest, 2.0f) << "the camera moves several pixels a frame";
  EXPECT_LT(worst, 0.05f) << "pixels from the neighbours' reprojection, worst of " << checked;

  capture("shard", args + " --range 2:3", 2);
  const ExrImage shard = read("shard", 2);
  for (const char* channel : {"motion.X", "motion.Y", "motion.Z", "motion.W", "depth.Z"}) {
    EXPECT_EQ(*shard.find(channel), *now.find(channel)) << channel;
  }
}

// A still camera over a keyed obstacle rolling across the river: its boulder's pixels move by
// the boulder's own displacement, and every other pixel (the water around it too) not at all.
TEST_F(CaptureLayersTest, AStillCameraSeesOnlyTheRollingBoulderMove) {
  const fs::path scene = write_scene("still", R"({"version":1,"river":{"procedural":{}},
      "obstacles":[{"center":[6,0.3,-25],"radius":1.2,
                    "keys":[{"t":0,"center":[6,0.3,-25]},{"t":2,"center":[11,0.3,-25]}]}],
      "camera":{"keys":[{"t":0,"position":[8.5,3.0,-40.0],"target":[8.5,0.0,-25.0]}]}})");
  constexpr uint32_t kFrame = 30;  // t = 1 s: the boulder at x = 8.5, 2.5 m/s, 1/12 m a frame
  const ExrImage image = capture("still", scene.string() + " --frames 31 --size 160x90 "
                                          "--aov depth,flow,motion", kFrame);
  const glm::vec3 centre(8.5f, 0.3f, -25.0f);
  const glm::vec3 step(2.5f / 30.0f, 0.0f, 0.0f);
  const std::vector<float>& depth = *image.find("depth.Z");
  size_t on_boulder = 0;
  float worst = 0.0f;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const size_t i = size_t(y) * image.width + x;
      const glm::vec2 xy((*image.find("motion.X"))[i], (*image.find("motion.Y"))[i]);
      const glm::vec2 zw((*image.find("motion.Z"))[i], (*image.find("motion.W"))[i]);
      const glm::vec3 point = world_point(image, x, y, depth[i]);
      const bool boulder_pixel = std::isfinite(depth[i]) && (*image.find("water.A"))[i] == 0.0f &&
                              glm::length(point - centre) < 1.2f * 1.15f;
      if (!boulder_pixel) {
        ASSERT_EQ(xy, glm::vec2(0.0f)) << "pixel " << x << "," << y;
        ASSERT_EQ(zw, glm::vec2(0.0f)) << "pixel " << x << "," << y;
        continue;
      }
      const glm::vec2 here = pixel_of(image, point);
      const glm::vec2 then = pixel_of(image, point - step);
      const glm::vec2 later = pixel_of(image, point + step);
      worst = std::max({worst, glm::length(xy - glm::vec2(then.x - here.x, here.y - then.y)),
                        glm::length(zw - glm::vec2(here.x - later.x, later.y - here.y))});
      ++on_boulder;
    }
  }
  EXPECT_GT(on_boulder, 20u) << "the boulder is in view";
  EXPECT_LT(worst, 0.02f) << "pixels from the boulder's own displacement";
}

}  // namespace
}  // namespace siviflow::testing
