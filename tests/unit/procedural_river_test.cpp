// The procedural default river: its profiles (used by the terrain) and its water-surface strip.
#include "siviflow/sim/procedural_river.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "siviflow/sim/river_surface.h"

namespace siviflow {
namespace {

TEST(ProceduralRiver, ProfilesStayInTheirRanges) {
  const ProceduralRiverParams params;
  const ProceduralRiver river(params);
  for (float z = -120.0f; z <= 120.0f; z += 0.5f) {
    EXPECT_LE(std::abs(river.centreline_x(z)), params.meander_amplitude + 1e-4f);
    const float w = river.width_at(z);
    EXPECT_GE(w, params.width * (1.0f - params.width_variation) - 1e-4f);
    EXPECT_LE(w, params.width * (1.0f + params.width_variation) + 1e-4f);
    const float x = river.centreline_x(z);
    EXPECT_NEAR(river.lateral_distance(x, z), 0.0f, 1e-4f);
    EXPECT_NEAR(river.terrain_height(x, z), -params.depth, 1e-4f);  // deepest at the centre
    EXPECT_NEAR(river.depth_at(x, z), params.depth, 1e-4f);
    EXPECT_GT(river.terrain_height(x + params.valley_half_width, z), params.bank_height);
    EXPECT_EQ(river.depth_at(x + w + 4.0f, z), 0.0f);  // well past the bank, even across a slope
  }
}

TEST(ProceduralRiver, MeshFollowsCentrelineAndWidth) {
  ProceduralRiverParams params;
  params.vertices_across = 9;
  const ProceduralRiver river(params);
  RiverMesh mesh;
  ASSERT_TRUE(river.generate_mesh(&mesh).ok());
  ASSERT_EQ(mesh.positions.size(), size_t{mesh.section_count} * 9);
  ASSERT_EQ(mesh.indices.size(), size_t{mesh.section_count - 1} * 8 * 6);
  ASSERT_EQ(mesh.depth.size(), mesh.positions.size());
  // The end sections are centred on the ends of the centreline.
  const size_t last = mesh.positions.size() - 9;
  EXPECT_NEAR(0.5f * (mesh.positions[0].z + mesh.positions[8].z), -0.5f * params.length, 1e-3f);
  EXPECT_NEAR(0.5f * (mesh.positions[last].z + mesh.positions[last + 8].z), 0.5f * params.length, 1e-3f);

  RiverSurface surface;
  const Status status = RiverSurface::build(mesh.positions, mesh.indices, {}, &surface);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(surface.sections().size(), mesh.section_count);
  for (uint32_t k = 0; k < mesh.section_count; ++k) {
    const glm::vec3 mid = surface.sections()[k].midpoint;
    EXPECT_NEAR(mid.x, river.centreline_x(mid.z), 1e-3f) << "section " << k;
    EXPECT_NEAR(surface.sections()[k].width, river.width_at(mid.z), 0.01f * river.width_at(mid.z));
    EXPECT_GT(surface.sections()[k].flow_direction.z, 0.0f);  // flows along +Z
    EXPECT_EQ(surface.vertex(k * 9).bank, Bank::kLeft);
    EXPECT_EQ(surface.vertex(k * 9 + 8).bank, Bank::kRight);
    if (k > 0) {
      const float gap = surface.sections()[k].along - surface.sections()[k - 1].along;
      EXPECT_NEAR(gap, params.section_spacing, 0.05f * params.section_spacing);
    }
  }
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_EQ(mesh.positions[v].y, river.water_level());
    EXPECT_GE(mesh.depth[v], 0.0f);
  }
  // Water is deeper mid-river than at the banks.
  EXPECT_GT(mesh.depth[4], mesh.depth[0]);
  EXPECT_GT(mesh.depth[4], mesh.depth[8]);
}

TEST(ProceduralRiver, AnIslandIsLandCutOutOfTheWater) {
  ProceduralRiverParams params;
  params.vertices_across = 25;
  params.width = 20.0f;
  params.width_variation = 0.0f;
  params.islands = {{10.0f, 2.0f, 30.0f, 6.0f}};
  const ProceduralRiver river(params);
  RiverMesh mesh;
  const Status generated = river.generate_mesh(&mesh);
  ASSERT_TRUE(generated.ok()) << generated.message();
  ASSERT_LT(mesh.positions.size(), size_t{mesh.section_count} * 25);
  ASSERT_EQ(mesh.depth.size(), mesh.positions.size());
  RiverSurface surface;
  const Status status = RiverSurface::build(mesh.positions, mesh.indices, {}, &surface);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(surface.islands().size(), 1u);
  // Land at its middle, a bank's height up; no water vertex inside it; shallow at its shore.
  const float x = river.centreline_x(10.0f) + 2.0f;
  EXPECT_NEAR(river.terrain_height(x, 10.0f), params.bank_height, 0.05f);
  EXPECT_EQ(river.depth_at(x, 10.0f), 0.0f);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_GE(river.island_radius(mesh.positions[v].x, mesh.positions[v].z), 0.8f) << "vertex " << v;
  }
  for (const uint32_t n : surface.island_nodes(0)) {
    EXPECT_LT(mesh.depth[n], 0.35f * params.depth) << "shore vertex " << n;
  }
}

// A confluence: a network of three ends (the generator names them), the tongue land between
// the tributaries, each tributary as wide as its share of the river and water to its shores.
TEST(ProceduralRiver, AConfluenceJoinsTwoTributaries) {
  ProceduralRiverParams params;
  params.vertices_across = 25;
  params.width = 20.0f;
  params.width_variation = 0.0f;
  params.meander_amplitude = 3.0f;  // the banks above the tip part: a gentle meander
  params.confluence = ProceduralConfluence{-40.0f, 2.5f, 30.0f};
  const ProceduralRiver river(params);
  RiverMesh mesh;
  const Status generated = river.generate_mesh(&mesh);
  ASSERT_TRUE(generated.ok()) << generated.message();
  ASSERT_EQ(mesh.depth.size(), mesh.positions.size());
  ASSERT_EQ(mesh.ends.size(), 3u);
  RiverSurfaceOptions options;
  for (const RiverMeshEnd& end : mesh.ends) options.ends.push_back({end.vertex, end.inflow});
  RiverSurface surface;
  const Status status = RiverSurface::build(mesh.positions, mesh.indices, options, &surface);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_TRUE(surface.network());
  EXPECT_FALSE(surface.ends()[0].inflow);
  // The tributaries: 7.5 m on the left (width / 2 - offset), 12.5 m on the right.
  for (const RiverEnd& end : surface.ends()) {
    const float expected = end.inflow ? (mesh.ends[end.mark].width) : 20.0f;
    EXPECT_NEAR(end.width, expected, 0.01f) << "end " << end.mark;
  }
  EXPECT_NEAR(mesh.ends[1].width, 7.5f, 0.01f);
  EXPECT_NEAR(mesh.ends[2].width, 12.5f, 0.01f);
  // 40 m above the tip the tongue is 2 * 40 tan 15 = 21.4 m wide: land in its middle, water in
  // the middle of each tributary beyond it.
  const float z = -80.0f, half = 40.0f * std::tan(15.0f * 3.14159265f / 180.0f);
  const float middle = river.centreline_x(z) + 2.5f;
  EXPECT_GT(river.terrain_height(middle, z), 0.9f * params.bank_height);
  EXPECT_GT(river.depth_at(middle + half + 3.75f, z), 0.5f * params.depth);
  EXPECT_GT(river.depth_at(middle - half - 6.25f, z), 0.5f * params.depth);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_GT(river.terrain_height(mesh.positions[v].x, mesh.positions[v].z), -params.depth - 1e-3f);
    // The terrain takes the meander's sections as approximately square to it: within 2 cm.
    EXPECT_LE(river.terrain_height(mesh.positions[v].x, mesh.positions[v].z), 0.02f) << "vertex " << v << " on land";
  }
}

// Each vertex's depth and bed slope are the terrain's under it, as the public profiles give them
// (the mesh reads the centreline once a vertex, to the same bits): in a strip, around an island
// and at a confluence. Across the bowl of the bed the slope grows from the middle to the banks.
TEST(ProceduralRiver, EveryVertexsDepthAndSlopeAreTheTerrainsUnderIt) {
  ProceduralRiverParams strip, island, confluence;
  strip.vertices_across = 9;
  island.vertices_across = 25;
  island.width = 20.0f;
  island.width_variation = 0.0f;
  island.islands = {{10.0f, 2.0f, 30.0f, 6.0f}};
  confluence.vertices_across = 25;
  confluence.width = 20.0f;
  confluence.meander_amplitude = 3.0f;
  confluence.confluence = ProceduralConfluence{-40.0f, 2.5f, 30.0f};
  for (const ProceduralRiverParams& params : {strip, island, confluence}) {
    const ProceduralRiver river(params);
    RiverMesh mesh;
    ASSERT_TRUE(river.generate_mesh(&mesh).ok());
    ASSERT_EQ(mesh.slope.size(), mesh.positions.size());
    ASSERT_EQ(mesh.depth.size(), mesh.positions.size());
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const float x = mesh.positions[v].x, z = mesh.positions[v].z, h = 0.5f;
      const float dx = river.terrain_height(x + h, z) - river.terrain_height(x - h, z);
      const float dz = river.terrain_height(x, z + h) - river.terrain_height(x, z - h);
      ASSERT_EQ(mesh.slope[v], std::sqrt(dx * dx + dz * dz) / (2.0f * h)) << "vertex " << v;
      ASSERT_EQ(mesh.depth[v], river.depth_at(x, z)) << "vertex " << v;
    }
  }
  RiverMesh mesh;
  ASSERT_TRUE(ProceduralRiver(strip).generate_mesh(&mesh).ok());
  const size_t k = 9 * (mesh.section_count / 2);  // a section halfway down
  EXPECT_LT(mesh.slope[k + 4], 0.5f * mesh.slope[k + 1]);
  EXPECT_LT(mesh.slope[k + 4], 0.5f * mesh.slope[k + 7]);
}

TEST(ProceduralRiver, ABadConfluenceNamesItsParameter) {
  for (const auto& [confluence, key] :
       {std::pair{ProceduralConfluence{0.0f, 0.0f, 0.0f}, "confluence.angle_deg"},
        std::pair{ProceduralConfluence{0.0f, 0.0f, 150.0f}, "confluence.angle_deg"},
        std::pair{ProceduralConfluence{500.0f, 0.0f, 30.0f}, "confluence.tip_z"},
        std::pair{ProceduralConfluence{0.0f, 5.5f, 30.0f}, "confluence.offset"},
        std::pair{ProceduralConfluence{NAN, 0.0f, 30.0f}, "confluence.tip_z"}}) {
    ProceduralRiverParams params;
    params.confluence = confluence;
    const Status status = ProceduralRiver::validate(params);
    ASSERT_FALSE(status.ok()) << key;
    EXPECT_NE(status.message().find(key), std::string::npos) << status.message();
  }
}

TEST(ProceduralRiver, SeedChangesTheRiverDeterministically) {
  ProceduralRiverParams a;
  ProceduralRiverParams b = a;
  b.seed = a.seed + 1;
  RiverMesh ma, ma2, mb;
  ASSERT_TRUE(ProceduralRiver(a).generate_mesh(&ma).ok());
  ASSERT_TRUE(ProceduralRiver(a).generate_mesh(&ma2).ok());
  ASSERT_TRUE(ProceduralRiver(b).generate_mesh(&mb).ok());
  EXPECT_EQ(ma.positions, ma2.positions);
  EXPECT_EQ(ma.indices, ma2.indices);
  EXPECT_NE(ma.positions, mb.positions);
}

TEST(ProceduralRiver, BadParametersNameTheParameter) {
  const std::pair<void (*)(ProceduralRiverParams&), const char*> cases[] = {
      {[](ProceduralRiverParams& p) { p.length = -1.0f; }, "length"},
      {[](ProceduralRiverParams& p) { p.width = NAN; }, "width"},
      {[](ProceduralRiverParams& p) { p.width_variation = 1.0f; }, "width_variation"},
      {[](ProceduralRiverParams& p) { p.section_spacing = 0.0f; }, "section_spacing"},
      {[](ProceduralRiverParams& p) { p.depth = 70000.0f; }, "depth = 70000 must be at most 65504"},
      {[](ProceduralRiverParams& p) {
         p.depth = 60000.0f;
         p.width = 2.0f;
       },
       "the bed's slope at vertex"},
      {[](ProceduralRiverParams& p) { p.vertices_across = 1; }, "vertices_across"},
      {[](ProceduralRiverParams& p) { p.valley_half_width = 5.0f; }, "valley_half_width"},
      {[](ProceduralRiverParams& p) { p.section_spacing = 1e-6f; }, "limit"},
      {[](ProceduralRiverParams& p) { p.islands = {{0.0f, 0.0f, -3.0f, 2.0f}}; }, "islands[0].length"},
      {[](ProceduralRiverParams& p) { p.islands = {{0.0f, 0.0f, 20.0f, 14.0f}}; }, "islands[0] comes within two cells of the bank"},
      {[](ProceduralRiverParams& p) { p.islands = {{118.0f, 0.0f, 20.0f, 3.0f}}; }, "river's end"},
      {[](ProceduralRiverParams& p) { p.islands = {{0.0f, 0.0f, 20.0f, 3.0f}, {16.0f, 0.0f, 20.0f, 3.0f}}; },
       "islands[0] and islands[1]"},
      {[](ProceduralRiverParams& p) { p.islands = {{0.0f, 40.0f, 20.0f, 3.0f}}; }, "covers no cell"},
      {[](ProceduralRiverParams& p) {
         p.meander_amplitude = 40.0f;
         p.meander_wavelength = 60.0f;
         p.width = 20.0f;
       },
       "cross"},
  };
  for (const auto& [edit, part] : cases) {
    ProceduralRiverParams params;
    edit(params);
    RiverMesh mesh;
    const Status status = ProceduralRiver(params).generate_mesh(&mesh);
    ASSERT_FALSE(status.ok()) << part;
    EXPECT_NE(status.message().find(part), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace siviflow
