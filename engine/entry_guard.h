// What every public entry point of the library runs its body through: no exception leaves it
// (an allocation that failed included), every error message starts with the component's prefix,
// and errors reach the host's log callback.
#pragma once

#include <new>
#include <string_view>

#include "siviflow/renderer.h"
#include "siviflow/status.h"

namespace siviflow {

// What an exception escaping a body becomes.
Status out_of_memory_error(std::string_view prefix) noexcept;
Status unexpected_error(std::string_view prefix) noexcept;
// Gives an error the prefix (if it lacks it) and hands it to `log`, if any.
void report_error(std::string_view prefix, LogCallback log, void* log_user, Status* status) noexcept;

template <typename Body>
Status guarded(std::string_view prefix, LogCallback log, void* log_user, Body&& body) noexcept {
  Status status;
  try {
    status = body();
  } catch (const std::bad_alloc&) {
    status = out_of_memory_error(prefix);
  } catch (...) {
    status = unexpected_error(prefix);
  }
  if (!status.ok()) report_error(prefix, log, log_user, &status);
  return status;
}

}  // namespace siviflow
