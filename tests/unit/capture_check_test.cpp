// What `siviflow capture` checks before it asks for a device, the same for --dry-run and the real
// run: every file the scene loads, the AOVs against its rivers, the memory budget, and the frames
// already in the output folder (kept by --resume when they are this capture's, refused by name
// when they are another's, unless --force). And `siviflow --version`, which frames record.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "gltf_test_files.h"
#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"
#include "siviflow/scene_digest.h"
#include "siviflow/version.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

class CaptureCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("capture_check");
    out_ = dir_ / "out";
    fs::create_directories(out_);
  }
  // Runs capture with `args` into out_, as a dry run and, where `real` too, for real: both
  // exit 1 with `needle` in the message, and leave the output folder as it was.
  void expect_refused(const std::string& args, const std::string& needle, bool real = true) {
    const std::vector<fs::path> before = files(out_);
    for (const std::string& mode : real ? std::vector<std::string>{" --dry-run", ""}
                                        : std::vector<std::string>{" --dry-run"}) {
      const RunResult run = run_siviflow("capture " + args + " --out " + out_.string() + mode);
      EXPECT_EQ(run.exit_code, 1) << args << mode << "\n" << run.output;
      EXPECT_NE(run.output.find(needle), std::string::npos)
          << args << mode << ": expected '" << needle << "' in:\n"
          << run.output;
    }
    EXPECT_EQ(files(out_), before);
  }
  RunResult dry_run(const std::string& args) {
    return run_siviflow("capture " + args + " --out " + out_.string() + " --dry-run");
  }
  static std::vector<fs::path> files(const fs::path& dir) {
    std::vector<fs::path> names;
    for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path());
    std::sort(names.begin(), names.end());
    return names;
  }
  // A beauty-only frame of the default scene at 16x8, as `capture --size 16x8` records it;
  // `edit` changes what it records.
  template <typename Edit>
  void write_frame(uint32_t frame, Edit&& edit) {
    std::vector<float> rgba(16 * 8 * 4, 0.5f);
    ExrFrame exr;
    exr.width = 16;
    exr.height = 8;
    exr.rgba = rgba.data();
    exr.metadata.scene = "default";
    exr.metadata.frame = static_cast<int>(frame);
    exr.metadata.time_seconds = frame / 30.0f;
    exr.metadata.seed = 1;
    exr.metadata.software_version = version_string();
    ASSERT_TRUE(scene_content_digest(nullptr, &exr.metadata.scene_digest).ok());
    exr.metadata.fps = 30.0f;
    edit(exr);
    ASSERT_TRUE(write_exr((out_ / frame_file_name(frame)).string(), exr).ok());
  }
  void write_frame(uint32_t frame) {
    write_frame(frame, [](ExrFrame&) {});
  }
  fs::path dir_;
  fs::path out_;
};

TEST_F(CaptureCheckTest, VersionIsWhatFramesRecord) {
  for (const char* command : {"--version", "version"}) {
    const RunResult run = run_siviflow(command);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(run.output, std::string(version_string()) + "\n");
  }
  const RunResult extra = run_siviflow("--version now");
  EXPECT_EQ(extra.exit_code, 1);
  EXPECT_NE(extra.output.find("unexpected argument 'now'"), std::string::npos) << extra.output;
}

TEST_F(CaptureCheckTest, EveryFileTheSceneLoadsIsChecked) {
  write_channel_gltf(dir_ / "river.gltf", 12, 5, 8.0f, 2.0f);
  write_textured_box_gltf(dir_ / "box.gltf", glm::vec3(1.0f), "box.png", glm::vec4(1.0f));
  // A PNG whose header reads (4x4) but whose pixels do not decode.
  write_text(dir_ / "box.png",
             std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x04\0\0\0\x04\x08\x02\0\0\0", 29) +
                 "CRC and no pixels");
  const std::string scene = (dir_ / "scene.json").string();
  write_text(scene, R"({"version": 1, "river": {"gltf": "missing_river.gltf"}})");
  expect_refused(scene, "missing_river.gltf");
  write_text(scene, R"({"version": 1, "river": {"gltf": "river.gltf", "mesh": "Nile"}})");
  expect_refused(scene, "has no mesh named 'Nile'");
  write_text(scene, R"({"version": 1, "river": {"gltf": "river.gltf"},
                        "objects": [{"gltf": "missing_duck.glb"}]})");
  expect_refused(scene, "objects[0]: ");
  expect_refused(scene, "missing_duck.glb");
  // The world decodes the objects' textures before it draws: so does the check.
  write_text(scene, R"({"version": 1, "river": {"gltf": "river.gltf"},
                        "objects": [{"gltf": "box.gltf", "translation": [20, 0, 0]}]})");
  expect_refused(scene, "box.gltf: image 0: PNG");
  // A river the renderer cannot build a surface from: a strip of one section has no quads.
  write_channel_gltf(dir_ / "river.gltf", 1, 5, 8.0f, 2.0f);
  write_text(scene, R"({"version": 1, "river": {"gltf": "river.gltf"}})");
  expect_refused(scene, "river.gltf");

  write_channel_gltf(dir_ / "river.gltf", 12, 5, 8.0f, 2.0f);
  const RunResult run = dry_run(scene);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("would render frames 0..0 of " + scene), std::string::npos)
      << run.output;
}

TEST_F(CaptureCheckTest, AovsOfOneRiverAndTheBudget) {
  write_channel_gltf(dir_ / "a.gltf", 12, 5, 8.0f, 2.0f);
  write_channel_gltf(dir_ / "b.gltf", 12, 5, 8.0f, 2.0f, 0.0f, 40.0f);
  const std::string scene = (dir_ / "two.json").string();
  write_text(scene, R"({"version": 1, "rivers": [{"gltf": "a.gltf"}, {"gltf": "b.gltf"}]})");
  for (const char* aov : {"flow", "particles", "normal", "reflection", "foam"}) {
    expect_refused(scene + " --aov depth," + aov,
                   "--aov flow, particles, normal, reflection and foam are of one river; the "
                   "scene has 2 (depth works with any number)");
  }
  const RunResult depth = dry_run(scene + " --aov depth");
  EXPECT_EQ(depth.exit_code, 0) << depth.output;
  expect_refused("--size 16384x16384 --aov depth,flow", "MiB budget");
  const std::string absent = (dir_ / "absent").string();
  for (const char* mode : {" --dry-run", ""}) {
    const RunResult run = run_siviflow("capture --size 16x8 --out " + absent + mode);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("output folder '" + absent + "': No such file or directory"),
              std::string::npos)
        << run.output;
  }
}

TEST_F(CaptureCheckTest, FramesOfThisCaptureAreKeptOrRenderedAgain) {
  write_frame(0);
  write_frame(1);
  RunResult run = dry_run("--size 16x8 --range 0:3 --resume");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("would render frames 0..2 of the default scene at 16x8 to " +
                            out_.string() + "/frame_NNNNN.exr; 2 are complete and kept\n"),
            std::string::npos)
      << run.output;
  // Without --resume this capture's frames are rendered again: no refusal.
  run = dry_run("--size 16x8 --range 0:3");
  EXPECT_EQ(run.exit_code, 0) << run.output;
}

TEST_F(CaptureCheckTest, FramesOfAnotherCaptureAreRefusedByName) {
  write_frame(0);
  write_frame(1, [](ExrFrame& exr) { exr.metadata.seed = 4; });
  const std::string file1 = out_.string() + "/frame_00001.exr";
  for (const char* resume : {"", " --resume"}) {
    expect_refused(std::string("--size 16x8 --range 0:3") + resume,
                   file1 +
                       " differs from this capture (in brackets): seed 4 (1); nothing was "
                       "overwritten (--force re-renders such frames)");
  }
  // Beside the range: the folder's first complete frame stands for it.
  expect_refused("--size 16x8 --range 5:6 --seed 4",
                 out_.string() +
                     "/frame_00000.exr, outside the range, differs from this capture "
                     "(in brackets): seed 1 (4): the folder holds another capture "
                     "(--force renders beside it)");
  for (const char* args : {"--size 16x8 --range 0:3 --force", "--size 16x8 --range 5:6 --force",
                           "--size 16x8 --range 0:3 --resume --force"}) {
    const RunResult run = dry_run(args);
    EXPECT_EQ(run.exit_code, 0) << args << "\n" << run.output;
  }
  // Another fps, another scene, a frame of the layout before digests.
  write_frame(1);
  expect_refused("--size 16x8 --range 0:2 --fps 24",
                 "frame_00000.exr differs from this capture "
                 "(in brackets): fps 30 (24); nothing");
  const std::string scene = (dir_ / "scene.json").string();
  write_text(scene, R"({"version": 1, "river": {"procedural": {}}, "render": {"size": [16, 8]}})");
  expect_refused(scene + " --range 0:2",
                 "frame_00000.exr differs from this capture (in "
                 "brackets): scene content differs, digest sha256:");
  write_frame(0, [](ExrFrame& exr) {
    exr.metadata.scene_digest.clear();
    exr.metadata.fps = 0.0f;
  });
  expect_refused("--size 16x8 --range 0:2 --resume",
                 "frame_00000.exr differs from this capture (in brackets): an earlier layout "
                 "without siviflow/scene_digest (one with it)");
}

}  // namespace
}  // namespace siviflow::testing
