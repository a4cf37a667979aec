// The live viewer (`siviflow view`) in a real window: an Xvfb server started by the test on a
// private display, a real swapchain on lavapipe, the validation layer with synchronization
// validation, scripted input through the viewer's own input path.
#include <fcntl.h>
#include <png.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <gtest/gtest.h>

#include "default_river.h"
#include "run_command.h"
#include "scene/default_scene.h"
#include "siviflow/scene_river.h"

namespace siviflow {
namespace {

using testing::fresh_test_dir;
using testing::run_siviflow;

constexpr uint32_t kWidth = 640;
constexpr uint32_t kHeight = 360;

// An Xvfb server on a display it picks itself (-displayfd), for the whole test program.
class XvfbServer : public ::testing::Environment {
 public:
  void SetUp() override {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    pid_ = fork();
    ASSERT_GE(pid_, 0);
    if (pid_ == 0) {
      close(fds[0]);
      const std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-nolisten", "tcp", "-screen", "0",
             "1920x1080x24", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    std::string number;
    char c = 0;
    while (read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    close(fds[0]);
    ASSERT_FALSE(number.empty())
        << "Xvfb did not start (package xvfb, installed by tools/scripts/install_deps.sh): the "
           "window tests need an X server";
    display_ = ":" + number;
  }
  void TearDown() override {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  static const std::string& display() { return display_; }

 private:
  pid_t pid_ = -1;
  static inline std::string display_;
};

const auto* const kXvfb = ::testing::AddGlobalTestEnvironment(new XvfbServer);

std::string display_env() { return "DISPLAY=" + XvfbServer::display() + " WAYLAND_DISPLAY="; }

struct Png {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgb;
  glm::vec3 at(uint32_t x, uint32_t y) const {
    const uint8_t* p = &rgb[(size_t{y} * width + x) * 3];
    return {p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f};
  }
};

bool read_png(const std::string& path, Png* out) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) return false;
  image.format = PNG_FORMAT_RGB;
  out->width = image.width;
  out->height = image.height;
  out->rgb.resize(PNG_IMAGE_SIZE(image));
  return png_image_finish_read(&image, nullptr, out->rgb.data(), 0, nullptr) != 0;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// The default scene as the viewer starts: the fly camera where the scene's camera is at t = 0.
struct DefaultScene {
  SceneRiverData river;
  View view;
  VkExtent2D extent;
  explicit DefaultScene(VkExtent2D size = {kWidth, kHeight}) : extent(size) {
    EXPECT_TRUE(scene_river_data(nullptr, 0, &river).ok());
    view = camera_view(default_camera(*river.procedural, 0.0), extent);
  }
  // The water's height under (x, z): the nearest river vertex's.
  glm::vec3 on_water(float x, float z) const {
    glm::vec3 best = river.mesh.positions.front();
    for (const glm::vec3& p : river.mesh.positions) {
      if (glm::length(glm::vec2(p.x - x, p.z - z)) < glm::length(glm::vec2(best.x - x, best.z - z))) {
        best = p;
      }
    }
    return {x, best.y, z};
  }
  std::optional<glm::vec2> pixel(const glm::vec3& world) const {
    const glm::vec4 clip = view.projection * view.view * glm::vec4(world, 1.0f);
    if (clip.w <= 0.0f) return std::nullopt;
    return glm::vec2((clip.x / clip.w * 0.5f + 0.5f) * static_cast<float>(extent.width),
                     (clip.y / clip.w * 0.5f + 0.5f) * static_cast<float>(extent.height));
  }
  // Right of the panel (which covers the left of the window), inside the window.
  bool clickable(glm::vec2 p) const {
    return p.x > 360.0f && p.x < static_cast<float>(extent.width) - 4.0f && p.y > 4.0f &&
           p.y < static_cast<float>(extent.height) - 4.0f;
  }
};

struct Report {
  std::vector<glm::vec4> obstacles;  // centre, radius
  std::vector<glm::vec3> floats;     // centres
  struct Sample {
    glm::vec3 position;
    glm::vec3 flow;
  };
  std::vector<Sample> vertices;  // the river's flow per vertex
};

Report read_report(const std::filesystem::path& path) {
  Report report;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    std::string kind;
    float v[6];
    words >> kind >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5];
    if (kind == "obstacle") report.obstacles.push_back({v[0], v[1], v[2], v[3]});
    if (kind == "float") report.floats.push_back({v[0], v[1], v[2]});
    if (kind == "vertex") report.vertices.push_back({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
  }
  return report;
}

// How much the flow near `centre` points across circles round it: the median of
// |flow . radial| / |flow| over the river's vertices between 1.05 and 2 radii (the flow the
// next frame's particles read). Flow round an obstacle is tangent to it (small); open water
// crosses the circles (about 0.7 for a uniform flow).
double median_radial_share(const Report& report, glm::vec3 centre, float radius, size_t* count) {
  std::vector<double> shares;
  for (const Report::Sample& p : report.vertices) {
    const glm::vec2 offset(p.position.x - centre.x, p.position.z - centre.z);
    const float d = glm::length(offset);
    const glm::vec2 flow(p.flow.x, p.flow.z);
    if (d < 1.05f * radius || d > 2.0f * radius || glm::length(flow) < 1e-4f) continue;
    shares.push_back(std::abs(glm::dot(offset / d, flow / glm::length(flow))));
  }
  *count = shares.size();
  if (shares.empty()) return -1.0;
  std::sort(shares.begin(), shares.end());
  return shares[shares.size() / 2];
}

TEST(ViewWindow, Presents90FramesValidationCleanAndShowsTheRiver) {
  const auto dir = fresh_test_dir("window");
  const std::string shot = (dir / "frame.png").string();
  const auto run = run_siviflow("view --frames 90 --size 640x360 --validation --screenshot " + shot,
                                display_env());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("90 frames presented"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("[vulkan error]"), std::string::npos) << run.output;
  Png png;
  ASSERT_TRUE(read_png(shot, &png));
  ASSERT_EQ(png.width, kWidth);
  ASSERT_EQ(png.height, kHeight);
  // Sky at the top right: bright, blue over red. Ground at the bottom right: green leads.
  const glm::vec3 sky = png.at(600, 12);
  EXPECT_GT(sky.b, sky.r + 0.1f) << "sky " << sky.r << " " << sky.g << " " << sky.b;
  EXPECT_GT(sky.b, 0.6f);
  const glm::vec3 ground = png.at(600, 340);
  EXPECT_GT(ground.g, ground.r + 0.1f) << "ground " << ground.r << " " << ground.g << " " << ground.b;
  EXPECT_GT(ground.g, ground.b + 0.1f);
  // Water: the river's middle right of the panel.
  const DefaultScene scene;
  const uint32_t middle = scene.river.mesh.vertices_across / 2;
  int water_probes = 0;
  for (uint32_t s = 0; s < scene.river.mesh.section_count; s += 4) {
    const glm::vec3 p = scene.river.mesh.positions[s * scene.river.mesh.vertices_across + middle];
    const std::optional<glm::vec2> px = scene.pixel(p);
    // The river right of the panel and before the boulders (about x 400 to 470).
    if (!px || !scene.clickable(*px) || px->x > 395.0f) continue;
    const glm::vec3 water = png.at(static_cast<uint32_t>(px->x), static_cast<uint32_t>(px->y));
    // Seen far off it mirrors the green banks, but stays bluer than the ground and than red.
    EXPECT_GT(water.b, ground.b + 0.04f) << "water at " << px->x << "," << px->y;
    EXPECT_GT(water.b, water.r + 0.03f) << "water at " << px->x << "," << px->y;
    EXPECT_LT(water.b, sky.b - 0.2f) << "water at " << px->x << "," << px->y;
    ++water_probes;
  }
  EXPECT_GT(water_probes, 0) << "no river point in view right of the panel";
  // The panel, recorded by Dear ImGui into the same command buffer: its title bar at top left.
  const glm::vec3 title = png.at(60, 8);
  EXPECT_GT(glm::length(title - sky), 0.05f) << "no panel drawn over the frame";
}

TEST(ViewWindow, ResizedTwiceKeepsPresentingAtTheNewSize) {
  const auto dir = fresh_test_dir("window");
  write_text(dir / "resize.txt", "20 resize 800 450\n45 resize 480 270\n");
  const std::string shot = (dir / "frame.png").string();
  const auto run = run_siviflow("view --frames 70 --size 640x360 --validation --screenshot " + shot +
                                    " --input-script " + (dir / "resize.txt").string(),
                                display_env());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("70 frames presented"), std::string::npos) << run.output;
  Png png;
  ASSERT_TRUE(read_png(shot, &png));
  EXPECT_EQ(png.width, 480u);
  EXPECT_EQ(png.height, 270u);
  const glm::vec3 sky = png.at(460, 8);
  EXPECT_GT(sky.b, sky.r + 0.1f) << "the frame at the new size shows the sky";
}

TEST(ViewWindow, DraggedBoulderReroutesTheNextFramesFlow) {
  const auto dir = fresh_test_dir("window");
  const DefaultScene scene;
  const glm::vec3 from = scene.on_water(scene.river.obstacles[0].centre.x, scene.river.obstacles[0].centre.z);
  const float radius = scene.river.obstacles[0].radius;
  // Where to drop it: the river's middle, 7 to 14 m away, far from the other boulder, in view.
  const uint32_t middle = scene.river.mesh.vertices_across / 2;
  std::optional<glm::vec3> to;
  for (uint32_t s = 0; s < scene.river.mesh.section_count && !to; ++s) {
    const glm::vec3 p = scene.river.mesh.positions[s * scene.river.mesh.vertices_across + middle];
    const float d = glm::length(glm::vec2(p.x - from.x, p.z - from.z));
    const glm::vec3 other = scene.river.obstacles[1].centre;
    const std::optional<glm::vec2> px = scene.pixel(p);
    if (d > 7.0f && d < 14.0f && glm::length(glm::vec2(p.x - other.x, p.z - other.z)) > 8.0f &&
        px && scene.clickable(*px)) {
      to = p;
    }
  }
  ASSERT_TRUE(to.has_value()) << "no open water in view to drag the boulder to";
  const std::optional<glm::vec2> a = scene.pixel(from);
  const std::optional<glm::vec2> b = scene.pixel(*to);
  ASSERT_TRUE(a && b && scene.clickable(*a));
  const glm::vec2 halfway = 0.5f * (*a + *b);
  std::ostringstream script;
  script << "5 move " << a->x << " " << a->y << "\n6 press left\n8 move " << halfway.x << " "
         << halfway.y << "\n10 move " << b->x << " " << b->y << "\n12 release left\n";
  write_text(dir / "drag.txt", script.str());

  const auto still = run_siviflow("view --frames 14 --size 640x360 --flow-report " +
                                      (dir / "still.csv").string(), display_env());
  ASSERT_EQ(still.exit_code, 0) << still.output;
  const auto dragged = run_siviflow("view --frames 14 --size 640x360 --validation --flow-report " +
                                        (dir / "dragged.csv").string() + " --input-script " +
                                        (dir / "drag.txt").string(), display_env());
  ASSERT_EQ(dragged.exit_code, 0) << dragged.output;

  const Report before = read_report(dir / "still.csv");
  const Report after = read_report(dir / "dragged.csv");
  ASSERT_EQ(after.obstacles.size(), before.obstacles.size());
  const glm::vec4 moved = after.obstacles[0];
  EXPECT_LT(glm::length(glm::vec2(moved.x - to->x, moved.z - to->z)), 1.0f)
      << "the boulder did not follow the drag: it is at " << moved.x << ", " << moved.z;
  size_t n_new_before = 0, n_new_after = 0, n_old_before = 0, n_old_after = 0;
  const double new_before = median_radial_share(before, *to, radius, &n_new_before);
  const double new_after = median_radial_share(after, *to, radius, &n_new_after);
  const double old_before = median_radial_share(before, from, radius, &n_old_before);
  const double old_after = median_radial_share(after, from, radius, &n_old_after);
  std::printf("radial share at the drop point %.3f -> %.3f (%zu, %zu vertices), at the old "
              "place %.3f -> %.3f (%zu, %zu)\n", new_before, new_after, n_new_before, n_new_after,
              old_before, old_after, n_old_before, n_old_after);
  ASSERT_GE(n_new_after, 3u);
  ASSERT_GE(n_old_after, 3u);
  // The flow now goes round the boulder where it was dropped, and straight on where it was.
  EXPECT_LT(new_after, new_before - 0.15);
  EXPECT_GT(old_after, old_before + 0.15);
}

// F drops a float under the cursor; it drifts downstream with the flow and stays on the water.
TEST(ViewWindow, DroppedFloatDriftsDownstream) {
  const auto dir = fresh_test_dir("window");
  const DefaultScene scene;
  const uint32_t middle = scene.river.mesh.vertices_across / 2;
  const glm::vec3 camera(glm::inverse(scene.view.view)[3]);
  std::optional<glm::vec3> drop;
  std::optional<glm::vec2> px;
  for (uint32_t s = 0; s < scene.river.mesh.section_count && !drop; ++s) {
    const glm::vec3 p = scene.river.mesh.positions[s * scene.river.mesh.vertices_across + middle];
    px = scene.pixel(p);
    bool clear = true;  // of the boulders' footprints, by a margin
    for (const auto& o : scene.river.obstacles) {
      clear = clear && glm::length(glm::vec2(p.x - o.centre.x, p.z - o.centre.z)) > 3.0f * o.radius;
    }
    if (clear && px && scene.clickable(*px) && glm::length(p - camera) > 12.0f) {
      drop = p;
    }
  }
  ASSERT_TRUE(drop.has_value()) << "no open water in view to drop a float on";
  write_text(dir / "drop.txt", "3 move " + std::to_string(px->x) + " " + std::to_string(px->y) +
                                   "\n4 key f\n");
  const auto run = run_siviflow("view --frames 64 --size 640x360 --validation --flow-report " +
                                    (dir / "floats.csv").string() + " --input-script " +
                                    (dir / "drop.txt").string(), display_env());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Report report = read_report(dir / "floats.csv");
  ASSERT_EQ(report.floats.size(), 1u) << "one log dropped";
  const glm::vec3 at = report.floats[0];
  std::printf("dropped at x %.2f, z %.2f; one second later at x %.2f, z %.2f\n", drop->x, drop->z,
              at.x, at.z);
  EXPECT_GT(at.z - drop->z, 0.3f) << "carried downstream (+z)";
  EXPECT_LT(at.z - drop->z, 3.0f) << "no faster than the water";
  EXPECT_LT(std::abs(at.x - drop->x), 1.5f) << "along the flow";
}

TEST(ViewWindow, WithoutADisplayExits1WithAMessage) {
  const auto run = run_siviflow("view --frames 5", "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no display"), std::string::npos) << run.output;
  const auto gone = run_siviflow("view --frames 5", "DISPLAY=:4095 WAYLAND_DISPLAY=");
  EXPECT_EQ(gone.exit_code, 1) << gone.output;
  EXPECT_NE(gone.output.find("cannot open the display"), std::string::npos) << gone.output;
}

TEST(ViewWindow, BadScriptIsRefusedByFileAndLine) {
  const auto dir = fresh_test_dir("window");
  write_text(dir / "bad.txt", "1 move 10 10\n2 jump 3\n");
  const auto run = run_siviflow("view --frames 5 --input-script " + (dir / "bad.txt").string(),
                                display_env());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("bad.txt:2: unknown event 'jump'"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace siviflow
