// The version header's macros, the library's version() and version_string(), and the version of
// project() in CMakeLists.txt (SIVIFLOW_PROJECT_VERSION, passed by the test's build) all agree.
#include "siviflow/version.h"

#include <string>

#include <gtest/gtest.h>

namespace siviflow {
namespace {

TEST(Version, HeaderLibraryAndProjectAgree) {
  const std::string project = SIVIFLOW_PROJECT_VERSION;
  EXPECT_EQ(SIVIFLOW_VERSION_STRING, project);
  EXPECT_EQ(std::to_string(SIVIFLOW_VERSION_MAJOR) + "." + std::to_string(SIVIFLOW_VERSION_MINOR) +
                "." + std::to_string(SIVIFLOW_VERSION_PATCH),
            project);
  const Version linked = version();
  EXPECT_EQ(linked.major, SIVIFLOW_VERSION_MAJOR);
  EXPECT_EQ(linked.minor, SIVIFLOW_VERSION_MINOR);
  EXPECT_EQ(linked.patch, SIVIFLOW_VERSION_PATCH);
  EXPECT_EQ(std::string(version_string()), "siviflow " + project);
}

}  // namespace
}  // namespace siviflow
