// The scene files the project ships follow the scene schema and load: the examples under
// examples/scenes (with every glTF file they name, its rivers as the renderer takes them) and the
// fuzz seeds of the scene parser. The schema check itself refuses what the schema forbids.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "json_schema_check.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kSource = SIVIFLOW_SOURCE_DIR;

Json read_json(const fs::path& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

SchemaCheck scene_schema() {
  return SchemaCheck(read_json(kSource / "engine/scene/scene.schema.json"));
}

std::vector<fs::path> json_files(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string lines(const std::vector<std::string>& errors) {
  std::string text;
  for (const std::string& e : errors) text += e + "\n";
  return text;
}

TEST(ShippedScenes, ExamplesFollowTheSchemaAndLoadEveryRiver) {
  const SchemaCheck schema = scene_schema();
  const std::vector<fs::path> examples = json_files(kSource / "examples" / "scenes");
  std::vector<std::string> names;
  for (const fs::path& file : examples) names.push_back(file.filename().string());
  EXPECT_EQ(names,
            (std::vector<std::string>{"confluence.json", "gltf_fork.json", "gltf_river.json",
                                      "island.json", "muddy_river.json", "two_rivers.json"}));
  for (const fs::path& file : examples) {
    const std::vector<std::string> errors = schema.errors(read_json(file));
    EXPECT_TRUE(errors.empty()) << file << "\n" << lines(errors);
    SceneFile scene;
    const Status loaded = load_scene_file(file.string(), &scene);
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    for (size_t i = 0; i < scene.rivers.size(); ++i) {
      SceneRiverData river;
      const Status status = scene_river_data(&scene, i, &river);
      EXPECT_TRUE(status.ok()) << status.message();
      EXPECT_GT(river.mesh.indices.size(), 100u) << file << " river " << i;
    }
  }
}

TEST(ShippedScenes, FuzzSeedsFollowTheSchemaAndNameFilesThatExist) {
  const SchemaCheck schema = scene_schema();
  const fs::path seeds = kSource / "tests" / "fuzz" / "seeds" / "scene";
  for (const fs::path& file : json_files(seeds)) {
    const std::vector<std::string> errors = schema.errors(read_json(file));
    EXPECT_TRUE(errors.empty()) << file << "\n" << lines(errors);
    SceneFile scene;
    const Status loaded = load_scene_file(file.string(), &scene);
    EXPECT_TRUE(loaded.ok()) << loaded.message();
  }
  // The seed with several rivers is a whole scene: its glTF river is there and loads.
  SceneFile two;
  ASSERT_TRUE(load_scene_file((seeds / "two_rivers.json").string(), &two).ok());
  ASSERT_EQ(two.rivers.size(), 2u);
  for (size_t i = 0; i < two.rivers.size(); ++i) {
    SceneRiverData river;
    const Status status = scene_river_data(&two, i, &river);
    EXPECT_TRUE(status.ok()) << status.message();
  }
}

TEST(ShippedScenes, SchemaCheckRefusesWhatTheSchemaForbids) {
  const SchemaCheck schema = scene_schema();
  const Json good = Json::parse(R"({"version": 1, "river": {"procedural": {}}})");
  EXPECT_TRUE(schema.errors(good).empty()) << lines(schema.errors(good));
  const struct {
    const char* text;
    const char* error;
  } cases[] = {
      {R"({"version": 2, "river": {"procedural": {}}})", ".version: is not 1"},
      {R"({"version": 1})", "matches 0 of the 2 schemas of oneOf"},
      {R"({"version": 1, "river": {"procedural": {}}, "colour": 1})",
       "key 'colour' is not allowed"},
      {R"({"version": 1, "river": {"procedural": {}, "mesh": "A"}})", "matches 0 of the 2"},
      {R"({"version": 1, "rivers": [{"gltf": "a.glb", "flow": {"p": 2}, "x": 1}]})",
       "matches 0 of the 2"},
      {R"({"version": 1, "river": {"procedural": {}}, "look": {"fresnel_f0": 2}})",
       ".look.fresnel_f0: 2 breaks maximum 1"},
      {R"({"version": 1, "river": {"procedural": {}}, "render": {"size": [0, 10]}})",
       ".render.size[0]: 0 breaks minimum 1"},
      {R"({"version": 1, "river": {"procedural": {}},
           "obstacles": [{"center": [0, 0, 0], "radius": 1, "polygon": [[0, 0], [1, 0], [0, 1]]}]})",
       ".obstacles[0]: matches 0 of the 2"},
  };
  for (const auto& c : cases) {
    const std::string errors = lines(schema.errors(Json::parse(c.text)));
    EXPECT_NE(errors.find(c.error), std::string::npos) << c.text << "\n" << errors;
  }
}

}  // namespace
}  // namespace siviflow::testing
