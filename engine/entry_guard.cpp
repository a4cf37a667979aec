#include "entry_guard.h"

#include <string>

namespace siviflow {

Status out_of_memory_error(std::string_view prefix) noexcept {
  try {
    return Status::error(std::string(prefix) + "out of host memory", VK_ERROR_OUT_OF_HOST_MEMORY);
  } catch (...) {  // no memory even for the message
    return Status::error(std::string(), VK_ERROR_OUT_OF_HOST_MEMORY);
  }
}

Status unexpected_error(std::string_view prefix) noexcept {
  try {
    return Status::error(std::string(prefix) + "unexpected internal exception");
  } catch (...) {
    return Status::error(std::string());
  }
}

void report_error(std::string_view prefix, LogCallback log, void* log_user, Status* status) noexcept {
  try {
    if (status->message().rfind(prefix, 0) != 0) {
      *status = Status::error(std::string(prefix) + status->message(), status->code());
    }
    if (log != nullptr) log(LogLevel::kError, status->message().c_str(), log_user);
  } catch (...) {  // the status stays as it was
  }
}

}  // namespace siviflow
