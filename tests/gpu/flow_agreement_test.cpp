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
#include <gtest/gtest.h>

#include "run_command.h"
#include "scene/default_scene.h"
#include "siviflow/image_files.h"
#include "view_proj.h"

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

constexpr int kWidth = 320;
constexpr int kHeight = 180;
constexpr double kFps = 30.0;

// The default scene's river and obstacles, as a scene file; `camera` is its "camera" object or
// empty for the default camera.
std::string default_scene_json(const ProceduralRiver& river, const std::string& camera = "") {
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
  scene << "]" << (camera.empty() ? "" : R"(,"camera":)" + camera) << "}";
  return scene.str();
}

// `siviflow flow` of the scene at frame `frame`'s time.
std::vector<CsvVertex> solve(const fs::path& dir, int frame) {
  const fs::path csv = dir / ("flow_" + std::to_string(frame) + ".csv");
  const RunResult r = run_siviflow("flow " + (dir / "scene.json").string() + " --time " +
                                   std::to_string(frame / kFps) + " --out " + csv.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return read_flow_csv(csv);
}

const CsvVertex& nearest_vertex(const std::vector<CsvVertex>& vertices, glm::vec2 xz) {
  const CsvVertex* nearest = &vertices.front();
  float best = 1e30f;
  for (const CsvVertex& v : vertices) {
    const glm::vec2 d = v.xz - xz;
    const float d2 = glm::dot(d, d);
    if (d2 < best) {
      best = d2;
      nearest = &v;
    }
  }
  return *nearest;
}

double angle_deg(glm::vec2 a, glm::vec2 b) {
  const double c = glm::dot(glm::normalize(a), glm::normalize(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / 3.14159265358979;
}

// A visible water pixel of a captured frame: where it is on the river and the flow AOV there.
struct WaterPixel {
  glm::vec3 world;
  glm::vec2 flow;  // xz of the flow AOV
};

// The water pixels with a flow of at least 0.2 m/s, placed in the world through the renderer's
// camera and the depth AOV.
std::vector<WaterPixel> water_pixels(const ExrImage& image, const Camera& camera) {
  const glm::mat4 inverse = glm::inverse(view_proj_of(camera, kWidth, kHeight));
  const glm::vec3 forward = glm::normalize(camera.target - camera.position);
  std::vector<WaterPixel> pixels;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + x;
      if ((*image.find("water.A"))[i] != 1.0f) continue;
      const glm::vec2 flow((*image.find("flow.X"))[i], (*image.find("flow.Z"))[i]);
      if (glm::length(flow) < 0.2f) continue;  // still water: no direction to compare
      const glm::vec4 far = inverse * glm::vec4(2.0f * (x + 0.5f) / kWidth - 1.0f,
                                                2.0f * (y + 0.5f) / kHeight - 1.0f, 1.0f, 1.0f);
      const glm::vec3 ray = glm::normalize(glm::vec3(far) / far.w - camera.position);
      const float z = (*image.find("depth.Z"))[i];
      pixels.push_back({camera.position + ray * (z / glm::dot(ray, forward)), flow});
    }
  }
  return pixels;
}

class FlowAgreement : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("flow_agreement");
    std::ofstream(dir_ / "scene.json") << default_scene_json(river_);
  }
  // Captures frames [first, last] of the default scene with the depth and flow AOVs.
  void capture(int first, int last) {
    const RunResult r = run_siviflow("capture --range " + std::to_string(first) + ":" +
                                     std::to_string(last + 1) + " --size " + std::to_string(kWidth) +
                                     "x" + std::to_string(kHeight) + " --aov depth,flow --out " +
                                     dir_.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  std::vector<WaterPixel> frame_pixels(int frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05d.exr", frame);
    ExrImage image;
    EXPECT_TRUE(read_exr((dir_ / name).string(), &image).ok());
    if (image.find("flow.X") == nullptr) return {};
    return water_pixels(image, default_camera(river_, frame / kFps));
  }
  const ProceduralRiver river_{default_river_params()};
  fs::path dir_;
};

TEST_F(FlowAgreement, FlowAovFollowsTheSolvedField) {
  constexpr int kFrame = 60;  // t = 2 s: the boulder is rolling into the river
  const std::vector<CsvVertex> vertices = solve(dir_, kFrame);
  ASSERT_GT(vertices.size(), 1000u);
  capture(kFrame, kFrame);
  std::vector<double> angles;
  for (const WaterPixel& pixel : frame_pixels(kFrame)) {
    const CsvVertex& nearest = nearest_vertex(vertices, glm::vec2(pixel.world.x, pixel.world.z));
    if (!nearest.wet || glm::length(nearest.flow) < 0.2f) continue;
    angles.push_back(angle_deg(pixel.flow, nearest.flow));
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

struct CsvParticle {
  int id;
  glm::vec2 xz;    // world position
  glm::vec2 flow;  // xz of its flow
};

std::vector<CsvParticle> read_particles_csv(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);  // id,state,sx,sy,wx,wy,wz,fx,fy,fz,speed,depth,slope,fade
  std::vector<CsvParticle> particles;
  while (std::getline(file, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ',')) cells.push_back(cell);
    particles.push_back({std::stoi(cells[0]), {std::stod(cells[4]), std::stod(cells[6])},
                         {std::stod(cells[7]), std::stod(cells[9])}});
  }
  return particles;
}

// While the boulder rolls into the river, the very next frame's particles around it carry that
// frame's fresh solve, not the previous frame's, and the flow AOV shows their flow.
TEST_F(FlowAgreement, NextFrameFollowsTheMovedObstacle) {
  constexpr int kFrame = 75;  // t = 2.5 s, half-way in; the frame before is at 2.467 s
  constexpr int kW = 640;
  constexpr int kH = 360;
  const Obstacle moving = default_scene_obstacles(river_).back();
  const glm::vec3 centre = obstacle_centre_at(moving, kFrame / kFps);
  // A still camera 12 m from the boulder, looking down at it.
  std::ofstream(dir_ / "scene.json") << default_scene_json(
      river_, R"({"keys":[{"t":0,"position":)" + vec3_json(centre + glm::vec3(0.0f, 7.0f, -10.0f)) +
                  R"(,"target":)" + vec3_json(centre) + "}]}");
  const std::vector<CsvVertex> before = solve(dir_, kFrame - 1);
  const std::vector<CsvVertex> after = solve(dir_, kFrame);
  const RunResult r = run_siviflow("capture " + (dir_ / "scene.json").string() + " --range " + std::to_string(kFrame) + ":" +
                                   std::to_string(kFrame + 1) + " --size " + std::to_string(kW) + "x" +
                                   std::to_string(kH) + " --aov flow,particles --out " + dir_.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExrImage image;
  ASSERT_TRUE(read_exr((dir_ / "frame_00075.exr").string(), &image).ok());
  const std::vector<CsvParticle> particles = read_particles_csv(dir_ / "frame_00075.particles.csv");

  std::vector<int> rerouted;  // particles near the boulder whose solved flow the move changed
  for (const CsvParticle& p : particles) {
    if (glm::length(p.xz - glm::vec2(centre.x, centre.z)) > 4.0f * moving.radius) continue;
    const glm::vec2 now = nearest_vertex(after, p.xz).flow;
    const glm::vec2 then = nearest_vertex(before, p.xz).flow;
    const float change = glm::length(now - then);
    if (change < 0.005f) continue;  // m/s; the boulder moves 0.1 m a frame
    rerouted.push_back(p.id);
    EXPECT_LT(glm::length(p.flow - now), 1e-4f + 1e-4f * glm::length(now))
        << "particle " << p.id << " carries this frame's solve";
    EXPECT_GT(glm::length(p.flow - then), 0.5f * change) << "particle " << p.id << " has the old flow";
  }
  std::printf("%zu particles near the moving boulder were re-routed between frames %d and %d\n",
              rerouted.size(), kFrame - 1, kFrame);
  ASSERT_GE(rerouted.size(), 5u) << "the boulder's move must change the flow of particles near it";

  // The flow AOV over each re-routed particle's pixels is that particle's (new) flow.
  size_t pixels = 0;
  const std::vector<float>& ids = *image.find("particle.I");
  for (size_t i = 0; i < ids.size(); ++i) {
    const int id = static_cast<int>(ids[i]);
    if (std::find(rerouted.begin(), rerouted.end(), id) == rerouted.end()) continue;
    const CsvParticle& p = *std::find_if(particles.begin(), particles.end(),
                                         [id](const CsvParticle& q) { return q.id == id; });
    const glm::vec2 aov((*image.find("flow.X"))[i], (*image.find("flow.Z"))[i]);
    EXPECT_LT(glm::length(aov - p.flow), 0.002f + 0.002f * glm::length(p.flow)) << "pixel " << i;
    ++pixels;
  }
  EXPECT_GT(pixels, rerouted.size() * 8) << "the re-routed particles cover pixels of the flow AOV";
}

}  // namespace
}  // namespace siviflow::testing
