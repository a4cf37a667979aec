// The flow AOV of a capture agrees in direction with `siviflow flow` for the same river, obstacles
// and time: the particles carry the solved field to the screen.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "run_command.h"
#include "scene/default_scene.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

struct CsvVertex {
  glm::vec2 xz;
  glm::vec2 flow;
  bool wet;
};

std::vector<CsvVertex> read_flow_csv(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);  // header
  std::vector<CsvVertex> vertices;
  while (std::getline(file, line)) {
    std::vector<double> v;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) v.push_back(std::stod(cell));
    vertices.push_back({{v[1], v[3]}, {v[10], v[12]}, v[13] != 0.0});
  }
  return vertices;
}

std::string vec3_json(glm::vec3 p) {
  std::ostringstream out;
  out.precision(9);
  out << "[" << p.x << "," << p.y << "," << p.z << "]";
  return out.str();
}

TEST(FlowAgreement, FlowAovFollowsTheSolvedField) {
  constexpr int kFrame = 60;  // t = 2 s: the boulder is rolling into the river
  constexpr double kTime = kFrame / 30.0;
  constexpr int kWidth = 320;
  constexpr int kHeight = 180;
  const fs::path dir = fs::path(SIVIFLOW_BINARY_DIR) / "tests" / "flow_agreement";
  fs::remove_all(dir);
  fs::create_directories(dir);

  // The default scene's river and obstacles, as a scene file.
  const ProceduralRiver river(default_river_params());
  std::ostringstream scene;
  scene << R"({"version":1,"river":{"procedural":{"seed":)" << river.params().seed
        << R"(}},"flow":{"discharge":20.0,"p":1.5},"obstacles":[)";
  const std::vector<Obstacle> obstacles = default_scene_obstacles(river);
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const Obstacle& o = obstacles[i];
    scene << (i ? "," : "") << R"({"center":)" << vec3_json(o.centre) << R"(,"radius":)" << o.radius;
    if (!o.keys.empty()) {
      scene << R"(,"keys":[)";
      for (size_t k = 0; k < o.keys.size(); ++k) {
        scene << (k ? "," : "") << R"({"t":)" << o.keys[k].t << R"(,"center":)" << vec3_json(o.keys[k].centre) << "}";
      }
      scene << "]";
    }
    scene << "}";
  }
  scene << "]}";
  std::ofstream(dir / "scene.json") << scene.str();

  RunResult r = run_siviflow("flow " + (dir / "scene.json").string() + " --time " + std::to_string(kTime) +
                             " --out " + (dir / "flow.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_siviflow("capture --range " + std::to_string(kFrame) + ":" + std::to_string(kFrame + 1) +
                   " --size 320x180 --aov depth,flow --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<CsvVertex> vertices = read_flow_csv(dir / "flow.csv");
  ASSERT_GT(vertices.size(), 1000u);
  ExrImage image;
  ASSERT_TRUE(read_exr((dir / "frame_00060.exr").string(), &image).ok());

  // Each water pixel's world point, from the renderer's camera and the depth AOV.
  const Camera camera = default_camera(river, kTime);
  glm::mat4 projection = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_deg),
                                               float(kWidth) / float(kHeight), camera.near_plane,
                                               camera.far_plane);
  projection[1][1] *= -1.0f;
  const glm::mat4 view = glm::lookAtRH(camera.position, camera.target, glm::vec3(0, 1, 0));
  const glm::mat4 inverse = glm::inverse(projection * view);
  const glm::vec3 forward = glm::normalize(camera.target - camera.position);
  std::vector<double> angles;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + x;
      if ((*image.find("water.mask"))[i] != 1.0f) continue;
      const glm::vec2 flow((*image.find("flow.X"))[i], (*image.find("flow.Z"))[i]);
      if (glm::length(flow) < 0.2f) continue;  // still water: no direction to compare
      const glm::vec4 far = inverse * glm::vec4(2.0f * (x + 0.5f) / kWidth - 1.0f,
                                                2.0f * (y + 0.5f) / kHeight - 1.0f, 1.0f, 1.0f);
      const glm::vec3 ray = glm::normalize(glm::vec3(far) / far.w - camera.position);
      const float z = (*image.find("depth.Z"))[i];
      const glm::vec3 world = camera.position + ray * (z / glm::dot(ray, forward));
      const CsvVertex* nearest = nullptr;
      float best = 1e30f;
      for (const CsvVertex& v : vertices) {
        const glm::vec2 d = v.xz - glm::vec2(world.x, world.z);
        const float d2 = glm::dot(d, d);
        if (d2 < best) {
          best = d2;
          nearest = &v;
        }
      }
      if (!nearest->wet || glm::length(nearest->flow) < 0.2f) continue;
      const double c = glm::dot(glm::normalize(flow), glm::normalize(nearest->flow));
      angles.push_back(std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979);
    }
  }
  ASSERT_GT(angles.size(), 500u);
  std::sort(angles.begin(), angles.end());
  const double median = angles[angles.size() / 2];
  const double p90 = angles[angles.size() * 9 / 10];
  std::printf("flow AOV vs solved field over %zu pixels: median %.2f deg, 90th percentile %.2f deg\n",
              angles.size(), median, p90);
  EXPECT_LT(median, 5.0) << "median angle between the flow AOV and the solved field";
  EXPECT_LT(p90, 15.0) << "90th percentile of that angle";
}

}  // namespace
}  // namespace siviflow::testing
