// The status every fallible siviflow call returns: library code never throws, aborts or exits.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include "siviflow/printable_text.h"

namespace siviflow {

class [[nodiscard]] Status {
 public:
  Status() = default;  // success

  static Status success() { return Status(); }
  // code: the VkResult when Vulkan is the cause (negative), otherwise kGenericError. The
  // message is kept as printable_text() of it: whatever bytes of a file it quotes, it is valid
  // UTF-8 without control characters.
  static Status error(std::string_view message, int32_t code = kGenericError) {
    return Status(code, printable_text(message));
  }

  bool ok() const { return code_ == 0; }
  explicit operator bool() const { return ok(); }
  int32_t code() const { return code_; }
  const std::string& message() const { return message_; }

  static constexpr int32_t kGenericError = -0x7fff;

 private:
  Status(int32_t code, std::string message) : code_(code), message_(std::move(message)) {}
  int32_t code_ = 0;
  std::string message_;
};

// Returns early from the enclosing function when `expr` yields a failed Status.
#define SIVIFLOW_TRY(expr)                  \
  do {                                      \
    ::siviflow::Status status_ = (expr);    \
    if (!status_.ok()) return status_;      \
  } while (0)

}  // namespace siviflow
