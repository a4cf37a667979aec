// Small helpers shared by the siviflow subcommands: strict argument parsing with messages that
// name the flag and the bad value.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "siviflow/status.h"

namespace siviflow::cli {

// Exit codes of every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitError = 1;     // bad input, or a failure with a message

struct Size {
  uint32_t width = 0;
  uint32_t height = 0;
};

// "1280x720" -> {1280, 720}; rejects zero, negative, non-numeric and absurd values.
Status parse_size(std::string_view flag, std::string_view text, Size* out);
// A non-negative integer that fits in uint32_t.
Status parse_uint(std::string_view flag, std::string_view text, uint32_t* out);
// A positive finite number.
Status parse_positive_float(std::string_view flag, std::string_view text, float* out);
// "A:B" with A < B.
Status parse_range(std::string_view flag, std::string_view text, uint32_t* first, uint32_t* end);
// Comma list, e.g. "depth,flow".
std::vector<std::string> split_list(std::string_view text);

// Walks argv, handing out values for flags that take one.
class ArgReader {
 public:
  ArgReader(int argc, char** argv, int first) : argc_(argc), argv_(argv), next_(first) {}
  bool done() const { return next_ >= argc_; }
  std::string_view next() { return argv_[next_++]; }
  // The value after `flag`; an error when it is missing.
  Status value(std::string_view flag, std::string_view* out);

 private:
  int argc_;
  char** argv_;
  int next_;
};

// The error for an argument that no option of capture or bench takes: an unknown option, or a
// positional argument (a scene file, which they do not read yet).
Status unexpected_argument(std::string_view arg);

// Prints "siviflow <command>: <message>" to stderr and returns kExitError.
int fail(std::string_view command, const std::string& message);

}  // namespace siviflow::cli
