// The siviflow command end to end: bad input gets exit status 1 and a message naming the
// problem; a capture writes readable EXR frames (and PNG previews) validation-clean.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gltf_test_files.h"
#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("cli_out");
  }
  // A failed run: exit 1 and a message with `needle`.
  void expect_error_only(const RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos)
        << "expected '" << needle << "' in:\n" << r.output;
  }
  // The same, in a folder that it must leave empty.
  void expect_error(const RunResult& r, const std::string& needle) {
    expect_error_only(r, needle);
    EXPECT_TRUE(fs::is_empty(dir_)) << "a failed run left files behind";
  }
  fs::path dir_;
};

TEST_F(CliTest, UnknownCommandAndFlag) {
  expect_error(run_siviflow("frobnicate"), "unknown command 'frobnicate'");
  expect_error(run_siviflow("capture --out " + dir_.string() + " --bogus"), "unknown option '--bogus'");
  expect_error(run_siviflow("capture --frames 2"), "--out DIR is required");
  expect_error(run_siviflow("capture --frames 0 --out " + dir_.string()), "--frames");
  expect_error(run_siviflow("capture --aov nonsense --out " + dir_.string()), "unknown AOV 'nonsense'");
  expect_error(run_siviflow("info --bogus"), "unknown argument '--bogus'");
}

TEST_F(CliTest, BadSizes) {
  const std::string out = " --out " + dir_.string();
  expect_error(run_siviflow("capture --size 0x720" + out), "width and height must be at least 1");
  expect_error(run_siviflow("capture --size -5x720" + out), "invalid value '-5x720'");
  expect_error(run_siviflow("capture --size axb" + out), "invalid value 'axb'");
  expect_error(run_siviflow("capture --size 1280" + out), "expected WIDTHxHEIGHT");
  expect_error(run_siviflow("capture --size 20000x16" + out), "exceeds the device limit");
  expect_error(run_siviflow("capture --size 16000x16000" + out),
               "--size 16000x16000 (with the AOVs asked for) needs 9895 MiB of device memory");
  // The AOVs' attachments and readback buffers count: this size fits without them, not with them.
  expect_error(run_siviflow("capture --size 4000x4000 --aov normal,reflection,foam,depth" + out),
               "needs 2579 MiB of device memory (the renderers' images and staging, the colour and "
               "depth targets, the frames' readback buffers), more than the 2048 MiB budget");
}

TEST_F(CliTest, BadOutputFolder) {
  expect_error(run_siviflow("capture --out " + (dir_ / "missing").string()), "missing");
  const fs::path file = dir_.parent_path() / "plain_file";
  FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  expect_error(run_siviflow("capture --out " + file.string()), "is not a folder");
}

// A frame the writer thread cannot write (the file-size limit here, a full disk on a farm)
// stops the capture with exit 1 naming the file; no frame and no temporary is left.
TEST_F(CliTest, FailedFrameWriteStopsTheCapture) {
  const RunResult r = run_siviflow(
      "capture --frames 8 --size 160x90 --out " + dir_.string(),
      "ulimit -f 8; trap '' XFSZ;");  // 8 KiB per file: EFBIG instead of the signal
  expect_error(r, (dir_ / "frame_00000.exr").string());
  EXPECT_NE(r.output.find("File too large"), std::string::npos) << r.output;
}

TEST_F(CliTest, FailedWriteMidCaptureKeepsEarlierFramesAndWritesNoLaterOne) {
  // A folder where frame 3 would go: its write fails while later frames are being encoded.
  fs::create_directory(dir_ / frame_file_name(3));
  const RunResult r = run_siviflow("capture --frames 8 --size 96x54 --aov depth --out " + dir_.string());
  expect_error_only(r, (dir_ / frame_file_name(3)).string());
  for (uint32_t frame = 0; frame < 3; ++frame) {
    ExrImage image;
    const Status read = read_exr((dir_ / frame_file_name(frame)).string(), &image);
    EXPECT_TRUE(read.ok()) << read.message();
  }
  EXPECT_TRUE(fs::is_directory(dir_ / frame_file_name(3)));
  for (uint32_t frame = 4; frame < 8; ++frame) {
    EXPECT_FALSE(fs::exists(dir_ / frame_file_name(frame))) << "written after the failure: " << frame;
  }
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary left: " << entry.path();
  }
}

TEST_F(CliTest, UnwritableOutputFolder) {
  // As root every folder is writable, so when the tests run as root the tool runs as nobody.
  const bool root = geteuid() == 0;
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                            fs::perms::others_read | fs::perms::others_exec);
  if (!root) fs::permissions(dir_, fs::perms::owner_write, fs::perm_options::remove);
  const std::string as_nobody = root ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "";
  const RunResult r = run_siviflow("capture --frames 1 --size 32x32 --out " + dir_.string(),
                                   "HOME=/tmp " + as_nobody);
  if (!root) fs::permissions(dir_, fs::perms::owner_write, fs::perm_options::add);
  // Named either way: "is not writable", or "Permission denied" where nobody cannot even reach
  // the folder (a build tree inside a private temporary folder).
  expect_error(r, dir_.string());
  EXPECT_TRUE(r.output.find("is not writable") != std::string::npos ||
              r.output.find("Permission denied") != std::string::npos)
      << r.output;
}

TEST_F(CliTest, NoVulkanDriver) {
  const RunResult r = run_siviflow("capture --frames 1 --size 32x32 --out " + dir_.string(),
                          "VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json");
  expect_error(r, "no Vulkan driver");
  expect_error(run_siviflow("info", "VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json"),
               "no Vulkan driver");
}

TEST_F(CliTest, MissingRequiredFeatureIsNamed) {
  const RunResult r = run_siviflow("capture --frames 1 --size 32x32 --out " + dir_.string(),
                          "SIVIFLOW_HIDE_DEVICE_FEATURES=shaderClipDistance");
  expect_error(r, "shaderClipDistance");
}

TEST_F(CliTest, MissingValidationLayerIsAFailureNotASkip) {
  const RunResult r = run_siviflow("capture --frames 1 --size 32x32 --validation --out " + dir_.string(),
                          "VK_LAYER_PATH=/nonexistent-layers");
  expect_error(r, "VK_LAYER_KHRONOS_validation is required but not installed");
  const RunResult info = run_siviflow("info", "VK_LAYER_PATH=/nonexistent-layers");
  EXPECT_NE(info.output.find("VK_LAYER_KHRONOS_validation: missing"), std::string::npos) << info.output;
}

TEST_F(CliTest, InfoNamesDeviceAndLayer) {
  const RunResult r = run_siviflow("info");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("llvmpipe"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("VK_LAYER_KHRONOS_validation: present"), std::string::npos) << r.output;
}

TEST_F(CliTest, CaptureWritesExrFramesAndPreviews) {
  const RunResult r = run_siviflow("capture --frames 3 --size 96x54 --seed 9 --aov depth --preview --validation --out " +
                          dir_.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("[vulkan error]"), std::string::npos) << r.output;
  for (int frame = 0; frame < 3; ++frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05d", frame);
    const std::string exr = (dir_ / (std::string(name) + ".exr")).string();
    ASSERT_TRUE(check_exr_file(exr).ok()) << exr;
    ExrImage image;
    const Status status = read_exr(exr, &image);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(image.width, 96);
    EXPECT_EQ(image.height, 54);
    for (const char* channel : {"R", "G", "B", "A"}) {
      ASSERT_NE(image.find(channel), nullptr) << channel;
      EXPECT_EQ(image.channels.at(channel).type, ExrPixelType::kHalf);
    }
    ASSERT_NE(image.find("depth.Z"), nullptr);
    EXPECT_EQ(image.channels.at("depth.Z").type, ExrPixelType::kFloat);
    // The beauty's part, then one per layer, each compressed as suits it.
    EXPECT_EQ(image.parts, (std::vector<std::string>{"rgba", "depth"}));
    EXPECT_EQ(image.channels.at("R").compression, "piz");
    EXPECT_EQ(image.channels.at("depth.Z").compression, "rle");
    EXPECT_EQ(image.metadata.frame, frame);
    EXPECT_EQ(image.metadata.seed, 9);
    EXPECT_EQ(image.metadata.scene, "default");
    EXPECT_NEAR(image.metadata.time_seconds, frame / 30.0f, 1e-6f);
    // Depth: the sky is infinitely far, the ground in front of the camera a few metres away.
    const std::vector<float>& depth = *image.find("depth.Z");
    EXPECT_TRUE(std::isinf(depth[48]));
    const float ground = depth[53 * 96 + 48];
    EXPECT_GT(ground, 1.0f);
    EXPECT_LT(ground, 50.0f);
    EXPECT_TRUE(fs::exists(dir_ / (std::string(name) + ".png")));
  }
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary left: " << entry.path();
    ++files;
  }
  EXPECT_EQ(files, 6u);
}


TEST_F(CliTest, FlowAndParticleAovs) {
  const RunResult r = run_siviflow("capture --frames 2 --size 160x90 --aov flow,particles --validation --out " +
                                   dir_.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExrImage image;
  ASSERT_TRUE(read_exr((dir_ / "frame_00001.exr").string(), &image).ok());
  for (const char* channel : {"flow.X", "flow.Y", "flow.Z", "water.A"}) {
    ASSERT_NE(image.find(channel), nullptr) << channel;
    EXPECT_EQ(image.channels.at(channel).type, ExrPixelType::kHalf) << channel;
  }
  ASSERT_NE(image.find("particle.I"), nullptr);
  EXPECT_EQ(image.channels.at("particle.I").type, ExrPixelType::kUint);
  EXPECT_EQ(image.find("depth.Z"), nullptr) << "only the AOVs asked for";
  // The CSV: its header, and ids that are exactly those the particle.I layer shows.
  const std::string csv = read_file(dir_ / "frame_00001.particles.csv");
  ASSERT_EQ(csv.rfind("id,state,sx,sy,wx,wy,wz,fx,fy,fz,speed,depth,slope,fade\n", 0), 0u) << csv.substr(0, 200);
  std::set<long> csv_ids;
  size_t start = csv.find('\n') + 1;
  while (start < csv.size()) {
    const size_t end = csv.find('\n', start);
    const std::string line = csv.substr(start, end - start);
    csv_ids.insert(std::stol(line));
    const size_t state = line.find(',') + 1;
    const std::string state_name = line.substr(state, line.find(',', state) - state);
    EXPECT_TRUE(state_name == "active" || state_name == "fading_in" || state_name == "fading_out") << line;
    start = end + 1;
  }
  ASSERT_GT(csv_ids.size(), 10u);
  const std::vector<uint32_t>& ids = image.channels.at("particle.I").ids;
  const std::vector<float>& mask = *image.find("water.A");
  size_t water = 0;
  size_t covered = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (mask[i] == 0.0f) {
      EXPECT_EQ(ids[i], 0u) << "pixel " << i << " is not water";
    } else {
      ++water;
      // Water pixels at the very bank may miss the river in the particles' ray cast.
      if (ids[i] == 0u) continue;
      ++covered;
      EXPECT_TRUE(csv_ids.count(static_cast<long>(ids[i])) == 1) << "pixel " << i << " id " << ids[i];
      EXPECT_NE(image.find("flow.Z")->at(i), 0.0f) << "a particle with no flow at pixel " << i;
    }
    if (HasFailure()) break;
  }
  EXPECT_GT(water, ids.size() / 20);
  EXPECT_GE(covered * 100, water * 97) << covered << " of " << water << " water pixels have a particle";
}

TEST_F(CliTest, CaptureOfAProceduralSceneFile) {
  const fs::path scene = dir_.parent_path() / "procedural_scene.json";
  FILE* f = std::fopen(scene.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"({"version":1,"river":{"procedural":{"seed":11,"width":9.0}},"flow":{"discharge":15.0},
    "obstacles":[{"center":[0,0.3,10],"radius":1.6}],
    "camera":{"fov_y_deg":60,"keys":[{"t":0,"position":[0,7,-20],"target":[0,0,15]},
                                    {"t":10,"position":[5,9,0],"target":[0,0,30]}]},
    "render":{"size":[80,48],"fps":24,"seed":3}})", f);
  std::fclose(f);
  const RunResult r = run_siviflow("capture " + scene.string() + " --range 2:3 --validation --out " + dir_.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExrImage image;
  ASSERT_TRUE(read_exr((dir_ / "frame_00002.exr").string(), &image).ok());
  EXPECT_EQ(image.width, 80) << "the scene's render size";
  EXPECT_EQ(image.height, 48);
  EXPECT_EQ(image.metadata.seed, 3);
  EXPECT_NEAR(image.metadata.time_seconds, 2.0f / 24.0f, 1e-6f) << "the scene's fps";
  EXPECT_EQ(image.metadata.scene, scene.string());
  // A flag wins over the scene's settings; frame 2 of the scene's size is another capture, and
  // the folder is refused unless --force.
  const std::string smaller = "capture " + scene.string() + " --size 32x16 --out " + dir_.string();
  expect_error_only(run_siviflow(smaller), "frame_00002.exr, outside the range, differs from this "
                                           "capture (in brackets): size 80x48 (32x16)");
  EXPECT_FALSE(fs::exists(dir_ / "frame_00000.exr"));
  ASSERT_EQ(run_siviflow(smaller + " --force").exit_code, 0);
  ASSERT_TRUE(read_exr((dir_ / "frame_00000.exr").string(), &image).ok());
  EXPECT_EQ(image.width, 32);
}

// Finite values whose products are not (issue 28): refused by name before anything is built,
// never a crash. The first is the crash seeded mutants found: one element of a glTF node's matrix
// at 3.4e38 faulted the occluders' hierarchy.
TEST_F(CliTest, GeometryBeyondTheWorldLimitIsRefusedByName) {
  const fs::path box = dir_.parent_path() / "huge_node_box.gltf";
  write_box_gltf(box, {1.0f, 1.0f, 1.0f});
  std::string text = read_file(box);
  const std::string node = R"("nodes":[{"mesh":0}])";
  ASSERT_NE(text.find(node), std::string::npos);
  text.replace(text.find(node), node.size(),
               R"("nodes":[{"mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,3.4e38,0,0,1]}])");
  write_text(box, text);
  const fs::path plain_box = dir_.parent_path() / "plain_box.gltf";
  write_box_gltf(plain_box, {1.0f, 1.0f, 1.0f});
  const auto scene = [&](const std::string& name, const std::string& objects) {
    const fs::path path = dir_.parent_path() / (name + ".json");
    write_text(path, R"({"version":1,"river":{"procedural":{}},)" + objects + "}");
    return "capture " + path.string() + " --size 64x36 --out " + dir_.string();
  };
  const std::string huge_node = R"("objects":[{"gltf":"huge_node_box.gltf","translation":[20,0,0]}])";
  expect_error(run_siviflow(scene("huge_node", huge_node)),
               "huge_node.json: objects[0]: " + box.string() + ": mesh 'Box' primitive 0 (node 0): "
               "vertex 0 after the node transforms (3.4e+38, -1, -1) lies beyond the world limit "
               "of ±1e+06 m");
  expect_error(run_siviflow(scene("huge_scale",
                                  R"("objects":[{"gltf":"plain_box.gltf","scale":[1e30,1,1]}])")),
               "huge_scale.json: objects[0]: " + plain_box.string() +
                   ": vertex 0 placed by the object's translation, rotation and scale (-1e+30, -1, "
                   "-1) lies beyond the world limit");
  expect_error(run_siviflow(scene("huge_obstacle_object",
                                  R"("objects":[{"gltf":"plain_box.gltf","scale":[1e30,1,1],"obstacle":true}])")),
               "vertex 0 placed by the object's translation, rotation and scale (-1e+30, -1, -1) "
               "lies beyond the world limit");
  expect_error(run_siviflow(scene("far_obstacle", R"("obstacles":[{"center":[3e6,0,0],"radius":1}])")),
               "obstacles[0]: obstacle 0: its centre (3e+06, 0, 0) lies beyond the world limit");
}

TEST_F(CliTest, CaptureRefusesBadSceneFiles) {
  const fs::path gltf_scene = dir_.parent_path() / "gltf_scene.json";
  FILE* f = std::fopen(gltf_scene.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"({"version":1,"river":{"gltf":"no_such_river.glb"}})", f);
  std::fclose(f);
  expect_error(run_siviflow("capture " + gltf_scene.string() + " --out " + dir_.string()),
               "no_such_river.glb");
  const fs::path bad = dir_.parent_path() / "bad_scene.json";
  f = std::fopen(bad.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"({"version":1,"river":{"procedural":{}},"rendr":{}})", f);
  std::fclose(f);
  expect_error(run_siviflow("capture " + bad.string() + " --out " + dir_.string()), "rendr");
  expect_error(run_siviflow("capture " + bad.string() + " " + bad.string() + " --out " + dir_.string()),
               "one scene file only");
}

TEST_F(CliTest, BenchReportsEveryPassAsJson) {
  const RunResult r = run_siviflow("bench --size 96x54 --frames 5 --warmup 1 --runs 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json report = nlohmann::json::parse(r.output, nullptr, false);
  ASSERT_FALSE(report.is_discarded()) << r.output;
  const double frame = report.at("frame_ms").get<double>();
  const double floor = report.at("floor_ms").get<double>();
  EXPECT_GT(floor, 0.0);
  EXPECT_LT(report.at("frame_without_floor_ms").get<double>(), frame);
  // The water's own passes, their span, and the world's pass.
  for (const char* pass : {"upload", "reflection", "flow", "water", "world"}) {
    ASSERT_TRUE(report.at("passes").contains(pass)) << pass << "\n" << r.output;
    const nlohmann::json& stats = report["passes"][pass];
    EXPECT_LE(stats.at("min_ms").get<double>(), stats.at("median_ms").get<double>()) << pass;
    EXPECT_LE(stats.at("median_ms").get<double>(), stats.at("max_ms").get<double>()) << pass;
  }
  EXPECT_FALSE(report.at("passes").contains("flow floor")) << "the floor is reported apart";
  // The passes run one after the other: their medians add up to no more than the frame.
  double passes = floor;
  for (const char* pass : {"upload", "reflection", "refraction copy", "flow tiles",
                           "flow material", "world"}) {
    passes += report.at("passes").at(pass).at("median_ms").get<double>();
  }
  EXPECT_LE(passes, frame) << r.output;
  EXPECT_EQ(report.at("runs").get<int>(), 2);
  EXPECT_EQ(report.at("run_frame_ms").size(), 2u);
  EXPECT_GE(report.at("run_spread").get<double>(), 0.0);
  for (const char* drawn : {"world", "world_reflection", "water"}) {
    EXPECT_GT(report.at("triangles").at(drawn).get<int>(), 0) << drawn;
  }
  EXPECT_GE(report.at("cpu").at("update_ms").get<double>(), 0.0);
  EXPECT_GT(report.at("create_ms").get<double>(), 0.0);
  EXPECT_FALSE(report.contains("second_view"));
  // A second view of the river: its own creation, update and water span.
  const RunResult two = run_siviflow("bench --size 96x54 --frames 2 --warmup 1 --json --second-view");
  ASSERT_EQ(two.exit_code, 0) << two.output;
  const nlohmann::json second = nlohmann::json::parse(two.output, nullptr, false);
  ASSERT_FALSE(second.is_discarded()) << two.output;
  for (const char* key : {"create_ms", "update_ms", "water_ms"}) {
    EXPECT_GT(second.at("second_view").at(key).get<double>(), 0.0) << key;
  }
  expect_error(run_siviflow("bench --frames 0"), "--frames");
  expect_error(run_siviflow("bench --runs 0"), "--runs");
  // A scene file, at its own render size.
  const fs::path scene = dir_.parent_path() / "bench_scene.json";
  FILE* f = std::fopen(scene.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(R"({"version":1,"river":{"procedural":{"seed":5}},"render":{"size":[64,36]}})", f);
  std::fclose(f);
  const RunResult from_scene = run_siviflow("bench " + scene.string() + " --frames 2 --warmup 0 --json");
  ASSERT_EQ(from_scene.exit_code, 0) << from_scene.output;
  EXPECT_FALSE(nlohmann::json::parse(from_scene.output, nullptr, false).is_discarded()) << from_scene.output;
  expect_error(run_siviflow("bench " + (dir_ / "missing.json").string()), "missing.json");
}

TEST_F(CliTest, RangeShardsEqualTheFullRun) {
  const fs::path full = dir_ / "full";
  const fs::path shard = dir_ / "shard";
  fs::create_directories(full);
  fs::create_directories(shard);
  ASSERT_EQ(run_siviflow("capture --frames 4 --size 64x36 --aov particles --out " + full.string()).exit_code, 0);
  ASSERT_EQ(run_siviflow("capture --range 2:4 --size 64x36 --aov particles --out " + shard.string()).exit_code, 0);
  EXPECT_FALSE(fs::exists(shard / "frame_00000.exr"));
  for (const char* name : {"frame_00002.exr", "frame_00003.exr"}) {
    ExrImage a;
    ExrImage b;
    ASSERT_TRUE(read_exr((full / name).string(), &a).ok());
    ASSERT_TRUE(read_exr((shard / name).string(), &b).ok());
    for (const char* channel : {"R", "G", "B", "A", "particle.I"}) {
      EXPECT_EQ(*a.find(channel), *b.find(channel)) << name << " " << channel;
    }
  }
  // The particles carry state across frames: the shard replays the simulation up to frame 2.
  for (const char* name : {"frame_00002.particles.csv", "frame_00003.particles.csv"}) {
    const std::string a = read_file(full / name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_EQ(a, read_file(shard / name)) << name;
  }
}

// --resume renders only what is missing or cannot be read whole, bit-identical to a full run,
// and leaves complete frames untouched; a complete frame of another capture is refused, naming
// it, with nothing overwritten, unless --force.
TEST_F(CliTest, ResumeRendersOnlyMissingOrIncompleteFrames) {
  const fs::path full = dir_ / "full";
  const fs::path resumed = dir_ / "resumed";
  fs::create_directories(full);
  const std::string args = "capture --range 0:6 --size 64x36 --aov depth --out ";
  ASSERT_EQ(run_siviflow(args + full.string()).exit_code, 0);
  fs::copy(full, resumed);
  fs::remove(resumed / "frame_00002.exr");
  const std::string frame4 = read_file(resumed / "frame_00004.exr");
  {  // cut short, as a killed copy leaves it
    std::ofstream cut(resumed / "frame_00004.exr", std::ios::binary | std::ios::trunc);
    cut << frame4.substr(0, frame4.size() / 2);
  }
  const auto old_time = fs::file_time_type::clock::now() - std::chrono::hours(24);
  for (const char* kept : {"frame_00000.exr", "frame_00001.exr", "frame_00003.exr",
                           "frame_00005.exr"}) {
    fs::last_write_time(resumed / kept, old_time);
  }

  RunResult run = run_siviflow(args + resumed.string() + " --resume");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("wrote 2 of frames 0..5"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("4 were complete"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("captured 2/2 frames, "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(" frames/s, 0 s left"), std::string::npos) << run.output;
  for (uint32_t frame = 0; frame < 6; ++frame) {
    const std::string name = frame_file_name(frame);
    EXPECT_EQ(read_file(full / name), read_file(resumed / name)) << name;
    const bool kept = frame != 2 && frame != 4;
    EXPECT_EQ(fs::last_write_time(resumed / name) == old_time, kept) << name;
  }

  // Another size, or other AOVs: refused at the first frame, nothing overwritten.
  run = run_siviflow("capture --range 0:6 --size 64x32 --aov depth --resume --out " +
                     resumed.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("frame_00000.exr differs from this capture (in brackets): size "
                            "64x36 (64x32)"),
            std::string::npos)
      << run.output;
  run = run_siviflow("capture --range 3:6 --size 64x36 --resume --out " + resumed.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("frame_00003.exr differs from this capture (in brackets): AOVs "
                            "depth (none)"),
            std::string::npos)
      << run.output;
  // Without --resume too: another capture's frames are not overwritten.
  expect_error_only(run_siviflow(args + resumed.string() + " --seed 5"),
                    "frame_00000.exr differs from this capture (in brackets): seed 1 (5); nothing "
                    "was overwritten (--force re-renders such frames)");
  for (const char* kept : {"frame_00000.exr", "frame_00003.exr"}) {
    EXPECT_EQ(fs::last_write_time(resumed / kept), old_time) << kept;
  }

  // --force re-renders them, with --resume or without.
  run = run_siviflow(args + resumed.string() + " --seed 5 --resume --force");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("wrote 6 of frames 0..5"), std::string::npos) << run.output;
  ExrImage image;
  ASSERT_TRUE(read_exr((resumed / "frame_00003.exr").string(), &image).ok());
  EXPECT_EQ(image.metadata.seed, 5);
  run = run_siviflow("capture --range 0:2 --size 64x36 --aov depth --seed 6 --force --out " +
                     resumed.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_TRUE(read_exr((resumed / "frame_00001.exr").string(), &image).ok());
  EXPECT_EQ(image.metadata.seed, 6);
}

// Frames record what made them, and a resume or `verify` compares all of it: a path spelled
// otherwise is the same capture, an edited scene or another --fps another one, named by its first
// frame and the difference; a plain capture re-renders its own frames and refuses another's.
TEST_F(CliTest, FramesKnowWhatMadeThem) {
  const fs::path scene = dir_ / "scene.json";
  const std::string text = R"({"version": 1, "river": {"procedural": {"length": 120}},
    "render": {"size": [48, 27], "seed": 3}})";
  std::ofstream(scene) << text;
  const fs::path out = dir_ / "frames";
  fs::create_directories(out);
  const std::string in_dir = "cd " + dir_.string() + " && " + SIVIFLOW_BINARY_DIR "/tools/siviflow ";
  RunResult run = run_shell(in_dir + "capture scene.json --frames 2 --out frames");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ExrImage image;
  ASSERT_TRUE(read_exr((out / "frame_00001.exr").string(), &image).ok());
  const std::string digest = image.metadata.scene_digest;
  EXPECT_EQ(digest.rfind("sha256:", 0), 0u) << digest;
  EXPECT_EQ(digest.size(), 7u + 64u);
  EXPECT_EQ(image.metadata.scene, "scene.json") << "the path as given, for people";
  EXPECT_EQ(image.metadata.fps, 30.0f);
  EXPECT_EQ(image.metadata.aovs, "");
  EXPECT_EQ(image.metadata.seed, 3);
  EXPECT_EQ(image.metadata.software_version + "\n", run_siviflow("--version").output);

  // The same scene by another spelling of its path: the same capture.
  run = run_shell(in_dir + "capture ./scene.json --range 0:3 --resume --out frames");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("wrote 1 of frames 0..2"), std::string::npos) << run.output;
  run = run_siviflow("capture " + scene.string() + " --range 0:3 --resume --out " + out.string());
  EXPECT_NE(run.output.find("wrote 0 of frames 0..2"), std::string::npos) << run.output;
  run = run_siviflow("verify " + out.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;

  // A plain capture of this capture renders its frames again.
  const auto old_time = fs::file_time_type::clock::now() - std::chrono::hours(24);
  fs::last_write_time(out / "frame_00000.exr", old_time);
  ASSERT_EQ(run_siviflow("capture " + scene.string() + " --out " + out.string()).exit_code, 0);
  EXPECT_NE(fs::last_write_time(out / "frame_00000.exr"), old_time);
  fs::last_write_time(out / "frame_00000.exr", old_time);

  // An edited scene at the same path: another capture, refused by its first frame.
  std::ofstream(scene) << R"({"version": 1, "river": {"procedural": {"length": 120}},
    "flow": {"discharge": 12}, "render": {"size": [48, 27], "seed": 3}})";
  expect_error_only(run_siviflow("capture " + scene.string() + " --range 0:4 --resume --out " +
                                 out.string()),
                    out.string() + "/frame_00000.exr differs from this capture (in brackets): "
                                   "scene content differs, digest sha256:");
  expect_error_only(run_siviflow("capture " + scene.string() + " --range 0:1 --out " +
                                 out.string()),
                    "frame_00000.exr differs from this capture (in brackets): scene content "
                    "differs, digest " + digest.substr(0, 19) + "... (sha256:");
  std::ofstream(scene) << text;

  // Another frame rate: another capture; forced into the folder, verify names its frame.
  expect_error_only(run_siviflow("capture " + scene.string() + " --range 0:4 --fps 24 --resume "
                                 "--out " + out.string()),
                    "frame_00000.exr differs from this capture (in brackets): fps 30 (24)");
  EXPECT_EQ(fs::last_write_time(out / "frame_00000.exr"), old_time) << "nothing overwritten";
  run = run_siviflow("capture " + scene.string() + " --range 3:4 --fps 24 --force --out " +
                     out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_TRUE(read_exr((out / "frame_00003.exr").string(), &image).ok());
  EXPECT_EQ(image.metadata.fps, 24.0f);
  EXPECT_NEAR(image.metadata.time_seconds, 3.0f / 24.0f, 1e-6f) << "--fps reaches the frame's time";
  run = run_siviflow("verify " + out.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("frame_00003.exr: differs from frame_00000.exr (in brackets): fps 24 "
                            "(30)\n"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("3 of 4 complete"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace siviflow::testing
