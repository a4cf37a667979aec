// The render-farm pieces that run without a cluster: capture_shard.sh refuses a bad chunking with
// a message, and the Kubernetes Indexed Job's pods, on a fresh volume, create the frames' folder
// and would run valid `siviflow capture` invocations (checked by the tool itself with --dry-run)
// that cover its range exactly once, with the verify Job checking that same range and folder.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_command.h"

namespace siviflow {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;
using testing::run_shell;

const std::string kFarm = std::string(SIVIFLOW_SOURCE_DIR) + "/tools/farm/";
const std::string kSiviflow = std::string(SIVIFLOW_BINARY_DIR) + "/tools/siviflow";

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The value of the first `key: value` line, or "".
std::string yaml_value(const std::string& yaml, const std::string& key) {
  std::smatch match;
  const std::regex line("\\n\\s*" + key + ": (.*)\\n");
  return std::regex_search(yaml, match, line) ? match[1].str() : "";
}

// A flow sequence of double-quoted strings, as the manifests write args (a JSON array).
std::vector<std::string> yaml_strings(const std::string& yaml, const std::string& key) {
  return nlohmann::json::parse(yaml_value(yaml, key)).get<std::vector<std::string>>();
}

RunResult run_shard(const std::string& args) {
  return run_shell("SIVIFLOW=" + kSiviflow + " bash " + kFarm + "capture_shard.sh " + args);
}

TEST(FarmScripts, ShardRefusesBadChunking) {
  const std::string out = testing::fresh_test_dir("farm").string();
  const struct {
    std::string args;
    std::string message;
  } cases[] = {
      {"0 0 240 0 " + out, "CHUNK must be at least 1 frame"},
      {"0 0 240 7 " + out, "the range's 240 frames do not divide into chunks of 7"},
      {"10 0 240 24 " + out, "INDEX 10 is past the last of the 10 chunks"},
      {"0 50 50 10 " + out, "the range 50..50 is empty"},
      {"x 0 240 24 " + out, "INDEX must be a whole number, not 'x'"},
      {"0 0 240", "usage: capture_shard.sh"},
  };
  for (const auto& c : cases) {
    const RunResult run = run_shard(c.args);
    EXPECT_EQ(run.exit_code, 1) << c.args << "\n" << run.output;
    EXPECT_NE(run.output.find("capture_shard: " + c.message), std::string::npos)
        << c.args << "\n" << run.output;
  }
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(FarmScripts, IndexedJobCoversItsRangeOnceWithValidCaptures) {
  const std::string job = read_file(kFarm + "capture-indexed-job.yaml");
  ASSERT_FALSE(job.empty());
  EXPECT_EQ(yaml_value(job, "completionMode"), "Indexed");
  const int completions = std::stoi(yaml_value(job, "completions"));
  const std::vector<std::string> command = yaml_strings(job, "command");
  ASSERT_EQ(command.size(), 1u);
  EXPECT_EQ(fs::path(command[0]).filename(), "capture_shard.sh");
  std::vector<std::string> args = yaml_strings(job, "args");
  ASSERT_GE(args.size(), 5u);
  EXPECT_EQ(args[0], "$(JOB_COMPLETION_INDEX)");
  const int first = std::stoi(args[1]);
  const int end = std::stoi(args[2]);
  EXPECT_EQ((end - first) / std::stoi(args[3]), completions) << "one pod per chunk";

  // The pods' volumes stand in as folders here: the frames' (fresh: the frames' folder is not
  // there yet, and the pods create it) and the scene's.
  const fs::path dir = testing::fresh_test_dir("farm");
  const std::string frames = args[4];
  args[4] = (dir / "volume" / "shot010").string();
  for (std::string& arg : args) {
    if (arg.size() > 5 && arg.compare(arg.size() - 5, 5, ".json") == 0) {
      arg = (dir / fs::path(arg).filename()).string();
      std::ofstream(arg) << R"({"version": 1, "river": {"procedural": {}}})";
    }
  }
  std::multiset<int> rendered;
  const std::regex plan("would render frames (\\d+)\\.\\.(\\d+) ");
  for (int index = 0; index < completions; ++index) {
    std::string line = std::to_string(index);
    for (size_t i = 1; i < args.size(); ++i) line += " " + args[i];
    const RunResult run = run_shard(line + " --dry-run");
    ASSERT_EQ(run.exit_code, 0) << line << "\n" << run.output;
    std::smatch match;
    ASSERT_TRUE(std::regex_search(run.output, match, plan)) << run.output;
    for (int frame = std::stoi(match[1]); frame <= std::stoi(match[2]); ++frame) {
      rendered.insert(frame);
    }
  }
  EXPECT_TRUE(fs::is_directory(args[4])) << "the pods create the frames' folder";
  ASSERT_EQ(rendered.size(), static_cast<size_t>(end - first));
  for (int frame = first; frame < end; ++frame) EXPECT_EQ(rendered.count(frame), 1u) << frame;

  // The verify Job checks that folder and that range.
  const std::string verify = read_file(kFarm + "verify-job.yaml");
  EXPECT_EQ(yaml_strings(verify, "args"),
            (std::vector<std::string>{"verify", frames, "--range",
                                      std::to_string(first) + ":" + std::to_string(end)}));
}

}  // namespace
}  // namespace siviflow
