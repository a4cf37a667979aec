// Scene file version 1: every field, the defaults, and the errors (each names the file and the
// JSON path of the problem). Also keeps engine/scene/scene.schema.json in step with the parser.
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "siviflow/scene_file.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const std::string kFile = "scenes/test.json";
const std::string kFolder = "/data/scenes";

Status parse(const std::string& text, SceneFile* scene) {
  return parse_scene_file(text, kFile, kFolder, scene);
}

void expect_error(const std::string& text, std::initializer_list<std::string> parts) {
  SceneFile scene;
  const Status status = parse(text, &scene);
  ASSERT_FALSE(status.ok()) << "accepted: " << text;
  EXPECT_EQ(status.message().rfind(kFile + ": ", 0), 0u)
      << "must start with the file: " << status.message();
  for (const std::string& part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << "missing '" << part << "' in: " << status.message();
  }
}

// A minimal valid file with `patch` merged in (RFC 7386: null removes a key).
std::string with(const Json& patch) {
  Json doc = {{"version", 1}, {"river", {{"procedural", Json::object()}}}};
  doc.merge_patch(patch);
  return doc.dump();
}

fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::path(SIVIFLOW_BINARY_DIR) / "test_tmp" / "scene_file" / info->name();
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::trunc);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

const char* kFullScene = R"({
  "$schema": "../engine/scene/scene.schema.json",
  "version": 1,
  "river": { "gltf": "rivers/river.glb", "mesh": "River" },
  "flow": { "discharge": 12.5, "p": 1.25, "search_radius": 30.0 },
  "obstacles": [
    { "center": [1, 0, 2], "radius": 1.5 },
    { "center": [0, 0, 0], "radius": 0.75,
      "keys": [ { "t": 0.0, "center": [0, 0, -10] }, { "t": 4.5, "center": [0, 0, 10] } ] }
  ],
  "objects": [
    { "gltf": "duck.glb", "translation": [2, 0.5, -3], "rotation": [0, 0, 0, 2],
      "scale": [2, 2, 2], "obstacle": true },
    { "gltf": "/assets/rock.gltf" }
  ],
  "camera": { "fov_y_deg": 42,
              "keys": [ { "t": 0, "position": [0, 5, -20], "target": [0, 0, 0] },
                        { "t": 10, "position": [0, 5, 20], "target": [0, 0, 40] } ] },
  "render": { "size": [640, 360], "fps": 24, "seed": 99 }
})";

TEST(SceneFile, FullFileParsesEveryField) {
  SceneFile scene;
  const Status status = parse(kFullScene, &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(scene.path, kFile);
  EXPECT_EQ(scene.folder, kFolder);
  EXPECT_EQ(scene.rivers[0].source, SceneRiver::Source::kGltf);
  EXPECT_EQ(scene.rivers[0].gltf, "/data/scenes/rivers/river.glb");
  EXPECT_EQ(scene.rivers[0].mesh, "River");
  EXPECT_EQ(scene.rivers[0].flow.discharge, 12.5f);
  EXPECT_EQ(scene.rivers[0].flow.p, 1.25f);
  EXPECT_EQ(scene.rivers[0].flow.search_radius, 30.0f);

  ASSERT_EQ(scene.obstacles.size(), 2u);
  EXPECT_EQ(scene.obstacles[0].centre, glm::vec3(1, 0, 2));
  EXPECT_EQ(scene.obstacles[0].radius, 1.5f);
  EXPECT_TRUE(scene.obstacles[0].keys.empty());
  EXPECT_TRUE(scene.obstacles[0].polygon.empty());
  ASSERT_EQ(scene.obstacles[1].keys.size(), 2u);
  EXPECT_EQ(scene.obstacles[1].radius, 0.75f);
  EXPECT_EQ(scene.obstacles[1].keys[1].t, 4.5);
  EXPECT_EQ(scene.obstacles[1].keys[1].centre, glm::vec3(0, 0, 10));

  ASSERT_EQ(scene.objects.size(), 2u);
  const SceneObject& duck = scene.objects[0];
  EXPECT_EQ(duck.gltf, "/data/scenes/duck.glb");
  EXPECT_EQ(duck.translation, glm::vec3(2, 0.5f, -3));
  EXPECT_EQ(duck.rotation, glm::quat(1, 0, 0, 0)) << "[0,0,0,2] is x,y,z,w, normalised";
  EXPECT_EQ(duck.scale, glm::vec3(2));
  EXPECT_TRUE(duck.obstacle);
  const SceneObject& rock = scene.objects[1];
  EXPECT_EQ(rock.gltf, "/assets/rock.gltf") << "absolute paths are kept";
  EXPECT_EQ(rock.translation, glm::vec3(0));
  EXPECT_EQ(rock.rotation, glm::quat(1, 0, 0, 0));
  EXPECT_EQ(rock.scale, glm::vec3(1));
  EXPECT_FALSE(rock.obstacle);

  EXPECT_EQ(scene.camera.fov_y_deg, 42.0f);
  ASSERT_EQ(scene.camera.keys.size(), 2u);
  EXPECT_EQ(scene.camera.keys[1].t, 10.0);
  EXPECT_EQ(scene.camera.keys[1].position, glm::vec3(0, 5, 20));
  EXPECT_EQ(scene.camera.keys[1].target, glm::vec3(0, 0, 40));

  EXPECT_EQ(scene.render.width, 640u);
  EXPECT_EQ(scene.render.height, 360u);
  EXPECT_EQ(scene.render.fps, 24.0);
  EXPECT_EQ(scene.render.seed, 99u);
}

TEST(SceneFile, RotationIsReadXyzw) {
  SceneFile scene;
  const Status status =
      parse(with({{"objects", {{{"gltf", "a.glb"}, {"rotation", {0, 1, 0, 0}}}}}}), &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(scene.objects[0].rotation.y, 1.0f);
  EXPECT_EQ(scene.objects[0].rotation.w, 0.0f);
}

TEST(SceneFile, PolygonObstacleParses) {
  SceneFile scene;
  const Status status = parse(with({{"obstacles",
                                     {{{"center", {1, 0.5, 2}},
                                       {"polygon", {{-1, -1}, {2, -1}, {2, 0}, {0, 0}, {0, 1.5}}},
                                       {"keys", {{{"t", 0}, {"center", {1, 0.5, 2}}}}}}}}}),
                              &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(scene.obstacles.size(), 1u);
  const Obstacle& o = scene.obstacles[0];
  EXPECT_EQ(o.centre, glm::vec3(1, 0.5f, 2));
  EXPECT_EQ(o.radius, 0.0f) << "a polygon footprint has no radius";
  ASSERT_EQ(o.polygon.size(), 5u);
  EXPECT_EQ(o.polygon[0], glm::vec2(-1, -1));
  EXPECT_EQ(o.polygon[4], glm::vec2(0, 1.5f));
  EXPECT_EQ(o.keys.size(), 1u);
  // Either winding is accepted (a clockwise triangle).
  ASSERT_TRUE(parse(with({{"obstacles", {{{"center", {0, 0, 0}},
                                          {"polygon", {{0, 0}, {0, 1}, {1, 0}}}}}}}),
                    &scene)
                  .ok());
}

TEST(SceneFile, ObstacleNeedsExactlyOneOfRadiusAndPolygon) {
  expect_error(with({{"obstacles", {{{"center", {0, 0, 0}}, {"radius", 1},
                                     {"polygon", {{0, 0}, {1, 0}, {0, 1}}}}}}}),
               {"obstacles[0]: ", "either 'radius'", "'polygon'", "not both"});
  expect_error(with({{"obstacles", {{{"center", {0, 0, 0}}, {"radius", 1}},
                                    {{"center", {0, 0, 0}}}}}}),
               {"obstacles[1]: needs 'radius'", "'polygon'"});
}

TEST(SceneFile, BadPolygonsNameThePath) {
  const auto polygon = [](const Json& points) {
    return with({{"obstacles", {{{"center", {0, 0, 0}}, {"polygon", points}}}}});
  };
  expect_error(polygon(Json::array()), {"obstacles[0].polygon: has 0 points", "at least 3"});
  expect_error(polygon({{0, 0}, {1, 0}}), {"obstacles[0].polygon: has 2 points", "at least 3"});
  expect_error(polygon({{0, 0}, {1e39, 0}, {0, 1}}),
               {"obstacles[0].polygon[1][0]: ", "not a finite 32-bit float"});
  expect_error(polygon({{0, 0}, {1, 0}, {0, nullptr}}),
               {"obstacles[0].polygon[2][1]: must be a number, not null"});
  // JSON has no NaN; an overflowing literal is the nearest a file can get to one.
  expect_error(R"({"version":1,"river":{"procedural":{}},
                  "obstacles":[{"center":[0,0,0],"polygon":[[0,0],[1e400,0],[0,1]]}]})",
               {"not valid JSON"});
  expect_error(polygon({{0, 0, 0}, {1, 0}, {0, 1}}),
               {"obstacles[0].polygon[0]: must be an array of 2 numbers, not 3"});
  expect_error(polygon({{0, 0}, {1, 0}, {2, 0}}), {"obstacles[0].polygon: ", "zero area"});
  expect_error(polygon({{0, 0}, {1, 1}, {1, 0}, {0, 1}}),
               {"obstacles[0].polygon: is not a simple polygon: edges 0 and 2"});
  expect_error(polygon({{0, 0}, {1, 0}, {1, 1}, {0, 0}}),
               {"obstacles[0].polygon: point 3 repeats point 0", "do not repeat the first point"});
  expect_error(polygon({{0, 0}, {2, 0}, {1, 0}, {1, 1}}),
               {"obstacles[0].polygon: the outline doubles back on itself at point 1"});
}

TEST(SceneFile, DefaultsWhenOptionalPartsAreAbsent) {
  SceneFile scene;
  const Status status = parse(R"({"version": 1, "river": {"procedural": {}}})", &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  const ProceduralRiverParams defaults;
  EXPECT_EQ(scene.rivers[0].source, SceneRiver::Source::kProcedural);
  EXPECT_EQ(scene.rivers[0].procedural.length, defaults.length);
  EXPECT_EQ(scene.rivers[0].procedural.width, defaults.width);
  EXPECT_EQ(scene.rivers[0].procedural.seed, defaults.seed);
  EXPECT_EQ(scene.rivers[0].procedural.vertices_across, defaults.vertices_across);
  EXPECT_EQ(scene.rivers[0].flow.discharge, kDefaultSceneDischarge);
  EXPECT_EQ(scene.rivers[0].flow.p, kDefaultShepardPower);
  EXPECT_EQ(scene.rivers[0].flow.search_radius, 0.0f) << "0: 3 x the widest section";
  EXPECT_TRUE(scene.obstacles.empty());
  EXPECT_TRUE(scene.objects.empty());
  EXPECT_EQ(scene.camera.fov_y_deg, 50.0f);
  EXPECT_TRUE(scene.camera.keys.empty()) << "the built-in river camera";
  EXPECT_EQ(scene.render.width, 1280u);
  EXPECT_EQ(scene.render.height, 720u);
  EXPECT_EQ(scene.render.fps, 30.0);
  EXPECT_EQ(scene.render.seed, 1u);

  // Empty sections give the same defaults.
  SceneFile empty_sections;
  ASSERT_TRUE(parse(with({{"flow", Json::object()},
                          {"camera", Json::object()},
                          {"render", Json::object()},
                          {"obstacles", Json::array()},
                          {"objects", Json::array()}}),
                    &empty_sections)
                  .ok());
  EXPECT_EQ(empty_sections.rivers[0].flow.discharge, kDefaultSceneDischarge);
  EXPECT_EQ(empty_sections.render.width, 1280u);
}

TEST(SceneFile, ProceduralParametersAreParsed) {
  SceneFile scene;
  const Status status = parse(with({{"river",
                                     {{"procedural",
                                       {{"length", 300},
                                        {"meander_amplitude", 0},
                                        {"meander_wavelength", 90.5},
                                        {"width", 8},
                                        {"width_variation", 0.1},
                                        {"depth", 2},
                                        {"bank_height", 1},
                                        {"valley_half_width", 50},
                                        {"valley_wall_height", 10},
                                        {"seed", 4000000000u},
                                        {"section_spacing", 0.5},
                                        {"vertices_across", 9}}}}}}),
                              &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  const ProceduralRiverParams& p = scene.rivers[0].procedural;
  EXPECT_EQ(p.length, 300.0f);
  EXPECT_EQ(p.meander_amplitude, 0.0f);
  EXPECT_EQ(p.meander_wavelength, 90.5f);
  EXPECT_EQ(p.width, 8.0f);
  EXPECT_EQ(p.width_variation, 0.1f);
  EXPECT_EQ(p.depth, 2.0f);
  EXPECT_EQ(p.bank_height, 1.0f);
  EXPECT_EQ(p.valley_half_width, 50.0f);
  EXPECT_EQ(p.valley_wall_height, 10.0f);
  EXPECT_EQ(p.seed, 4000000000u);
  EXPECT_EQ(p.section_spacing, 0.5f);
  EXPECT_EQ(p.vertices_across, 9u);
}

TEST(SceneFile, MessagesQuoteTheFilesBytesAsText) {
  // A key holding a terminal's escape sequence, and a file that is not UTF-8 at all: the
  // messages name them with the bytes escaped.
  expect_error(R"({"version": 1, "river": {"procedural": {}}, "colour\u001b[31m": 1})",
               {"colour\\x1B[31m: unknown key"});
  SceneFile scene;
  const Status status = parse("{\"version\": 1, \"na\xFF\xFEme\": 1}", &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("\\xFF"), std::string::npos) << status.message();
  EXPECT_EQ(status.message().find('\xFF'), std::string::npos) << "no raw byte";
}

TEST(SceneFile, UnknownKeysNameTheirPathAndTheFile) {
  expect_error(with({{"colour", "blue"}}),
               {"colour: unknown key", "allowed here: $schema, version, river"});
  expect_error(with({{"flow", {{"dischrage", 3}}}}), {"flow.dischrage: unknown key"});
  expect_error(with({{"river", {{"procedural", {{"wdith", 3}}}}}}),
               {"river.procedural.wdith: unknown key"});
  expect_error(
      with(
          {{"obstacles",
            {{{"center", {0, 0, 0}},
              {"radius", 1},
              {"keys", {{{"t", 0}, {"center", {0, 0, 0}}}, {{"t", 1}, {"centre", {0, 0, 0}}}}}}}}}),
      {"obstacles[0].keys[1].centre: unknown key (allowed here: t, center)"});
  expect_error(with({{"objects", {{{"gltf", "a.glb"}, {"position", {0, 0, 0}}}}}}),
               {"objects[0].position: unknown key"});
  expect_error(
      with({{"camera",
             {{"keys",
               {{{"t", 0}, {"position", {0, 0, 0}}, {"target", {1, 0, 0}}, {"up", {0, 1, 0}}}}}}}}),
      {"camera.keys[0].up: unknown key"});
  expect_error(with({{"render", {{"width", 3}}}}), {"render.width: unknown key"});
}

TEST(SceneFile, WrongTypesNameThePath) {
  expect_error(with({{"flow", {{"discharge", "20"}}}}),
               {"flow.discharge: must be a number, not string"});
  expect_error(with({{"flow", 3}}), {"flow: must be an object, not number"});
  expect_error(with({{"obstacles", {{"center", {0, 0, 0}}}}}),
               {"obstacles: must be an array, not object"});
  expect_error(with({{"obstacles", {{{"center", {0, 0}}, {"radius", 1}}}}}),
               {"obstacles[0].center: must be an array of 3 numbers, not 2"});
  expect_error(with({{"obstacles", {{{"center", {0, "x", 0}}, {"radius", 1}}}}}),
               {"obstacles[0].center[1]: must be a number, not string"});
  expect_error(with({{"objects", {{{"gltf", "a.glb"}, {"obstacle", "yes"}}}}}),
               {"objects[0].obstacle: must be true or false, not string"});
  expect_error(with({{"objects", {{{"gltf", 5}}}}}),
               {"objects[0].gltf: must be a string, not number"});
  expect_error(with({{"objects", {{{"gltf", ""}}}}}), {"objects[0].gltf: must not be empty"});
  expect_error(with({{"objects", {{{"gltf", "a.glb"}, {"rotation", {0, 0, 1}}}}}}),
               {"objects[0].rotation: must be an array of 4 numbers, not 3"});
  expect_error(with({{"render", {{"size", Json::array({1280})}}}}),
               {"render.size: must be an array of 2 integers"});
  expect_error(with({{"render", {{"size", {1280.5, 720}}}}}),
               {"render.size[0]: 1280.5 must be an integer"});
  expect_error(with({{"render", {{"seed", -1}}}}), {"render.seed: -1 must not be negative"});
  expect_error(with({{"river", {{"procedural", {{"seed", "7"}}}}}}),
               {"river.procedural.seed: must be an integer, not string"});
  expect_error(with({{"river", {{"procedural", nullptr}, {"gltf", Json::array()}}}}),
               {"river.gltf: must be a string, not array"});
}

TEST(SceneFile, OutOfRangeValuesNameThePath) {
  expect_error(with({{"obstacles", {{{"center", {0, 0, 0}}, {"radius", -1.5}}}}}),
               {"obstacles[0].radius: -1.5 must be > 0"});
  expect_error(with({{"flow", {{"discharge", 0}}}}), {"flow.discharge: 0 must be > 0"});
  expect_error(with({{"flow", {{"discharge", -3}}}}), {"flow.discharge: -3 must be > 0"});
  expect_error(with({{"flow", {{"p", 0}}}}), {"flow.p: 0 must be > 0"});
  expect_error(with({{"flow", {{"p", 17}}}}), {"flow.p: 17 must be at most 16"});
  expect_error(with({{"flow", {{"search_radius", 0}}}}), {"flow.search_radius: 0 must be > 0"});
  expect_error(with({{"flow", {{"discharge", 1e39}}}}),
               {"flow.discharge: 1e+39 is not a finite 32-bit float"});
  expect_error(R"({"version": 1, "river": {"procedural": {}}, "flow": {"p": 1e400}})",
               {"not valid JSON", "number overflow parsing '1e400'"});
  expect_error(with({{"render", {{"size", {0, 720}}}}}), {"render.size[0]: must be at least 1"});
  expect_error(with({{"render", {{"size", {1280, 20000}}}}}),
               {"render.size[1]: 20000 is more than the limit of 16384"});
  expect_error(with({{"render", {{"fps", 0}}}}), {"render.fps: 0 must be in (0, 1000]"});
  expect_error(with({{"render", {{"seed", 4294967296ull}}}}),
               {"render.seed: 4294967296 is more than the limit"});
  expect_error(with({{"camera", {{"fov_y_deg", 180}}}}),
               {"camera.fov_y_deg: 180 must be below 180"});
  expect_error(
      with({{"camera", {{"keys", {{{"t", 0}, {"position", {1, 2, 3}}, {"target", {1, 2, 3}}}}}}}}),
      {"camera.keys[0].target: must differ from position"});
  expect_error(with({{"objects", {{{"gltf", "a.glb"}, {"rotation", {0, 0, 0, 0}}}}}}),
               {"objects[0].rotation: must be a non-zero quaternion"});
  expect_error(with({{"objects", {{{"gltf", "a.glb"}, {"scale", {1, 0, 1}}}}}}),
               {"objects[0].scale: every component must be non-zero"});
  expect_error(with({{"river", {{"procedural", {{"vertices_across", 1}}}}}}),
               {"river.procedural: vertices_across = 1 must be at least 2"});
  expect_error(with({{"river", {{"procedural", {{"width", -4}}}}}}),
               {"river.procedural: width = -4 must be finite and > 0"});
}

TEST(SceneFile, KeysMustBeSortedByTime) {
  expect_error(
      with(
          {{"obstacles",
            {{{"center", {0, 0, 0}},
              {"radius", 1},
              {"keys", {{{"t", 2}, {"center", {0, 0, 0}}}, {{"t", 1}, {"center", {0, 0, 1}}}}}}}}}),
      {"obstacles[0].keys[1].t: keys are not sorted by t (1 after 2)"});
  expect_error(with({{"camera",
                      {{"keys",
                        {{{"t", 0}, {"position", {0, 1, 0}}, {"target", {0, 0, 1}}},
                         {{"t", 0}, {"position", {0, 1, 0}}, {"target", {0, 0, 2}}}}}}}}),
               {"camera.keys[1].t: two keys at t = 0"});
}

TEST(SceneFile, VersionMustBeOne) {
  expect_error(with({{"version", 2}}),
               {"version: version 2 is not supported (this build reads version 1)"});
  expect_error(with({{"version", "1"}}), {"version: must be an integer, not string"});
  expect_error(R"({"river": {"procedural": {}}})", {"missing required key 'version'"});
  // A newer file's new keys report the version, not an unknown key.
  expect_error(with({{"version", 2}, {"lights", Json::array()}}), {"version 2 is not supported"});
}

TEST(SceneFile, RiverIsRequiredAndHasOneSource) {
  expect_error(R"({"version": 1})", {"missing required key 'river'"});
  expect_error(with({{"river", {{"gltf", "r.glb"}}}}),  // merged beside the procedural source
               {"river: give either 'gltf' or 'procedural', not both"});
  expect_error(with({{"river", {{"procedural", nullptr}}}}), {"river: needs 'gltf'"});
  expect_error(with({{"river", {{"mesh", "River"}}}}), {"river.mesh: only goes with 'gltf'"});
  SceneFile scene;
  const Status status =
      parse(with({{"river", {{"procedural", nullptr}, {"gltf", "r.glb"}}}}), &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(scene.rivers[0].mesh, "") << "mesh is optional: the first mesh";
}

TEST(SceneFile, MalformedJsonIsAnErrorNamingTheFile) {
  expect_error("", {"not valid JSON"});
  expect_error("{\"version\": 1,", {"not valid JSON"});
  expect_error("[1, 2]", {"the top level must be a JSON object, not array"});
  expect_error(R"({"version": 1, "version": 1, "river": {"procedural": {}}})",
               {"duplicate key 'version'"});
  expect_error(with({{"flow", {{"p", 1}}}}).insert(1, "\"flow\": {}, "), {"duplicate key 'flow'"});
  expect_error(std::string(100000, '[') + std::string(100000, ']'),
               {"JSON nested deeper than 64 levels"});
}

TEST(SceneFile, LoadsFromDiskAndResolvesPathsAgainstTheFilesFolder) {
  const fs::path dir = test_dir();
  write_file(dir / "scenes" / "valley.json",
             R"({"version": 1, "river": {"gltf": "../models/river.glb"},
                 "objects": [{"gltf": "props/duck.glb"}, {"gltf": "./props/../rock.glb"}]})");
  SceneFile scene;
  const Status status = load_scene_file((dir / "scenes" / "valley.json").string(), &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(fs::path(scene.folder), dir / "scenes");
  EXPECT_EQ(fs::path(scene.rivers[0].gltf), dir / "models" / "river.glb");
  EXPECT_EQ(fs::path(scene.objects[0].gltf), dir / "scenes" / "props" / "duck.glb");
  EXPECT_EQ(fs::path(scene.objects[1].gltf), dir / "scenes" / "rock.glb");
}

TEST(SceneFile, LoadRefusesMissingAndSpecialFiles) {
  const fs::path dir = test_dir();
  SceneFile scene;
  Status status = load_scene_file((dir / "absent.json").string(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("absent.json: cannot open"), std::string::npos)
      << status.message();
  status = load_scene_file(dir.string(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not a regular file"), std::string::npos) << status.message();
  ASSERT_EQ(::mkfifo((dir / "pipe.json").c_str(), 0600), 0);
  status = load_scene_file((dir / "pipe.json").string(), &scene);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pipe.json: not a regular file"), std::string::npos)
      << status.message();
}

TEST(SceneFile, FailureLeavesTheOutputUntouched) {
  SceneFile scene;
  scene.render.width = 77;
  ASSERT_FALSE(parse(with({{"render", {{"size", {0, 1}}}}}), &scene).ok());
  EXPECT_EQ(scene.render.width, 77u);
}

// --- The JSON Schema agrees with the parser ---------------------------------------------------

Json load_schema() {
  const fs::path path = fs::path(SIVIFLOW_TEST_DATA_DIR).parent_path().parent_path() / "engine" /
                        "scene" / "scene.schema.json";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return Json::parse(text.str());
}

TEST(SceneFileSchema, ProceduralPropertiesAndDefaultsMatchTheParser) {
  EXPECT_EQ(sizeof(ProceduralRiverParams), 12 * sizeof(float) + sizeof(std::vector<ProceduralIsland>) +
                                               sizeof(std::optional<ProceduralConfluence>))
      << "ProceduralRiverParams changed: add the field to kProceduralFloats/kProceduralUints in "
         "engine/scene/scene_file.cpp and to engine/scene/scene.schema.json";
  const Json schema = load_schema();
  const Json& props = schema["$defs"]["procedural"]["properties"];
  std::set<std::string> schema_keys;
  for (const auto& item : props.items()) schema_keys.insert(item.key());
  const std::vector<std::string> parser_keys = procedural_river_keys();
  EXPECT_EQ(schema_keys, std::set<std::string>(parser_keys.begin(), parser_keys.end()));
  // Every schema default, written out, parses to the struct's default (a confluence, absent by
  // default, has its own defaults below).
  Json procedural = Json::object();
  for (const auto& item : props.items()) {
    if (item.value().contains("default")) procedural[item.key()] = item.value()["default"];
  }
  SceneFile from_defaults;
  const Status status = parse(with({{"river", {{"procedural", procedural}}}}), &from_defaults);
  ASSERT_TRUE(status.ok()) << status.message();
  const ProceduralRiverParams d;
  const ProceduralRiverParams& p = from_defaults.rivers[0].procedural;
  EXPECT_EQ(p.length, d.length);
  EXPECT_EQ(p.meander_amplitude, d.meander_amplitude);
  EXPECT_EQ(p.meander_wavelength, d.meander_wavelength);
  EXPECT_EQ(p.width, d.width);
  EXPECT_EQ(p.width_variation, d.width_variation);
  EXPECT_EQ(p.depth, d.depth);
  EXPECT_EQ(p.bank_height, d.bank_height);
  EXPECT_EQ(p.valley_half_width, d.valley_half_width);
  EXPECT_EQ(p.valley_wall_height, d.valley_wall_height);
  EXPECT_EQ(p.seed, d.seed);
  EXPECT_EQ(p.section_spacing, d.section_spacing);
  EXPECT_EQ(p.vertices_across, d.vertices_across);
  EXPECT_FALSE(p.confluence.has_value());
  // The confluence's own defaults, written out, parse to ProceduralConfluence's.
  const Json& confluence_props = props["confluence"]["properties"];
  Json confluence = Json::object();
  for (const auto& item : confluence_props.items()) confluence[item.key()] = item.value()["default"];
  SceneFile with_confluence;
  ASSERT_TRUE(parse(with({{"river", {{"procedural", {{"confluence", confluence}}}}}}), &with_confluence).ok());
  const ProceduralConfluence dc;
  ASSERT_TRUE(with_confluence.rivers[0].procedural.confluence.has_value());
  EXPECT_EQ(with_confluence.rivers[0].procedural.confluence->tip_z, dc.tip_z);
  EXPECT_EQ(with_confluence.rivers[0].procedural.confluence->offset, dc.offset);
  EXPECT_EQ(with_confluence.rivers[0].procedural.confluence->angle_deg, dc.angle_deg);
}

// A river's ends: each a vertex or a point and an inflow or an outflow; their inflows make the
// discharge; bad ones named by key and value.
TEST(SceneFile, RiverEndsCarryTheirDischarges) {
  SceneFile scene;
  const Json ends = {{{"vertex", 3}, {"inflow", 2.0}},
                     {{"near", {1.0, 0.0, -40.0}}, {"inflow", 1.5}},
                     {{"vertex", 9}, {"outflow", 3.5}}};
  const Status parsed = parse(with({{"river", {{"procedural", nullptr}, {"gltf", "y.glb"}, {"ends", ends}}}}), &scene);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  const std::vector<SceneRiverEnd>& e = scene.rivers[0].ends;
  ASSERT_EQ(e.size(), 3u);
  EXPECT_TRUE(e[0].by_vertex);
  EXPECT_EQ(e[0].vertex, 3u);
  EXPECT_FALSE(e[1].by_vertex);
  EXPECT_EQ(e[1].near, glm::vec3(1.0f, 0.0f, -40.0f));
  EXPECT_FALSE(e[2].inflow);
  EXPECT_EQ(e[2].discharge, 3.5f);
  EXPECT_EQ(scene.rivers[0].flow.discharge, 3.5f);

  auto refused = [&](const Json& bad, std::initializer_list<const char*> parts) {
    const Status status = parse(with({{"river", {{"procedural", nullptr}, {"gltf", "y.glb"}, {"ends", bad}}}}), &scene);
    ASSERT_FALSE(status.ok());
    for (const char* part : parts) {
      EXPECT_NE(status.message().find(part), std::string::npos) << status.message() << " lacks " << part;
    }
  };
  refused({{{"vertex", 3}, {"inflow", 2.0}}, {{"vertex", 9}, {"outflow", 2.5}}},
          {"river.ends", "do not balance", "2 m^2/s flows in (2)", "2.5 m^2/s out (2.5)"});
  refused({{{"vertex", 3}, {"inflow", -2.0}}, {{"vertex", 9}, {"outflow", -2.0}}},
          {"river.ends[0].inflow", "-2 is negative"});
  refused({{{"vertex", 3}, {"inflow", 2.0}, {"outflow", 2.0}}, {{"vertex", 9}, {"outflow", 2.0}}},
          {"river.ends[0]", "either 'inflow' or 'outflow'"});
  refused({{{"inflow", 2.0}}, {{"vertex", 9}, {"outflow", 2.0}}}, {"river.ends[0]", "'vertex'", "'near'"});
  refused({{{"vertex", 3}, {"inflow", 2.0}}}, {"river.ends", "at least two"});
}

TEST(SceneFile, SeveralRiversEachWithTheirOwnFlow) {
  SceneFile scene;
  const Status status = parse(
      with({{"river", nullptr},
            {"flow", {{"discharge", 7.0}}},
            {"rivers", {{{"gltf", "a.glb"}, {"flow", {{"discharge", 3.0}, {"p", 2.0}}}},
                        {{"procedural", {{"width", 9.0}}}}}}}),
      &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(scene.rivers.size(), 2u);
  EXPECT_EQ(scene.rivers[0].source, SceneRiver::Source::kGltf);
  EXPECT_EQ(scene.rivers[0].flow.discharge, 3.0f);
  EXPECT_EQ(scene.rivers[0].flow.p, 2.0f);
  EXPECT_EQ(scene.rivers[1].procedural.width, 9.0f);
  EXPECT_EQ(scene.rivers[1].flow.discharge, 7.0f) << "the top-level flow is the default";
  // "river" still means one river, with the top-level flow.
  ASSERT_TRUE(parse(with({{"flow", {{"discharge", 5.0}}}}), &scene).ok());
  ASSERT_EQ(scene.rivers.size(), 1u);
  EXPECT_EQ(scene.rivers[0].flow.discharge, 5.0f);
}

TEST(SceneFile, BadRiverListsAreNamed) {
  expect_error(with({{"rivers", {{{"procedural", Json::object()}}}}}),
               {"rivers: give either 'river' or 'rivers', not both"});
  expect_error(with({{"river", nullptr}, {"rivers", Json::array()}}), {"rivers: needs at least one"});
  expect_error(with({{"river", nullptr}}), {"missing required key 'river' (or 'rivers')"});
  expect_error(with({{"river", nullptr}, {"rivers", {{{"procedural", Json::object()}}, {{"gltf", 3}}}}}),
               {"rivers[1].gltf"});
  expect_error(with({{"river", nullptr},
                     {"rivers", {{{"procedural", Json::object()}, {"flow", {{"p", 40}}}}}}}),
               {"rivers[0].flow.p", "at most 16"});
  expect_error(with({{"river", {{"procedural", Json::object()}, {"flow", Json::object()}}}}),
               {"river.flow: unknown key"});
  Json many = Json::array();
  for (size_t i = 0; i <= kMaxSceneRivers; ++i) many.push_back({{"procedural", Json::object()}});
  expect_error(with({{"river", nullptr}, {"rivers", many}}), {"rivers", "more than the limit"});
}

TEST(SceneFileSchema, LookKeysDefaultsAndRangesMatchWaterLook) {
  const Json schema = load_schema();
  const Json& look = schema["properties"]["look"]["properties"];
  EXPECT_EQ(look.size(), 18u) << "WaterLook has 18 fields";
  // All the schema's defaults, written out, give WaterLook's defaults.
  Json defaults = Json::object();
  for (const auto& item : look.items()) defaults[item.key()] = item.value()["default"];
  SceneFile scene;
  const Status status = parse(with({{"look", defaults}}), &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  const WaterLook d;
  const WaterLook& l = scene.look;
  EXPECT_EQ(l.material, d.material);
  EXPECT_EQ(l.water_color, d.water_color);
  EXPECT_EQ(l.deep_color, d.deep_color);
  EXPECT_EQ(l.absorption_per_metre, d.absorption_per_metre);
  EXPECT_EQ(l.opacity_per_metre, d.opacity_per_metre);
  EXPECT_EQ(l.ripple_strength, d.ripple_strength);
  EXPECT_EQ(l.ripple_scale, d.ripple_scale);
  EXPECT_EQ(l.tile_size_m, d.tile_size_m);
  EXPECT_EQ(l.reflection_distortion, d.reflection_distortion);
  EXPECT_EQ(l.fresnel_f0, d.fresnel_f0);
  EXPECT_EQ(l.sun_direction, d.sun_direction);
  EXPECT_EQ(l.sun_color, d.sun_color);
  EXPECT_EQ(l.sun_glint, d.sun_glint);
  EXPECT_EQ(l.foam_amount, d.foam_amount);
  EXPECT_EQ(l.foam_color, d.foam_color);
  EXPECT_EQ(l.opacity_tint, d.opacity_tint);
  EXPECT_EQ(l.refraction_distortion, d.refraction_distortion);
  // Each scalar's schema maximum is accepted, and just past it refused by name and value.
  for (const auto& item : look.items()) {
    if (!item.value().contains("maximum")) continue;
    const double max = item.value()["maximum"].get<double>();
    EXPECT_TRUE(parse(with({{"look", {{item.key(), max}}}}), &scene).ok()) << item.key();
    const Status over = parse(with({{"look", {{item.key(), max * 1.5 + 1.0}}}}), &scene);
    ASSERT_FALSE(over.ok()) << item.key();
    EXPECT_NE(over.message().find("look." + item.key()), std::string::npos) << over.message();
    EXPECT_NE(over.message().find("is outside"), std::string::npos) << over.message();
  }
}

TEST(SceneFile, LookKeysReachTheLookAndBadOnesAreNamed) {
  SceneFile scene;
  ASSERT_TRUE(parse(with({{"look", {{"water_color", {0.3, 0.1, 0.05}}, {"fresnel_f0", 0.1}}}}),
                    &scene).ok());
  EXPECT_EQ(scene.look.water_color, glm::vec3(0.3f, 0.1f, 0.05f));
  EXPECT_EQ(scene.look.fresnel_f0, 0.1f);
  EXPECT_EQ(scene.look.deep_color, WaterLook{}.deep_color);
  expect_error(with({{"look", {{"deep_color", {0.1, 2.0, 0.1}}}}}),
               {"look.deep_color", "component 1", "2 is outside [0, 1]"});
  expect_error(with({{"look", {{"sun_direction", {0, 0, 0}}}}}),
               {"look.sun_direction", "non-zero"});
  expect_error(with({{"look", {{"gloss", 1}}}}), {"look.gloss: unknown key", "fresnel_f0"});
}

TEST(SceneFile, ObstacleHeightDefaultsToItsBouldersAndMustNotBeNegative) {
  SceneFile scene;
  ASSERT_TRUE(parse(with({{"obstacles", {{{"center", {0, 0, 5}}, {"radius", 2.0}},
                                         {{"center", {0, 0, 9}}, {"radius", 1.0}, {"height", 3.5}}}}}),
                    &scene).ok());
  ASSERT_EQ(scene.obstacles.size(), 2u);
  EXPECT_FLOAT_EQ(scene.obstacles[0].height, 0.95f * 2.0f) << "the boulder drawn for it";
  EXPECT_FLOAT_EQ(scene.obstacles[1].height, 3.5f);
  expect_error(with({{"obstacles", {{{"center", {0, 0, 5}}, {"radius", 2.0}, {"height", -1}}}}}),
               {"obstacles[0]", "height -1", ">= 0"});
}

TEST(SceneFile, LookMaterialIsNamedAndAnUnknownOneRefused) {
  SceneFile scene;
  ASSERT_TRUE(parse(with({{"look", {{"material", "flowmap"}}}}), &scene).ok());
  EXPECT_EQ(scene.look.material, WaterMaterial::kFlowMap);
  ASSERT_TRUE(parse(with({{"look", {{"material", "tiled_directional_flow"}}}}), &scene).ok());
  EXPECT_EQ(scene.look.material, WaterMaterial::kTiledDirectionalFlow);
  const Json schema = load_schema();
  EXPECT_EQ(schema["properties"]["look"]["properties"]["material"]["enum"],
            Json({"tiled_directional_flow", "flowmap"}));
  expect_error(with({{"look", {{"material", "wavy"}}}}),
               {"look.material", "'wavy' is not a material", "tiled_directional_flow or flowmap"});
  expect_error(with({{"look", {{"material", 1}}}}), {"look.material", "must be a string"});
}

TEST(SceneFileSchema, SectionDefaultsAndKeysMatchTheParser) {
  const Json schema = load_schema();
  const Json& top = schema["properties"];
  EXPECT_EQ(schema["required"], Json({"version"}));
  EXPECT_EQ(schema["oneOf"], Json::parse(R"([{"required":["river"]},{"required":["rivers"]}])"));
  EXPECT_EQ(top["rivers"]["maxItems"].get<size_t>(), kMaxSceneRivers);
  const SceneFile defaults;
  EXPECT_EQ(top["flow"]["properties"]["discharge"]["default"].get<double>(),
            defaults.rivers[0].flow.discharge);
  EXPECT_EQ(top["flow"]["properties"]["p"]["default"].get<double>(), defaults.rivers[0].flow.p);
  EXPECT_EQ(top["camera"]["properties"]["fov_y_deg"]["default"].get<double>(),
            defaults.camera.fov_y_deg);
  EXPECT_EQ(top["render"]["properties"]["size"]["default"],
            Json({defaults.render.width, defaults.render.height}));
  EXPECT_EQ(top["render"]["properties"]["fps"]["default"].get<double>(), defaults.render.fps);
  EXPECT_EQ(top["render"]["properties"]["seed"]["default"].get<uint32_t>(), defaults.render.seed);
  // Every property the schema lists anywhere is accepted by the parser (no "unknown key").
  SceneFile scene;
  const Status status = parse(kFullScene, &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  for (const char* section : {"flow", "camera", "render"}) {
    for (const auto& item : top[section]["properties"].items()) {
      if (!item.value().contains("default")) continue;
      const Status s = parse(with({{section, {{item.key(), item.value()["default"]}}}}), &scene);
      EXPECT_TRUE(s.ok()) << section << "." << item.key() << ": " << s.message();
    }
  }
  for (const char* key : {"version", "river", "rivers", "flow", "obstacles", "objects", "floats",
                          "camera", "render", "look", "$schema"}) {
    EXPECT_TRUE(top.contains(key)) << key;
  }
  EXPECT_EQ(top.size(), 11u) << "a top-level key the parser does not know";
  // Floats: every listed key parses, and the listed mesh names are the parser's.
  const Json& floating = top["floats"]["items"];
  EXPECT_EQ(top["floats"]["maxItems"].get<size_t>(), kMaxSceneFloats);
  EXPECT_EQ(floating["required"], Json({"release_point"}));
  EXPECT_EQ(floating["properties"]["mesh"]["enum"], Json({"log", "leaf"}));
  const Status with_every_key = parse(
      with({{"floats", {{{"mesh", "leaf"}, {"release_point", {0, 0}}, {"release_time", 1},
                         {"radius", 0.2}, {"drag", 3}}}}}),
      &scene);
  EXPECT_TRUE(with_every_key.ok()) << with_every_key.message();
  EXPECT_EQ(floating["properties"].size(), 5u);
  // Obstacles: a circle or a polygon, exactly one (oneOf), and every listed key parses.
  const Json& obstacle = top["obstacles"]["items"];
  std::set<std::string> obstacle_keys;
  for (const auto& item : obstacle["properties"].items()) obstacle_keys.insert(item.key());
  EXPECT_EQ(obstacle_keys, (std::set<std::string>{"center", "radius", "polygon", "height", "keys"}));
  EXPECT_EQ(obstacle["required"], Json({"center"}));
  ASSERT_EQ(obstacle["oneOf"].size(), 2u);
  EXPECT_EQ(obstacle["properties"]["polygon"]["minItems"].get<int>(), 3);
}

TEST(SceneFile, FloatsTakeTheirMeshsDefaults) {
  SceneFile scene;
  const Status status =
      parse(with({{"floats",
                   {{{"release_point", {1.5, -20.0}}},
                    {{"mesh", "leaf"}, {"release_point", {0, 3}}, {"release_time", 2.5}},
                    {{"mesh", "log"}, {"release_point", {0, 3}}, {"radius", 1.1}, {"drag", 0}}}}}),
            &scene);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(scene.floats.size(), 3u);
  EXPECT_EQ(scene.floats[0].mesh, FloatMesh::kLog);
  EXPECT_EQ(scene.floats[0].release_point, glm::vec2(1.5f, -20.0f));
  EXPECT_EQ(scene.floats[0].release_time, 0.0);
  EXPECT_EQ(scene.floats[0].radius, 0.6f);
  EXPECT_EQ(scene.floats[0].drag, 1.5f);
  EXPECT_EQ(scene.floats[1].mesh, FloatMesh::kLeaf);
  EXPECT_EQ(scene.floats[1].release_time, 2.5);
  EXPECT_EQ(scene.floats[1].radius, 0.15f);
  EXPECT_EQ(scene.floats[1].drag, 6.0f);
  EXPECT_EQ(scene.floats[2].radius, 1.1f);
  EXPECT_EQ(scene.floats[2].drag, 0.0f);
}

TEST(SceneFile, BadFloatsAreNamed) {
  expect_error(with({{"floats", {{{"mesh", "log"}}}}}),
               {"floats[0]: missing required key 'release_point'"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}, {"mesh", "boat"}}}}}),
               {"floats[0].mesh: 'boat' is not a float mesh"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}}, {{"release_point", {0, 0}}, {"radius", -1}}}}}),
               {"floats[1].radius"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}, {"radius", 60}}}}}),
               {"floats[0].radius: 60 is past the largest float, 50 metres"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}, {"release_time", -0.5}}}}}),
               {"floats[0].release_time: -0.5 must not be negative"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}, {"drag", -2}}}}}),
               {"floats[0].drag: -2 must not be negative"});
  expect_error(with({{"floats", {{{"release_point", {0, 0, 0}}}}}}), {"floats[0].release_point"});
  expect_error(with({{"floats", {{{"release_point", {0, 0}}, {"speed", 2}}}}}),
               {"floats[0]", "speed"});
}

}  // namespace
}  // namespace siviflow
