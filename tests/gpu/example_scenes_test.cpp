// The example scenes under examples/scenes (installed to share/siviflow/examples/scenes), each
// captured small with the validation layer on: the glTF river shows its water and its flow; the
// two rivers each show their water where that river alone would; the look preset colours the
// water as its "look" says (muddier than the same river without it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_command.h"
#include "siviflow/image_files.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kScenes = fs::path(SIVIFLOW_SOURCE_DIR) / "examples" / "scenes";

Json read_json(const fs::path& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

// Captures frame 0 of `scene` at 160x90 with `aovs` under the validation layer into `out`
// (created), and reads it back.
ExrImage capture(const fs::path& scene, const fs::path& out, const std::string& aovs) {
  fs::create_directories(out);
  const RunResult run = run_siviflow("capture " + scene.string() + " --size 160x90 --aov " + aovs +
                                     " --validation --out " + out.string());
  EXPECT_EQ(run.exit_code, 0) << scene << "\n" << run.output;
  ExrImage image;
  const Status read = read_exr((out / "frame_00000.exr").string(), &image);
  EXPECT_TRUE(read.ok()) << read.message();
  return image;
}

std::vector<bool> water_of(const ExrImage& image) {
  std::vector<bool> water;
  if (const std::vector<float>* mask = image.find("water.A")) {
    for (float m : *mask) water.push_back(m > 0.5f);
  }
  return water;
}

size_t count(const std::vector<bool>& pixels) {
  return static_cast<size_t>(std::count(pixels.begin(), pixels.end(), true));
}

// The mean of |a - b| over R, G and B of the pixels in `where`.
double mean_difference(const ExrImage& a, const ExrImage& b, const std::vector<bool>& where) {
  double sum = 0.0;
  for (const char* channel : {"R", "G", "B"}) {
    const std::vector<float>& pa = *a.find(channel);
    const std::vector<float>& pb = *b.find(channel);
    for (size_t i = 0; i < where.size(); ++i) {
      if (where[i]) sum += std::abs(pa[i] - pb[i]);
    }
  }
  return sum / (3.0 * static_cast<double>(count(where)));
}

TEST(ExampleScenes, GltfRiverShowsItsWaterAndFlow) {
  const fs::path dir = fresh_test_dir("examples");
  const ExrImage image = capture(kScenes / "gltf_river.json", dir, "flow");
  const std::vector<bool> water = water_of(image);
  ASSERT_EQ(water.size(), 160u * 90u);
  EXPECT_GT(count(water), water.size() / 10) << "the river fills a good part of the view (17 %)";
  size_t flowing = 0;
  for (size_t i = 0; i < water.size(); ++i) {
    if (water[i] && (*image.find("flow.Z"))[i] > 0.2f) ++flowing;  // downstream is +Z
  }
  EXPECT_GT(flowing * 10, count(water) * 9) << flowing << " of " << count(water);
}

// Each river of two_rivers.json alone (a scene of its own, same camera) gives the pixels where
// its water is; on those, the two-river frame looks like that river's frame, not like the other's.
TEST(ExampleScenes, TwoRiversEachShowTheirWater) {
  const fs::path dir = fresh_test_dir("examples");
  const Json scene = read_json(kScenes / "two_rivers.json");
  ASSERT_EQ(scene["rivers"].size(), 2u);
  const ExrImage both = capture(kScenes / "two_rivers.json", dir / "both", "depth");
  std::vector<ExrImage> alone;
  std::vector<std::vector<bool>> water;
  for (size_t i = 0; i < 2; ++i) {
    Json one = scene;
    one.erase("rivers");
    Json river = scene["rivers"][i];
    one["flow"] = river["flow"];
    river.erase("flow");
    river["gltf"] = (kScenes / river["gltf"].get<std::string>()).string();
    one["river"] = river;
    const fs::path file = dir / ("river_" + std::to_string(i) + ".json");
    std::ofstream(file) << one.dump();
    alone.push_back(capture(file, dir / ("alone_" + std::to_string(i)), "flow"));
    water.push_back(water_of(alone.back()));
    EXPECT_GT(count(water.back()), water.back().size() / 50) << "river " << i << " in view";
  }
  for (size_t i = 0; i < 2; ++i) {
    const double same = mean_difference(both, alone[i], water[i]);
    const double other = mean_difference(both, alone[1 - i], water[i]);
    // Lavapipe here: 1e-5 against 0.13 (river 0), 0.007 against 0.20 (river 1).
    EXPECT_LT(same, 0.25 * other) << "river " << i << ": " << same << " against " << other;
  }
}

// The mean red over blue of the water's pixels.
double red_over_blue(const ExrImage& image) {
  const std::vector<bool> water = water_of(image);
  double red = 0.0, blue = 0.0;
  for (size_t i = 0; i < water.size(); ++i) {
    if (!water[i]) continue;
    red += (*image.find("R"))[i];
    blue += (*image.find("B"))[i];
  }
  EXPECT_GT(count(water), water.size() / 10);
  return red / blue;
}

TEST(ExampleScenes, LookPresetColoursTheWater) {
  const fs::path dir = fresh_test_dir("examples");
  const Json scene = read_json(kScenes / "muddy_river.json");
  ASSERT_TRUE(scene.contains("look"));
  const ExrImage muddy = capture(kScenes / "muddy_river.json", dir / "muddy", "flow");
  Json plain = scene;
  plain.erase("look");
  std::ofstream(dir / "plain.json") << plain.dump();
  const ExrImage clear = capture(dir / "plain.json", dir / "plain", "flow");
  const double muddy_ratio = red_over_blue(muddy);
  const double clear_ratio = red_over_blue(clear);
  // Lavapipe here: 1.04 against 0.60.
  EXPECT_GT(muddy_ratio, 1.4 * clear_ratio) << muddy_ratio << " against " << clear_ratio;
}

// A scene seen straight down from 90 m above (cx, 0, cz) at 320x180 (screen right +X, down +Z,
// 2.14 px a metre): frame 150 with the flow and foam AOVs, validated.
struct FromAbove {
  ExrImage image;
  std::vector<bool> water;
  double cx = 0.0, cz = 0.0;
  size_t pixel(double x, double z) const {
    const double px_per_m = 90.0 / (90.0 * std::tan(25.0 * M_PI / 180.0));
    const int u = int(std::lround(160.0 + (x - cx) * px_per_m)), v = int(std::lround(90.0 + (z - cz) * px_per_m));
    EXPECT_TRUE(u >= 0 && u < 320 && v >= 0 && v < 180) << "(" << x << ", " << z << ") is out of view";
    return size_t(std::clamp(v, 0, 179)) * 320u + size_t(std::clamp(u, 0, 319));
  }
};

bool capture_from_above(Json scene, double cz, const std::string& name, FromAbove* out, double cx = 0.0) {
  const fs::path dir = fresh_test_dir("examples");
  scene["camera"] = {{"fov_y_deg", 50.0},
                     {"keys", {{{"t", 0.0}, {"position", {cx, 90.0, cz + 0.01}}, {"target", {cx, 0.0, cz}}}}}};
  std::ofstream(dir / (name + ".json")) << scene.dump();
  const RunResult run = run_siviflow("capture " + (dir / (name + ".json")).string() +
                                     " --range 150:151 --size 320x180 --aov flow,foam --validation --out " +
                                     dir.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  if (run.exit_code != 0 || !read_exr((dir / "frame_00150.exr").string(), &out->image).ok()) return false;
  out->water = water_of(out->image);
  out->cx = cx;
  out->cz = cz;
  EXPECT_EQ(out->water.size(), 320u * 180u);
  return out->water.size() == 320u * 180u;
}

// The island scene straightened and seen from 90 m above (screen right +X, down +Z, 2.14 px a
// metre at 320x180): land where the island is, water flowing downstream in both its arms, and foam
// in the island's wake (the water its tail leaves behind) beyond what mid-river carries above it.
TEST(ExampleScenes, IslandPartsTheFlowAndLeavesAWake) {
  Json scene = read_json(kScenes / "island.json");
  Json& procedural = scene["river"]["procedural"];
  ASSERT_EQ(procedural["islands"].size(), 1u);
  procedural["meander_amplitude"] = 0.0;
  const Json island = procedural["islands"][0];
  const double cz = island["center_z"], offset = island["offset"];
  const double half_length = 0.5 * island["length"].get<double>();
  FromAbove view;
  ASSERT_TRUE(capture_from_above(scene, cz, "above", &view));
  const std::vector<bool>& water = view.water;
  const ExrImage& image = view.image;
  const auto pixel = [&](double x, double z) { return view.pixel(x, z); };
  const std::vector<float>& flow_z = *image.find("flow.Z");
  const std::vector<float>& foam = *image.find("foam.Y");
  EXPECT_FALSE(water[pixel(offset, cz)]) << "the island's middle is land";
  for (const double x : {offset + 6.0, offset - 8.0}) {  // the narrow arm and the wide one
    EXPECT_TRUE(water[pixel(x, cz)]) << "x = " << x;
    EXPECT_GT(flow_z[pixel(x, cz)], 0.3f) << "x = " << x << ": downstream is +Z";
  }
  // Mean foam over 3 m across the island's line, 8 m long, just past its tail and above its head.
  const auto mean_foam = [&](double z0, double z1) {
    double sum = 0.0;
    size_t n = 0;
    for (double z = z0; z <= z1; z += 0.25) {
      for (double x = offset - 1.5; x <= offset + 1.5; x += 0.25) {
        if (!water[pixel(x, z)]) continue;
        sum += foam[pixel(x, z)];
        ++n;
      }
    }
    EXPECT_GT(n, 0u);
    return sum / double(std::max<size_t>(n, 1));
  };
  const double wake = mean_foam(cz + half_length + 1.0, cz + half_length + 9.0);
  const double above = mean_foam(cz - half_length - 14.0, cz - half_length - 6.0);
  RecordProperty("foam", std::to_string(wake) + " in the wake, " + std::to_string(above) + " above");
  EXPECT_GT(wake, 0.1) << "above the island " << above;
  EXPECT_GT(wake, 2.0 * above) << "wake " << wake << ", above the island " << above;
}

// The confluence scene straightened and seen from 90 m above its tongue's tip (screen right +X,
// down +Z, 2.14 px a metre at 320x180): land on the tongue, water flowing downstream in both
// tributaries and in the river they make, the wider tributary bringing the more.
TEST(ExampleScenes, ConfluenceJoinsTwoTributaries) {
  Json scene = read_json(kScenes / "confluence.json");
  Json& procedural = scene["river"]["procedural"];
  procedural["meander_amplitude"] = 0.0;
  const double tip = procedural["confluence"]["tip_z"], offset = procedural["confluence"]["offset"];
  FromAbove view;
  ASSERT_TRUE(capture_from_above(scene, tip, "junction", &view));
  const std::vector<bool>& water = view.water;
  const ExrImage& image = view.image;
  const auto pixel = [&](double x, double z) { return view.pixel(x, z); };
  const std::vector<float>& flow_x = *image.find("flow.X");
  const std::vector<float>& flow_z = *image.find("flow.Z");
  // 12 m above the tip the tongue (30 degrees) is 6.4 m wide about the offset; each tributary
  // lies beyond it, the left (+X) one width / 2 - offset = 9 m wide, the right 15 m.
  EXPECT_FALSE(water[pixel(offset, tip - 12.0)]) << "the tongue is land";
  const double half = 12.0 * std::tan(15.0 * M_PI / 180.0);
  for (const auto& [x, z] : {std::pair{offset + half + 4.5, tip - 12.0}, std::pair{offset - half - 7.5, tip - 12.0},
                             std::pair{0.0, tip + 12.0}}) {
    EXPECT_TRUE(water[pixel(x, z)]) << "(" << x << ", " << z << ")";
    EXPECT_GT(flow_z[pixel(x, z)], 0.3f) << "(" << x << ", " << z << "): downstream is +Z";
  }
  // Each tributary runs towards the junction: the left one (+X) towards -X, the right towards +X.
  EXPECT_LT(flow_x[pixel(offset + half + 4.5, tip - 12.0)], 0.0f);
  EXPECT_GT(flow_x[pixel(offset - half - 7.5, tip - 12.0)], 0.0f);
}

// The glTF fork seen from above where it parts: an island in mid-river above, water flowing
// downstream (+Z) in both arms, the left arm (12 m^2/s of its ends' 18) about twice as fast as the
// right (6), both 6 m wide.
TEST(ExampleScenes, GltfForkPartsTheFlowAsItsEndsSay) {
  Json scene = read_json(kScenes / "gltf_fork.json");
  scene["river"]["gltf"] = (kScenes / scene["river"]["gltf"].get<std::string>()).string();
  FromAbove view;
  ASSERT_TRUE(capture_from_above(scene, 0.0, "fork", &view, -60.0));
  const auto pixel = [&](double x, double z) { return view.pixel(x, z); };
  const std::vector<float>& flow_z = *view.image.find("flow.Z");
  EXPECT_FALSE(view.water[pixel(-60.0, -30.0)]) << "the island";
  EXPECT_FALSE(view.water[pixel(-60.0, 16.0)]) << "the land between the arms";
  // Mid-arm, 16 m past the fork: each arm is 6 m wide, drawn apart 4 m either side.
  const float left = flow_z[pixel(-60.0 + 4.0 + 3.0, 16.0)], right = flow_z[pixel(-60.0 - 4.0 - 3.0, 16.0)];
  EXPECT_TRUE(view.water[pixel(-53.0, 16.0)] && view.water[pixel(-67.0, 16.0)]);
  EXPECT_GT(right, 0.3f);
  EXPECT_NEAR(left / right, 2.0, 0.3) << "left " << left << ", right " << right;
}

}  // namespace
}  // namespace siviflow::testing
