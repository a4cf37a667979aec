// The library's side of siviflow/version.h: the release it was built as, for a host to compare.
#include "siviflow/version.h"

namespace siviflow {

Version version() {
  return {SIVIFLOW_VERSION_MAJOR, SIVIFLOW_VERSION_MINOR, SIVIFLOW_VERSION_PATCH};
}

const char* version_string() { return "siviflow " SIVIFLOW_VERSION_STRING; }

}  // namespace siviflow
