// Checking a folder of captured frames (check_frame_folder, and `siviflow verify` over it):
// present, read whole, their own frame number, and captured alike; each bad frame named with its
// problem, and a folder that cannot be checked refused with a message.
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "run_command.h"
#include "siviflow/frame_folder.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;
using testing::fresh_test_dir;
using testing::run_siviflow;

constexpr const char* kDigest =
    "sha256:0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";

struct FrameSpec {
  int width = 8;
  int height = 4;
  int seed = 1;
  std::string scene = "default";
  std::string version = "0.1.0";
  bool depth = false;
  bool half_depth = false;  // depth.Z written as HALF: the layout of another build
  int frame_attribute = -1;  // -1: the file's own frame
  std::string digest = kDigest;  // "": a frame of the layout before digests
  float fps = 30.0f;
  std::optional<std::string> aovs;  // absent: "depth" with depth, else ""
};

void write_frame(const fs::path& dir, uint32_t frame, const FrameSpec& spec = {}) {
  const size_t pixels = size_t(spec.width) * spec.height;
  std::vector<float> rgba(pixels * 4, 0.25f);
  std::vector<float> depth(pixels, 3.0f);
  std::vector<uint16_t> depth_halves(pixels, 0x4200);  // 3.0
  ExrFrame exr;
  exr.width = spec.width;
  exr.height = spec.height;
  exr.rgba = rgba.data();
  if (spec.depth) exr.layers.push_back({"depth", ExrCompression::kZip, {{"depth.Z", depth.data()}}});
  if (spec.half_depth) {
    exr.layers.push_back(
        {"depth", ExrCompression::kZip, {{.name = "depth.Z", .halves = depth_halves.data()}}});
  }
  exr.metadata.scene = spec.scene;
  exr.metadata.frame = spec.frame_attribute >= 0 ? spec.frame_attribute : static_cast<int>(frame);
  exr.metadata.seed = spec.seed;
  exr.metadata.software_version = spec.version;
  exr.metadata.scene_digest = spec.digest;
  exr.metadata.fps = spec.digest.empty() ? 0.0f : spec.fps;  // the earlier layout had neither
  exr.metadata.aovs = spec.aovs ? *spec.aovs : spec.depth || spec.half_depth ? "depth" : "";
  const Status status = write_exr((dir / frame_file_name(frame)).string(), exr);
  ASSERT_TRUE(status.ok()) << status.message();
}

std::string problem_of(const FrameFolderReport& report, uint32_t frame) {
  for (const FrameProblem& p : report.problems) {
    if (p.frame == frame) return p.problem;
  }
  return "";
}

TEST(FrameFolder, CompleteFolderHasNoProblems) {
  const fs::path dir = fresh_test_dir("frame_folder");
  for (uint32_t frame = 3; frame < 8; ++frame) write_frame(dir, frame);
  std::ofstream(dir / "frame_00003.png") << "previews and other files are not frames";
  FrameFolderReport report;
  ASSERT_TRUE(check_frame_folder(dir.string(), 0, 0, &report).ok());
  EXPECT_EQ(report.first, 3u);
  EXPECT_EQ(report.end, 8u);
  EXPECT_EQ(report.complete, 5u);
  EXPECT_EQ(report.reference, "frame_00003.exr");
  EXPECT_TRUE(report.problems.empty());
}

TEST(FrameFolder, NamesEveryBadFrameAndItsProblem) {
  const fs::path dir = fresh_test_dir("frame_folder");
  write_frame(dir, 0, {.depth = true});
  write_frame(dir, 1, {.depth = true});
  // 2: missing.
  write_frame(dir, 3, {.depth = true});
  {  // 3: cut short, as a killed copy leaves it.
    std::ifstream in(dir / "frame_00003.exr", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / "frame_00003.exr", std::ios::binary | std::ios::trunc)
        << bytes.substr(0, bytes.size() - 40);
  }
  std::ofstream(dir / "frame_00004.exr") << "not an EXR file at all";
  write_frame(dir, 5, {.seed = 7, .depth = true});
  write_frame(dir, 6, {.width = 16, .scene = "other.json", .depth = true});
  write_frame(dir, 7);  // no depth.Z
  write_frame(dir, 8, {.version = "0.2.0", .depth = true});
  write_frame(dir, 9, {.depth = true, .frame_attribute = 2});
  write_frame(dir, 10, {.depth = true, .fps = 24.0f});
  write_frame(dir, 11, {.depth = true, .digest = "sha256:fedcba98765432100123"});
  write_frame(dir, 12, {.aovs = "depth"});  // the AOVs' channels under other names
  write_frame(dir, 13, {.seed = 2, .depth = true, .digest = ""});
  write_frame(dir, 14, {.half_depth = true});  // the same names, another pixel type

  FrameFolderReport report;
  ASSERT_TRUE(check_frame_folder(dir.string(), 0, 15, &report).ok());
  EXPECT_EQ(report.complete, 2u);
  ASSERT_EQ(report.problems.size(), 13u);
  EXPECT_EQ(report.problems[0].file, "frame_00002.exr");
  EXPECT_EQ(problem_of(report, 2), "missing");
  EXPECT_NE(problem_of(report, 3).find("cannot be read whole"), std::string::npos)
      << problem_of(report, 3);
  EXPECT_NE(problem_of(report, 4).find("not an EXR file"), std::string::npos)
      << problem_of(report, 4);
  EXPECT_EQ(problem_of(report, 5), "differs from frame_00000.exr (in brackets): seed 7 (1)");
  // The scene's path is for people: its content is compared.
  EXPECT_EQ(problem_of(report, 6), "differs from frame_00000.exr (in brackets): size 16x4 (8x4)");
  EXPECT_EQ(problem_of(report, 7), "differs from frame_00000.exr (in brackets): AOVs none (depth)");
  EXPECT_EQ(problem_of(report, 8),
            "differs from frame_00000.exr (in brackets): software version '0.2.0' ('0.1.0')");
  EXPECT_EQ(problem_of(report, 9), "holds frame 2");
  EXPECT_EQ(problem_of(report, 10), "differs from frame_00000.exr (in brackets): fps 24 (30)");
  EXPECT_EQ(problem_of(report, 11),
            "differs from frame_00000.exr (in brackets): scene content differs, digest "
            "sha256:fedcba987654... (sha256:0123456789ab...)");
  EXPECT_EQ(problem_of(report, 12),
            "differs from frame_00000.exr (in brackets): channels A:half,B:half,G:half,R:half "
            "(A:half,B:half,G:half,R:half,depth.Z:float)");
  // A frame of the layout before digests is another capture, whatever else it shares.
  EXPECT_EQ(problem_of(report, 13),
            "differs from frame_00000.exr (in brackets): an earlier layout without "
            "siviflow/scene_digest (one with it)");
  EXPECT_EQ(problem_of(report, 14),
            "differs from frame_00000.exr (in brackets): channels A:half,B:half,G:half,R:half,"
            "depth.Z:half (A:half,B:half,G:half,R:half,depth.Z:float)");
}

TEST(FrameFolder, WhatACaptureIsMadeOfNamesTheFrameOfAnotherOne) {
  const fs::path dir = fresh_test_dir("frame_folder");
  // The same content reached by two spellings of the scene's path: one capture.
  write_frame(dir, 0, {.scene = "./scene.json"});
  write_frame(dir, 1, {.scene = "scene.json"});
  FrameFolderReport report;
  ASSERT_TRUE(check_frame_folder(dir.string(), 0, 0, &report).ok());
  EXPECT_EQ(report.complete, 2u);
  EXPECT_TRUE(report.problems.empty());

  FrameExpectation capture;
  capture.scene_digest = kDigest;
  capture.fps = 30.0f;
  capture.seed = 1;
  capture.width = 8;
  capture.height = 4;
  capture.channels = {"A:half", "B:half", "G:half", "R:half"};
  capture.software_version = "0.1.0";
  FrameCheck check = check_frame(dir.string(), 1, capture, "this capture");
  EXPECT_EQ(check.state, FrameState::kComplete) << check.problem;
  capture.fps = 25.0f;
  capture.scene_digest = "sha256:99999999999999999999";
  check = check_frame(dir.string(), 1, capture, "this capture");
  EXPECT_EQ(check.state, FrameState::kMismatch);
  EXPECT_EQ(check.problem,
            "differs from this capture (in brackets): scene content differs, digest "
            "sha256:0123456789ab... (sha256:999999999999...), fps 30 (25)");
  // A folder of the earlier layout, checked by a capture that records digests: named as such.
  write_frame(dir, 2, {.digest = ""});
  check = check_frame(dir.string(), 2, capture, "this capture");
  EXPECT_EQ(check.state, FrameState::kMismatch);
  EXPECT_EQ(check.problem,
            "differs from this capture (in brackets): an earlier layout without "
            "siviflow/scene_digest (one with it)");
  // And verify, whose reference is the first frame: the later layout is the odd one out there.
  write_frame(dir, 0, {.digest = ""});
  ASSERT_TRUE(check_frame_folder(dir.string(), 0, 0, &report).ok());
  EXPECT_EQ(problem_of(report, 1),
            "differs from frame_00000.exr (in brackets): a layout with siviflow/scene_digest (an "
            "earlier one without it)");
}

TEST(FrameFolder, ListsItsFramesInOrder) {
  const fs::path dir = fresh_test_dir("frame_folder");
  for (uint32_t frame : {12u, 3u, 100000u, 7u}) write_frame(dir, frame);
  std::ofstream(dir / "frame_7.exr") << "not five digits";
  std::ofstream(dir / "frame_00009.exr.tmp") << "a temporary";
  std::vector<uint32_t> frames;
  ASSERT_TRUE(list_frames(dir.string(), &frames).ok());
  EXPECT_EQ(frames, (std::vector<uint32_t>{3, 7, 12, 100000}));
  const Status status = list_frames((dir / "absent").string(), &frames);
  EXPECT_EQ(status.message(), "'" + (dir / "absent").string() + "': no such folder");
}

TEST(FrameFolder, RefusesWhatIsNotAFolderOfFrames) {
  const fs::path dir = fresh_test_dir("frame_folder");
  FrameFolderReport report;
  Status status = check_frame_folder((dir / "absent").string(), 0, 0, &report);
  EXPECT_EQ(status.message(), "'" + (dir / "absent").string() + "': no such folder");
  status = check_frame_folder(dir.string(), 0, 0, &report);
  EXPECT_EQ(status.message(), "'" + dir.string() + "': no frame_NNNNN.exr file in it");
  std::ofstream(dir / "file") << "x";
  status = check_frame_folder((dir / "file").string(), 0, 0, &report);
  EXPECT_EQ(status.message(), "'" + (dir / "file").string() + "': not a folder");
  // With a range, an empty folder is every frame missing.
  ASSERT_TRUE(check_frame_folder(dir.string(), 4, 6, &report).ok());
  EXPECT_EQ(report.problems.size(), 2u);
}

TEST(VerifyCommand, ExitStatusAndOneLinePerBadFrame) {
  const fs::path dir = fresh_test_dir("frame_folder");
  for (uint32_t frame = 0; frame < 4; ++frame) write_frame(dir, frame);
  testing::RunResult run = run_siviflow("verify " + dir.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("frames 0..3: 4 of 4 complete"), std::string::npos) << run.output;

  fs::remove(dir / "frame_00001.exr");
  write_frame(dir, 2, {.seed = 9});
  run = run_siviflow("verify " + dir.string() + " --range 0:5");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("frame_00001.exr: missing\n"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("frame_00002.exr: differs from frame_00000.exr (in brackets): seed "
                            "9 (1)\n"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("frame_00004.exr: missing\n"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("2 of 5 complete"), std::string::npos) << run.output;

  run = run_siviflow("verify " + (dir / "absent").string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("siviflow verify: '" + (dir / "absent").string() +
                            "': no such folder"),
            std::string::npos)
      << run.output;
  run = run_siviflow("verify");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("required"), std::string::npos) << run.output;
  run = run_siviflow("verify " + dir.string() + " --range 5:2");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("--range"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace siviflow
