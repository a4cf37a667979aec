// glTF objects of a scene file on screen: drawn with their base-colour texture and factor,
// reflected in the water when above it and not at all when wholly under it (the clip plane),
// and a broken texture refused with a message naming it; a glTF river rendered with its flow.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "run_command.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class SceneObjectsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("scene_objects");
    fs::create_directories(dir_ / "out");
  }
  // Captures frames [0, frames) of `scene` at kWidth x kHeight with `flags` into out/<its
  // name>/ and reads the last one (use under ASSERT_NO_FATAL_FAILURE).
  void capture_file(const fs::path& scene, uint32_t frames, const std::string& flags,
                    ExrImage* image) {
    const fs::path out = dir_ / "out" / scene.stem();
    fs::create_directories(out);
    const RunResult r = run_siviflow("capture " + scene.string() + " --frames " +
                                     std::to_string(frames) + " --size " + std::to_string(kWidth) +
                                     "x" + std::to_string(kHeight) + " " + flags + " --out " +
                                     out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05u.exr", frames - 1);
    ASSERT_TRUE(read_exr((out / name).string(), image).ok());
  }
  // Writes `name`.json (default procedural river, the given objects and camera) and captures
  // its frame 0 with `aovs`.
  ExrImage capture(const std::string& name, const std::string& objects, const std::string& camera,
                   const std::string& aovs) {
    const fs::path scene = dir_ / (name + ".json");
    write_text(scene, R"({"version":1,"river":{"procedural":{}},"objects":[)" + objects +
                          R"(],"camera":)" + camera + "}");
    ExrImage image;
    capture_file(scene, 1, "--aov " + aovs, &image);
    return image;
  }
  // A PNG of one colour (linear RGB), 8x8, beside the scene.
  void write_color_png(const std::string& name, glm::vec3 color) {
    std::vector<float> rgba;
    for (int i = 0; i < 64; ++i) rgba.insert(rgba.end(), {color.r, color.g, color.b, 1.0f});
    ASSERT_TRUE(write_png((dir_ / name).string(), 8, 8, rgba.data()).ok());
  }
  fs::path dir_;
};

std::string object(const std::string& gltf, glm::vec3 at) {
  char text[256];
  std::snprintf(text, sizeof(text), R"({"gltf":"%s","translation":[%g,%g,%g]})", gltf.c_str(),
                at.x, at.y, at.z);
  return text;
}

// Looking down the river at the reach around z = -25, where it runs from x = 3 to x = 14.
const std::string kRiverCamera = R"({"keys":[{"t":0,"position":[8.5,3.0,-40.0],"target":[8.5,0.0,-25.0]}]})";

TEST_F(SceneObjectsTest, ObjectAboveTheWaterIsReflectedAndOneUnderItIsNot) {
  write_box_gltf(dir_ / "post.gltf", glm::vec3(0.8f, 1.5f, 0.8f));
  write_box_gltf(dir_ / "stone.gltf", glm::vec3(0.4f));
  const ExrImage none = capture("none", "", kRiverCamera, "reflection,flow");
  // Not obstacles: the flow, and so the water's normal, stays the same in all three.
  const ExrImage above = capture("above", object("post.gltf", {8.5f, 2.0f, -22.0f}), kRiverCamera,
                                 "reflection,flow");
  const ExrImage under = capture("under", object("stone.gltf", {8.5f, -1.0f, -28.0f}), kRiverCamera,
                                 "reflection,flow");
  const std::vector<float>* mask = none.find("water.A");
  ASSERT_NE(mask, nullptr);
  size_t water = 0;
  size_t reflected = 0;
  float under_difference = 0.0f;
  for (size_t i = 0; i < mask->size(); ++i) {
    if ((*mask)[i] != 1.0f) continue;
    ++water;
    float above_difference = 0.0f;
    for (const char* channel : {"reflection.R", "reflection.G", "reflection.B"}) {
      const float reference = (*none.find(channel))[i];
      above_difference = std::max(above_difference, std::abs((*above.find(channel))[i] - reference));
      under_difference = std::max(under_difference, std::abs((*under.find(channel))[i] - reference));
    }
    reflected += above_difference > 0.05f ? 1 : 0;
  }
  std::printf("%zu water pixels: %zu show the post's reflection; largest change from the stone %g\n",
              water, reflected, under_difference);
  ASSERT_GT(water, size_t{kWidth * kHeight / 4}) << "the camera looks at the river";
  EXPECT_GT(reflected, 150u) << "the post above the water is reflected in it";
  EXPECT_EQ(under_difference, 0.0f) << "nothing under the water is reflected";
}

TEST_F(SceneObjectsTest, ObjectShowsItsBaseColourTextureTimesItsFactor) {
  write_color_png("blue.png", {0.05f, 0.1f, 0.8f});
  write_textured_box_gltf(dir_ / "blue.gltf", glm::vec3(1.0f), "blue.png", glm::vec4(1.0f));
  write_textured_box_gltf(dir_ / "dark.gltf", glm::vec3(1.0f), "blue.png", glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  // High above the valley, so the sky is behind it; the camera faces its -Z side.
  const std::string camera = R"({"keys":[{"t":0,"position":[0,30,-8],"target":[0,30,0]}]})";
  const ExrImage blue = capture("blue", object("blue.gltf", {0.0f, 30.0f, 0.0f}), camera, "depth");
  const ExrImage dark = capture("dark", object("dark.gltf", {0.0f, 30.0f, 0.0f}), camera, "depth");
  const size_t centre = size_t{kHeight / 2} * kWidth + kWidth / 2;
  EXPECT_NEAR((*blue.find("depth.Z"))[centre], 7.0f, 0.01f) << "the box's near face is 7 m away";
  const float r = (*blue.find("R"))[centre];
  const float g = (*blue.find("G"))[centre];
  const float b = (*blue.find("B"))[centre];
  std::printf("blue box %g %g %g; red factor on it %g %g %g\n", r, g, b, (*dark.find("R"))[centre],
              (*dark.find("G"))[centre], (*dark.find("B"))[centre]);
  EXPECT_GT(b, 4.0f * r) << "the texture's blue, lit";
  EXPECT_GT(b, 2.0f * g);
  // Red factor times a blue texture: little light comes back, and mostly red.
  EXPECT_LT((*dark.find("B"))[centre], 0.1f * b);
  EXPECT_GT((*dark.find("R"))[centre], (*dark.find("B"))[centre]);
}

TEST_F(SceneObjectsTest, BrokenTextureIsRefusedNamingIt) {
  write_text(dir_ / "broken.png", std::string("\x89PNG\r\n\x1a\n", 8) + "not really a png");
  write_textured_box_gltf(dir_ / "crate.gltf", glm::vec3(1.0f), "broken.png", glm::vec4(1.0f));
  write_text(dir_ / "scene.json", R"({"version":1,"river":{"procedural":{}},"objects":[)" +
                                      object("crate.gltf", {0.0f, 2.0f, 0.0f}) + "]}");
  const RunResult r = run_siviflow("capture " + (dir_ / "scene.json").string() + " --frames 1 --out " +
                                   (dir_ / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("scene.json: objects[0]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("crate.gltf"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::is_empty(dir_ / "out")) << "nothing written";
}

// A descending glTF channel (1 m drop per 20 m) with a crate in it that is an obstacle, seen by
// the overview camera: the water shows, its flow runs downstream (+Z), and the reflection plane
// is the visible reach's level, so the crate's reflection lies on the water.
TEST_F(SceneObjectsTest, GltfRiverFlowsDownstreamAroundAnObjectObstacle) {
  write_channel_gltf(dir_ / "channel.gltf", 41, 9, 8.0f, 1.0f, 0.05f);
  write_box_gltf(dir_ / "crate.gltf", glm::vec3(0.8f));
  const fs::path scene = dir_ / "scene.json";
  write_text(scene, R"({"version":1,"river":{"gltf":"channel.gltf"},"flow":{"discharge":8.0},)"
                    R"("objects":[{"gltf":"crate.gltf","translation":[0,-0.6,20],"obstacle":true}]})");
  ExrImage image;
  ASSERT_NO_FATAL_FAILURE(capture_file(scene, 2, "--aov flow,reflection --preview", &image));
  size_t water = 0;
  size_t downstream = 0;
  size_t aside = 0;  // turned by more than 6 degrees
  for (size_t i = 0; i < image.find("water.A")->size(); ++i) {
    if ((*image.find("water.A"))[i] != 1.0f) continue;
    ++water;
    const glm::vec3 flow((*image.find("flow.X"))[i], (*image.find("flow.Y"))[i], (*image.find("flow.Z"))[i]);
    downstream += (glm::length(flow) > 0.1f && flow.z > 0.9f * glm::length(flow)) ? 1 : 0;
    aside += std::abs(flow.x) > 0.1f * glm::length(flow) ? 1 : 0;
  }
  std::printf("%zu water pixels, %zu flowing downstream within 26 degrees, %zu turned aside\n", water,
              downstream, aside);
  ASSERT_GT(water, size_t{kWidth * kHeight / 20}) << "the channel is in view";
  EXPECT_GT(downstream, water * 7 / 10) << "the channel's flow runs along it";
  EXPECT_GT(aside, 30u) << "the crate turns some of it aside";
  EXPECT_LT(aside, water / 5);
}

// A glTF river brings no terrain: the world grows ground around it that meets its banks, so
// seen from above nothing of the picture is void, and the ground beside the water is the
// sand and grass of a bank, lit, at the water's own level.
TEST_F(SceneObjectsTest, GltfRiverHasGroundAroundIt) {
  write_channel_gltf(dir_ / "channel.gltf", 41, 9, 8.0f, 1.0f, 0.05f);
  const fs::path scene = dir_ / "scene.json";
  write_text(scene, R"({"version":1,"river":{"gltf":"channel.gltf"},)"
                    R"("camera":{"keys":[{"t":0,"position":[0,40,0],"target":[0,0,20]}]}})");
  ExrImage image;
  ASSERT_NO_FATAL_FAILURE(capture_file(scene, 1, "--aov depth,flow --validation", &image));
  const std::vector<float>& depth = *image.find("depth.Z");
  const std::vector<float>& mask = *image.find("water.A");
  const std::vector<float>& green = *image.find("G");
  size_t void_pixels = 0, water = 0, ground = 0, grassy = 0;
  for (size_t i = 0; i < depth.size(); ++i) {
    if (!std::isfinite(depth[i])) {
      ++void_pixels;
      continue;
    }
    if (mask[i] == 1.0f) {
      ++water;
      continue;
    }
    ++ground;
    grassy += green[i] > (*image.find("R"))[i] * 1.3f ? 1 : 0;
  }
  std::printf("%zu water, %zu ground (%zu grassy), %zu void pixels\n", water, ground, grassy,
              void_pixels);
  EXPECT_EQ(void_pixels, 0u) << "the river does not float in a void";
  EXPECT_GT(water, size_t{kWidth * kHeight / 20}) << "the channel is in view";
  EXPECT_GT(grassy, ground / 2) << "beyond the banks, grass";
}

// A scene of two rivers captured: both drawn over the world (their beds), with the depth AOV;
// the AOVs that belong to one river are refused by name before any GPU work.
TEST_F(SceneObjectsTest, CaptureOfTwoRivers) {
  write_channel_gltf(dir_ / "west.gltf", 41, 9, 8.0f, 1.0f, 0.0f, -9.0f);
  write_channel_gltf(dir_ / "east.gltf", 41, 9, 8.0f, 1.0f, 0.0f, 9.0f);
  const fs::path scene = dir_ / "two.json";
  write_text(scene, R"({"version":1,"rivers":[{"gltf":"west.gltf"},)"
                    R"({"gltf":"east.gltf","flow":{"discharge":30}}],)"
                    R"("camera":{"keys":[{"t":0,"position":[0,30,-12],"target":[0,0,30]}]}})");
  ExrImage image;
  ASSERT_NO_FATAL_FAILURE(capture_file(scene, 1, "--aov depth --validation", &image));
  // Water is bluer than the grey-lit beds it lies on: count the bluish pixels in front of a bed
  // (finite depth, not the sky) on each side of the picture's middle.
  const std::vector<float>& red = *image.find("R");
  const std::vector<float>& blue = *image.find("B");
  const std::vector<float>* depth = image.find("depth.Z");
  ASSERT_NE(depth, nullptr);
  size_t left = 0, right = 0;
  for (size_t i = 0; i < red.size(); ++i) {
    if (!std::isfinite((*depth)[i]) || blue[i] <= red[i] * 1.2f) continue;
    (i % kWidth < kWidth / 2 ? left : right) += 1;
  }
  EXPECT_GT(left, 500u) << "the east river (+X is on the left looking down +Z)";
  EXPECT_GT(right, 500u) << "the west river";
  const RunResult r = run_siviflow("capture " + scene.string() + " --frames 1 --size 64x36 "
                                   "--aov flow --out " + (dir_ / "out").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("the scene has 2"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace siviflow::testing
