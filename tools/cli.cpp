#include "cli.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "siviflow/printable_text.h"

namespace siviflow::cli {
namespace {

Status bad_value(std::string_view flag, std::string_view text, const char* expected) {
  return Status::error(std::string(flag) + ": invalid value '" + std::string(text) + "' (" +
                       expected + ")");
}

}  // namespace

Status parse_uint(std::string_view flag, std::string_view text, uint32_t* out) {
  uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    return bad_value(flag, text, "expected a non-negative integer");
  }
  *out = value;
  return Status::success();
}

Status parse_positive_float(std::string_view flag, std::string_view text, float* out) {
  const std::string copy(text);
  char* end = nullptr;
  const float value = std::strtof(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size() || !std::isfinite(value) || value <= 0.0f) {
    return bad_value(flag, text, "expected a positive number");
  }
  *out = value;
  return Status::success();
}

Status parse_size(std::string_view flag, std::string_view text, Size* out) {
  const size_t x = text.find('x');
  if (x == std::string_view::npos) return bad_value(flag, text, "expected WIDTHxHEIGHT, e.g. 1280x720");
  uint32_t width = 0;
  uint32_t height = 0;
  if (!parse_uint(flag, text.substr(0, x), &width).ok() ||
      !parse_uint(flag, text.substr(x + 1), &height).ok()) {
    return bad_value(flag, text, "expected WIDTHxHEIGHT with positive integers, e.g. 1280x720");
  }
  if (width == 0 || height == 0) return bad_value(flag, text, "width and height must be at least 1");
  *out = {width, height};
  return Status::success();
}

Status parse_range(std::string_view flag, std::string_view text, uint32_t* first, uint32_t* end) {
  const size_t colon = text.find(':');
  if (colon == std::string_view::npos) return bad_value(flag, text, "expected A:B");
  uint32_t a = 0;
  uint32_t b = 0;
  if (!parse_uint(flag, text.substr(0, colon), &a).ok() ||
      !parse_uint(flag, text.substr(colon + 1), &b).ok()) {
    return bad_value(flag, text, "expected A:B with non-negative integers");
  }
  if (a >= b) return bad_value(flag, text, "A must be less than B");
  *first = a;
  *end = b;
  return Status::success();
}

std::vector<std::string> split_list(std::string_view text) {
  std::vector<std::string> items;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    const size_t stop = comma == std::string_view::npos ? text.size() : comma;
    if (stop > start) items.emplace_back(text.substr(start, stop - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return items;
}

Status ArgReader::value(std::string_view flag, std::string_view* out) {
  if (done()) return Status::error(std::string(flag) + ": missing value");
  *out = next();
  return Status::success();
}

Status unexpected_argument(std::string_view arg) {
  if (!arg.empty() && arg[0] == '-') {
    return Status::error("unknown option '" + std::string(arg) + "' (see --help)");
  }
  return Status::error("unexpected argument '" + std::string(arg) + "' (see --help)");
}

int fail(std::string_view command, const std::string& message) {
  std::fprintf(stderr, "siviflow %.*s: %s\n", static_cast<int>(command.size()), command.data(),
               printable_text(message).c_str());
  return kExitError;
}

}  // namespace siviflow::cli
