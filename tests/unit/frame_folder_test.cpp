// Checking a folder of captured frames (check_frame_folder, and `siviflow verify` over it):
// present, read whole, their own frame number, and captured alike; each bad frame named with its
// problem, and a folder that cannot be checked refused with a message.
#include <filesystem>
#include <fstream>
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

struct FrameSpec {
  int width = 8;
  int height = 4;
  int seed = 1;
  std::string scene = "default";
  std::string version = "0.1.0";
  bool depth = false;
  int frame_attribute = -1;  // -1: the file's own frame
};

void write_frame(const fs::path& dir, uint32_t frame, const FrameSpec& spec = {}) {
  const size_t pixels = size_t(spec.width) * spec.height;
  std::vector<float> rgba(pixels * 4, 0.25f);
  std::vector<float> depth(pixels, 3.0f);
  ExrFrame exr;
  exr.width = spec.width;
  exr.height = spec.height;
  exr.rgba = rgba.data();
  if (spec.depth) exr.layers.push_back({"depth", ExrCompression::kZip, {{"depth.Z", depth.data()}}});
  exr.metadata.scene = spec.scene;
  exr.metadata.frame = spec.frame_attribute >= 0 ? spec.frame_attribute : static_cast<int>(frame);
  exr.metadata.seed = spec.seed;
  exr.metadata.software_version = spec.version;
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

  FrameFolderReport report;
  ASSERT_TRUE(check_frame_folder(dir.string(), 0, 10, &report).ok());
  EXPECT_EQ(report.complete, 2u);
  ASSERT_EQ(report.problems.size(), 8u);
  EXPECT_EQ(report.problems[0].file, "frame_00002.exr");
  EXPECT_EQ(problem_of(report, 2), "missing");
  EXPECT_NE(problem_of(report, 3).find("cannot be read whole"), std::string::npos)
      << problem_of(report, 3);
  EXPECT_NE(problem_of(report, 4).find("not an EXR file"), std::string::npos)
      << problem_of(report, 4);
  EXPECT_EQ(problem_of(report, 5), "differs from frame_00000.exr (in brackets): seed 7 (1)");
  EXPECT_EQ(problem_of(report, 6),
            "differs from frame_00000.exr (in brackets): scene 'other.json' ('default'), "
            "size 16x4 (8x4)");
  EXPECT_EQ(problem_of(report, 7),
            "differs from frame_00000.exr (in brackets): channels A,B,G,R (A,B,G,R,depth.Z)");
  EXPECT_EQ(problem_of(report, 8),
            "differs from frame_00000.exr (in brackets): software version '0.2.0' ('0.1.0')");
  EXPECT_EQ(problem_of(report, 9), "holds frame 2");
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
