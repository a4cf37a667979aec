// The viewer's "save look to scene file": the look written into a scene file reads back as it
// was, the file's other keys are kept, and a file that is not a scene is left alone.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "run_command.h"
#include "siviflow/scene_file.h"
#include "view/look_file.h"

namespace siviflow {
namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

WaterLook tuned_look() {
  WaterLook look;
  look.water_color = {0.2f, 0.3f, 0.25f};
  look.ripple_strength = 1.25f;
  look.tile_size_m = 5.0f;
  look.sun_glint = 3.0f;
  look.material = WaterMaterial::kFlowMap;
  return look;
}

TEST(LookFile, SavedLookReadsBackAndKeepsTheScene) {
  const auto dir = testing::fresh_test_dir("look_file");
  const auto path = dir / "scene.json";
  std::ofstream(path) << R"({"version": 1, "river": {"procedural": {}}, "render": {"size": [320, 180]}, "look": {"fresnel_f0": 0.5}})";
  const Status saved = view::save_look_to_scene(path.string(), tuned_look());
  ASSERT_TRUE(saved.ok()) << saved.message();
  SceneFile scene;
  const Status loaded = load_scene_file(path.string(), &scene);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(scene.render.width, 320u);
  EXPECT_FLOAT_EQ(scene.look.ripple_strength, 1.25f);
  EXPECT_FLOAT_EQ(scene.look.tile_size_m, 5.0f);
  EXPECT_FLOAT_EQ(scene.look.sun_glint, 3.0f);
  EXPECT_EQ(scene.look.material, WaterMaterial::kFlowMap);
  EXPECT_FLOAT_EQ(scene.look.water_color.g, 0.3f);
  EXPECT_FLOAT_EQ(scene.look.fresnel_f0, WaterLook{}.fresnel_f0) << "every field is written";
}

TEST(LookFile, MissingFileBecomesASceneWithTheLook) {
  const auto dir = testing::fresh_test_dir("look_file");
  const auto path = dir / "new.json";
  const Status saved = view::save_look_to_scene(path.string(), tuned_look());
  ASSERT_TRUE(saved.ok()) << saved.message();
  SceneFile scene;
  ASSERT_TRUE(load_scene_file(path.string(), &scene).ok());
  EXPECT_FLOAT_EQ(scene.look.ripple_strength, 1.25f);
}

TEST(LookFile, NotASceneIsRefusedAndLeftAsItWas) {
  const auto dir = testing::fresh_test_dir("look_file");
  const auto path = dir / "list.json";
  std::ofstream(path) << "[1, 2, 3]";
  const Status status = view::save_look_to_scene(path.string(), tuned_look());
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("list.json"), std::string::npos) << status.message();
  EXPECT_EQ(read_all(path), "[1, 2, 3]");
}

}  // namespace
}  // namespace siviflow
