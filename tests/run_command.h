// Runs the siviflow tool as a user would, capturing its exit status and output; a fresh folder
// for what a test run writes, and the bytes of what it wrote.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace siviflow::testing {

struct RunResult {
  int exit_code = -1;  // -1: did not exit normally (a crash counts as a failure)
  std::string output;  // stdout and stderr
};

// Runs `command` through the shell, stderr into the output.
inline RunResult run_shell(const std::string& command) {
  RunResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// `env` is prepended as shell assignments, e.g. "VK_DRIVER_FILES=/x.json".
inline RunResult run_siviflow(const std::string& args, const std::string& env = "") {
  return run_shell(env + " " + std::string(SIVIFLOW_BINARY_DIR) + "/tools/siviflow " + args);
}

// A file's bytes; empty when it cannot be read.
inline std::string read_file(const std::filesystem::path& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  std::string text;
  if (f == nullptr) return text;
  char buffer[4096];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), f)) > 0) text.append(buffer, n);
  std::fclose(f);
  return text;
}

// An empty folder for the running test's files: <build>/tests/<group>/<test name>.
inline std::filesystem::path fresh_test_dir(const std::string& group) {
  const std::filesystem::path dir = std::filesystem::path(SIVIFLOW_BINARY_DIR) / "tests" / group /
                                    ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace siviflow::testing
