// `siviflow flow`: the solved field of a scene's river as CSV, from a procedural river and from a
// glTF file, with obstacles at a time; bad input gets exit status 1 and no output file.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "river_network_meshes.h"
#include "run_command.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/text_format.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHeader = "vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet";

struct Row {
  double v[14];
};

std::vector<Row> read_csv(const fs::path& path, std::string* header) {
  std::ifstream file(path);
  std::vector<Row> rows;
  std::getline(file, *header);
  std::string line;
  while (std::getline(file, line)) {
    Row row{};
    std::stringstream cells(line);
    std::string cell;
    for (int i = 0; i < 14 && std::getline(cells, cell, ','); ++i) row.v[i] = std::stod(cell);
    rows.push_back(row);
  }
  return rows;
}

class FlowCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("flow_cli_out");
  }
  fs::path dir_;
};

TEST_F(FlowCliTest, StraightGltfChannelIsUniformAndInAccessorOrder) {
  constexpr int kSections = 30;
  constexpr int kAcross = 9;
  constexpr float kWidth = 8.0f;
  write_channel_gltf(dir_ / "channel.gltf", kSections, kAcross, kWidth, 1.0f);
  write_text(dir_ / "scene.json", R"({"version":1,"river":{"gltf":"channel.gltf","mesh":"River"},
    "flow":{"discharge":12.0,"p":1.0,"search_radius":400.0}})");
  const RunResult r = run_siviflow("flow " + (dir_ / "scene.json").string() + " --out " + (dir_ / "flow.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::string header;
  const std::vector<Row> rows = read_csv(dir_ / "flow.csv", &header);
  EXPECT_EQ(header, kHeader);
  ASSERT_EQ(rows.size(), size_t{kSections} * kAcross);
  const double expected_speed = 12.0 / kWidth;
  for (size_t i = 0; i < rows.size(); ++i) {
    const double* v = rows[i].v;
    EXPECT_EQ(v[0], static_cast<double>(i));
    const int k = static_cast<int>(i) / kAcross;
    const int j = static_cast<int>(i) % kAcross;
    EXPECT_NEAR(v[1], kWidth * 0.5 - kWidth * j / (kAcross - 1), 1e-5) << "row " << i;  // accessor order
    EXPECT_NEAR(v[3], k, 1e-5) << "row " << i;
    EXPECT_EQ(v[4], k) << "section of row " << i;
    EXPECT_EQ(v[5], j == 0 ? -1 : (j == kAcross - 1 ? 1 : 0)) << "bank of row " << i;
    EXPECT_NEAR(v[6], kWidth, 1e-4);
    EXPECT_NEAR(v[7] + v[8], kWidth, 1e-3);
    const double speed = std::sqrt(v[10] * v[10] + v[11] * v[11] + v[12] * v[12]);
    EXPECT_NEAR(speed, expected_speed, 0.01 * expected_speed) << "row " << i;
    EXPECT_GT(v[12], 0.0) << "flow runs downstream (+Z)";
    EXPECT_EQ(v[13], 1.0);
    if (HasFailure()) break;
  }
}

// An island off the middle: --describe names it and its arms, which carry the discharge between
// them, the narrower less; in the CSV its shore (d_left = d_right = 0 off the banks) holds one psi.
TEST_F(FlowCliTest, ProceduralRiverWithAnIslandDescribesItsArms) {
  write_text(dir_ / "scene.json",
             R"({"version":1,"river":{"procedural":{"length":120.0,"width":20.0,"width_variation":0.0,)"
             R"("meander_amplitude":0.0,"vertices_across":21,)"
             R"("islands":[{"center_z":0.0,"offset":3.0,"length":40.0,"width":5.0}]}},"flow":{"discharge":20.0}})");
  const RunResult r = run_siviflow("flow " + (dir_ / "scene.json").string() + " --describe --out " +
                                   (dir_ / "flow.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 island, 3 arms, 0 junctions"), std::string::npos) << r.output;
  const auto discharge_of = [&](const std::string& arm) {
    const size_t at = r.output.find(arm + ": ");
    EXPECT_NE(at, std::string::npos) << arm << " in\n" << r.output;
    return at == std::string::npos ? 0.0 : std::stod(r.output.substr(at + arm.size() + 2));
  };
  const double left = discharge_of("arm from the left bank to island 0");
  const double right = discharge_of("arm from island 0 to the right bank");
  EXPECT_NEAR(left + right, 20.0, 1e-6);
  EXPECT_LT(left, 0.8 * right) << "the island lies towards the left bank (+X)";
  std::string header;
  const std::vector<Row> rows = read_csv(dir_ / "flow.csv", &header);
  size_t shore = 0;
  for (const Row& row : rows) {
    if (row.v[5] != 0 || row.v[7] != 0 || row.v[8] != 0) continue;
    EXPECT_NEAR(row.v[9], right, 1e-6) << "shore vertex " << row.v[0];
    ++shore;
  }
  EXPECT_GT(shore, 20u);
}

// A Y from glTF with its ends named by vertex: --describe finds the network, its ends with their
// discharges and the tongue's psi; in the CSV the tongue holds it. Unbalanced ends, or one named
// by a vertex that is on no end, are refused with the key.
TEST_F(FlowCliTest, GltfConfluenceWithNamedEnds) {
  const test::YMesh y = test::y_channel(4.0f, 24.0f, 16.0f, 10.0f, 0.25f, 0.5f, 8);
  write_river_gltf(dir_ / "y.gltf", y.mesh.positions, y.mesh.indices);
  const auto scene = [&](uint32_t left_vertex, double out) {
    write_text(dir_ / "scene.json",
               text_format(R"({"version":1,"river":{"gltf":"y.gltf","ends":[)"
                           R"({"vertex":%u,"inflow":5.0},{"vertex":%u,"inflow":2.5},{"vertex":%u,"outflow":%g}]}})",
                           left_vertex, y.right_end, y.main_end, out));
    return run_siviflow("flow " + (dir_ / "scene.json").string() + " --describe --out " +
                        (dir_ / "flow.csv").string());
  };
  const RunResult r = scene(y.left_end, 7.5);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* part : {"a network of", "end 0, outflow", "7.5 m^2/s", "end 1, inflow", "tongue 0: psi 2.5",
                           "the left bank: psi 7.5", "0 islands, 3 arms, 1 junction",
                           "arm from the left bank to tongue 0: 5 m^2/s"}) {
    EXPECT_NE(r.output.find(part), std::string::npos) << part << " in\n" << r.output;
  }
  std::string header;
  size_t tongue = 0;
  for (const Row& row : read_csv(dir_ / "flow.csv", &header)) {
    if (row.v[5] != 0 || row.v[7] != 0 || row.v[8] != 0) continue;
    EXPECT_NEAR(row.v[9], 2.5, 1e-6) << "tongue vertex " << row.v[0];
    ++tongue;
  }
  EXPECT_GT(tongue, 40u);

  const RunResult unbalanced = scene(y.left_end, 7.0);
  EXPECT_EQ(unbalanced.exit_code, 1);
  EXPECT_NE(unbalanced.output.find("river.ends: the ends do not balance: 7.5 m^2/s flows in (5 + 2.5) and 7 m^2/s out (7)"),
            std::string::npos) << unbalanced.output;
  const RunResult off_end = scene(5, 7.5);
  EXPECT_EQ(off_end.exit_code, 1);
  EXPECT_NE(off_end.output.find("river.ends[0]: vertex 5 is not on the border"), std::string::npos) << off_end.output;
  EXPECT_NE(off_end.output.find("not on an end"), std::string::npos) << off_end.output;
}

TEST_F(FlowCliTest, ProceduralRiverWithAMovingObstacle) {
  ProceduralRiverParams params;
  params.length = 80.0f;
  params.seed = 3;
  const ProceduralRiver river(params);
  // The obstacle glides down the middle of the river, from z = -30 at t = 0 to z = 30 at t = 2.
  const float x0 = river.centreline_x(-30.0f);
  const float x2 = river.centreline_x(30.0f);
  std::ostringstream scene;
  scene << R"({"version":1,"river":{"procedural":{"length":80.0,"seed":3}},"flow":{"discharge":20.0},)"
        << R"("obstacles":[{"center":[)" << x0 << R"(,0,-30],"radius":1.5,"keys":[{"t":0.0,"center":[)"
        << x0 << R"(,0,-30]},{"t":2.0,"center":[)" << x2 << ",0,30]}]}]}";
  write_text(dir_ / "scene.json", scene.str());
  const fs::path at0 = dir_ / "t0.csv";
  const fs::path at2 = dir_ / "t2.csv";
  ASSERT_EQ(run_siviflow("flow " + (dir_ / "scene.json").string() + " --out " + at0.string()).exit_code, 0);
  ASSERT_EQ(run_siviflow("flow " + (dir_ / "scene.json").string() + " --time 2 --out " + at2.string()).exit_code, 0);
  std::string header;
  const std::vector<Row> rows0 = read_csv(at0, &header);
  const std::vector<Row> rows2 = read_csv(at2, &header);
  ASSERT_EQ(rows0.size(), rows2.size());
  ASSERT_FALSE(rows0.empty());
  size_t dry0 = 0;
  size_t dry2 = 0;
  for (size_t i = 0; i < rows0.size(); ++i) {
    const double* a = rows0[i].v;
    const double* b = rows2[i].v;
    // Banks carry psi = Q on the left and 0 on the right, at any time.
    if (a[5] == -1) {
      EXPECT_NEAR(a[9], 20.0, 1e-9);
    } else if (a[5] == 1) {
      EXPECT_NEAR(a[9], 0.0, 1e-9);
    }
    EXPECT_GE(a[9], -1e-9);
    EXPECT_LE(a[9], 20.0 + 1e-9);
    // A dry vertex lies inside the obstacle where it is at that time, and does not move.
    if (a[13] == 0) {
      ++dry0;
      EXPECT_LT(std::hypot(a[1] - x0, a[3] + 30.0), 1.5 + 1e-3);
      EXPECT_EQ(a[10], 0.0);
      EXPECT_EQ(a[12], 0.0);
    }
    if (b[13] == 0) {
      ++dry2;
      EXPECT_LT(std::hypot(b[1] - x2, b[3] - 30.0), 1.5 + 1e-3);
    }
  }
  EXPECT_GT(dry0, 0u) << "the obstacle in mid-river makes some vertices dry";
  EXPECT_GT(dry2, 0u);
}

// Even-odd point-in-polygon test in the XZ plane.
bool inside_polygon(const std::vector<glm::dvec2>& polygon, glm::dvec2 q) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const glm::dvec2 a = polygon[j], b = polygon[i];
    if ((b.y > q.y) != (a.y > q.y) && q.x < a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y))
      inside = !inside;
  }
  return inside;
}

// The straight test channel of the obstacle tests: 8 m wide along +Z, a vertex every 0.5 m.
constexpr int kObstacleSections = 41;
constexpr int kObstacleAcross = 17;

std::vector<Row> run_flow(const fs::path& dir, const std::string& scene_json) {
  write_text(dir / "scene.json", scene_json);
  const fs::path csv = dir / "flow.csv";
  fs::remove(csv);
  const RunResult r = run_siviflow("flow " + (dir / "scene.json").string() + " --out " + csv.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::string header;
  std::vector<Row> rows = read_csv(csv, &header);
  EXPECT_EQ(rows.size(), size_t{kObstacleSections} * kObstacleAcross);
  return rows;
}

// The box object, scaled, turned 45 degrees about +Y and moved to mid-river, half in the water:
// (local x, z) of a world point, to test against the box's footprint |x|, |z| < 1.
constexpr float kBoxScaleZ = 1.5f;
const glm::dvec2 kBoxCentre(0.25, 10.25);

glm::dvec2 box_local(double x, double z) {
  const double c = std::sqrt(0.5);
  const double dx = x - kBoxCentre.x, dz = z - kBoxCentre.y;
  // Undo the rotation of +45 degrees about +Y (x' = c x + c z, z' = -c x + c z), then the scale.
  return {c * dx - c * dz, (c * dx + c * dz) / kBoxScaleZ};
}

std::string box_object_scene(bool obstacle) {
  std::ostringstream scene;
  const double s = std::sin(0.5 * 0.25 * 3.14159265358979323846);
  const double c = std::cos(0.5 * 0.25 * 3.14159265358979323846);
  scene << R"({"version":1,"river":{"gltf":"channel.gltf"},"flow":{"discharge":8.0},)"
        << R"("objects":[{"gltf":"box.gltf","translation":[)" << kBoxCentre.x << ",-0.3,"
        << kBoxCentre.y << R"(],"rotation":[0,)" << s << ",0," << c << R"(],"scale":[1,1,)"
        << kBoxScaleZ << R"(],"obstacle":)" << (obstacle ? "true" : "false") << "}]}";
  return scene.str();
}

TEST_F(FlowCliTest, ObjectMarkedObstacleDriesItsFootprint) {
  write_channel_gltf(dir_ / "channel.gltf", kObstacleSections, kObstacleAcross, 8.0f, 0.5f);
  write_box_gltf(dir_ / "box.gltf", glm::vec3(1.0f));
  const std::vector<Row> rows = run_flow(dir_, box_object_scene(true));
  size_t dry = 0;
  size_t checked = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const double* v = rows[i].v;
    const glm::dvec2 local = box_local(v[1], v[3]);
    const double edge = std::max(std::abs(local.x), std::abs(local.y));
    if (std::abs(edge - 1.0) < 0.02) continue;  // on the outline: either answer is right
    ++checked;
    const bool inside = edge < 1.0;
    EXPECT_EQ(v[13], inside ? 0.0 : 1.0) << "vertex " << i << " at x " << v[1] << ", z " << v[3];
    if (v[13] == 0.0) {
      ++dry;
      EXPECT_EQ(v[10], 0.0);
      EXPECT_EQ(v[12], 0.0);
    }
  }
  EXPECT_GT(checked, rows.size() - 8);
  EXPECT_GE(dry, 16u) << "the 2 x 3 m footprint covers ~24 vertices of the 0.5 m grid";
}

TEST_F(FlowCliTest, ObjectNotMarkedObstacleLeavesTheRiverWet) {
  write_channel_gltf(dir_ / "channel.gltf", kObstacleSections, kObstacleAcross, 8.0f, 0.5f);
  write_box_gltf(dir_ / "box.gltf", glm::vec3(1.0f));
  const std::vector<Row> rows = run_flow(dir_, box_object_scene(false));
  for (size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].v[13], 1.0) << "vertex " << i;
}

TEST_F(FlowCliTest, ObjectObstacleErrorsNameItsFile) {
  write_channel_gltf(dir_ / "channel.gltf", kObstacleSections, kObstacleAcross, 8.0f, 0.5f);
  write_text(dir_ / "scene.json", R"({"version":1,"river":{"gltf":"channel.gltf"},
    "objects":[{"gltf":"rock.glb","obstacle":true}]})");
  const RunResult missing = run_siviflow("flow " + (dir_ / "scene.json").string() + " --out " +
                                         (dir_ / "flow.csv").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("objects[0]"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("rock.glb"), std::string::npos) << missing.output;
  // A box flattened to a vertical sheet has no footprint: an error, not a silent no-op.
  write_box_gltf(dir_ / "sheet.gltf", glm::vec3(1.0f, 1.0f, 0.0f));
  write_text(dir_ / "scene.json", R"({"version":1,"river":{"gltf":"channel.gltf"},
    "objects":[{"gltf":"sheet.gltf","translation":[0,0,10],"obstacle":true}]})");
  const RunResult flat = run_siviflow("flow " + (dir_ / "scene.json").string() + " --out " +
                                      (dir_ / "flow.csv").string());
  EXPECT_EQ(flat.exit_code, 1);
  EXPECT_NE(flat.output.find("sheet.gltf"), std::string::npos) << flat.output;
  EXPECT_NE(flat.output.find("no area"), std::string::npos) << flat.output;
  EXPECT_FALSE(fs::exists(dir_ / "flow.csv"));
}

TEST_F(FlowCliTest, PolygonObstacleDriesTheVerticesInsideIt) {
  write_channel_gltf(dir_ / "channel.gltf", kObstacleSections, kObstacleAcross, 8.0f, 0.5f);
  // A non-convex L, clockwise seen from +Y, its corners between the grid's vertices.
  const std::vector<glm::dvec2> offsets = {{-1.25, -1.25}, {1.25, -1.25}, {1.25, 0.25},
                                           {0.25, 0.25},   {0.25, 1.25},  {-1.25, 1.25}};
  const glm::dvec2 centre(0.0, 8.0);
  std::ostringstream scene;
  scene << R"({"version":1,"river":{"gltf":"channel.gltf"},"flow":{"discharge":8.0},)"
        << R"("obstacles":[{"center":[)" << centre.x << ",0," << centre.y << R"(],"polygon":[)";
  std::vector<glm::dvec2> world;
  for (size_t i = 0; i < offsets.size(); ++i) {
    scene << (i ? "," : "") << "[" << offsets[i].x << "," << offsets[i].y << "]";
    world.push_back(centre + offsets[i]);
  }
  scene << "]}]}";
  const std::vector<Row> rows = run_flow(dir_, scene.str());
  size_t dry = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const double* v = rows[i].v;
    const bool inside = inside_polygon(world, {v[1], v[3]});
    EXPECT_EQ(v[13], inside ? 0.0 : 1.0) << "vertex " << i << " at x " << v[1] << ", z " << v[3];
    dry += v[13] == 0.0 ? 1 : 0;
  }
  EXPECT_EQ(dry, 5u * 5u - 2u * 2u) << "the L covers a 5 x 5 block of vertices less a 2 x 2 corner";
}

TEST_F(FlowCliTest, BadInputIsAnErrorAndWritesNothing) {
  const std::string out = " --out " + (dir_ / "flow.csv").string();
  const auto expect_error = [&](const RunResult& r, const std::string& needle) {
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << "expected '" << needle << "' in:\n" << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "flow.csv"));
  };
  expect_error(run_siviflow("flow" + out), "a scene file is required");
  expect_error(run_siviflow("flow " + (dir_ / "missing.json").string() + out), "missing.json");
  write_text(dir_ / "unknown.json", R"({"version":1,"river":{"procedural":{}},"flw":{}})");
  expect_error(run_siviflow("flow " + (dir_ / "unknown.json").string() + out), "flw");
  write_text(dir_ / "badgltf.json", R"({"version":1,"river":{"gltf":"nothere.glb"}})");
  expect_error(run_siviflow("flow " + (dir_ / "badgltf.json").string() + out), "nothere.glb");
  write_text(dir_ / "ok.json", R"({"version":1,"river":{"procedural":{"length":40.0}}})");
  expect_error(run_siviflow("flow " + (dir_ / "ok.json").string() + " --time nan" + out), "--time");
  expect_error(run_siviflow("flow " + (dir_ / "ok.json").string()), "--out FILE.csv or --describe is required");
  expect_error(run_siviflow("flow " + (dir_ / "ok.json").string() + " --bogus" + out), "unknown option '--bogus'");
  // A one-section river is not a strip of sections: named, exit 1.
  write_channel_gltf(dir_ / "tiny.gltf", 1, 2, 4.0f, 1.0f);
  write_text(dir_ / "tiny.json", R"({"version":1,"river":{"gltf":"tiny.gltf"}})");
  expect_error(run_siviflow("flow " + (dir_ / "tiny.json").string() + out), "tiny");
}

}  // namespace
}  // namespace siviflow::testing
