// The procedural default river: a meandering centreline in the XZ plane (glTF conventions:
// metres, +Y up), a width profile, and the valley terrain with the riverbed it runs in.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "siviflow/status.h"

namespace siviflow {

// An island in the procedural river: an ellipse in the river's own frame (along the flow and
// across it), cut out of the water's mesh and raised as land in the terrain.
struct ProceduralIsland {
  float center_z = 0.0f;  // metres: where along +Z its middle lies
  float offset = 0.0f;    // metres from the centreline across the flow, + towards the left bank
  float length = 30.0f;   // metres along the flow
  float width = 4.0f;     // metres across it
};

// A confluence in the procedural river: two tributaries joining into it, the tongue of land
// between them a wedge from the river's upstream end to its tip. Each tributary keeps its width
// (the river's, split where the tongue lies); above the tip the banks part as the tongue widens.
struct ProceduralConfluence {
  float tip_z = 0.0f;       // metres: where along +Z the tongue ends (the tributaries meet)
  float offset = 0.0f;      // metres from the centreline across the flow, + towards the left bank
                            // (snapped to the mesh's nearest vertex): the left tributary is
                            // width / 2 - offset wide, the right width / 2 + offset
  float angle_deg = 30.0f;  // between the two tributaries, degrees in (0, 120]
};

struct ProceduralRiverParams {
  float length = 240.0f;              // metres along +Z, centred on the origin
  float meander_amplitude = 14.0f;    // metres of lateral swing of the centreline
  float meander_wavelength = 110.0f;  // metres per full meander
  float width = 12.0f;                // mean water width, metres
  float width_variation = 0.25f;      // relative swing of the width along the river
  float depth = 1.6f;                 // riverbed depth below the water surface at the centre
  float bank_height = 1.2f;           // height of the banks above the water
  float valley_half_width = 70.0f;    // distance from the centreline to the valley walls
  float valley_wall_height = 22.0f;   // height the valley walls rise to
  uint32_t seed = 7;
  // The water-surface strip mesh (generate_mesh): sections across the flow, this far apart
  // along the centreline, each with this many vertices from bank to bank.
  float section_spacing = 1.0f;  // metres
  uint32_t vertices_across = 13;
  // Islands, each clear of the banks, the ends and the others by two cells of the mesh (and
  // below the confluence's tip, where there is one).
  std::vector<ProceduralIsland> islands;
  std::optional<ProceduralConfluence> confluence;
};

// An end of the generated river: a vertex in its middle, which way the water crosses it, and
// its width (the rule that shares a discharge among ends of one kind).
struct RiverMeshEnd {
  uint32_t vertex = 0;
  bool inflow = true;
  float width = 0.0f;
};

// The river's water surface as a strip, ready for RiverSurface::build. The river flows along +Z:
// section 0 is at z = -length/2, vertex 0 is its left-bank corner (+X side).
struct RiverMesh {
  // Vertex k * vertices_across + j: section k, j = 0 on the left (in that order, less the
  // vertices inside islands, where the river has any). With a confluence the sections from its
  // tip down come first, then each section above it, its left tributary's vertices before its
  // right's (vertices_across + 1 a section, the tongue's two shores among them).
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;     // triangles, counter-clockwise seen from +Y
  std::vector<float> depth;          // water depth under each vertex, metres, >= 0
  std::vector<float> slope;          // the riverbed's slope under each vertex (rise / run, >= 0)
  uint32_t section_count = 0;
  uint32_t vertices_across = 0;
  // With a confluence, its three ends (the outflow first), for RiverSurfaceOptions::ends; else
  // none (the strip's upstream end holds vertex 0).
  std::vector<RiverMeshEnd> ends;
};

class ProceduralRiver {
 public:
  explicit ProceduralRiver(const ProceduralRiverParams& params);

  const ProceduralRiverParams& params() const { return params_; }

  // X of the centreline at the given Z.
  float centreline_x(float z) const;
  // Water width at the given Z.
  float width_at(float z) const;
  // Signed lateral distance of (x, z) from the centreline, measured across the flow.
  float lateral_distance(float x, float z) const;
  // Height of the terrain (riverbed under the water, banks and valley beyond).
  float terrain_height(float x, float z) const;
  // Height of the water surface (flat for now: the default river is level).
  float water_level() const { return 0.0f; }
  // Water depth at (x, z): water level minus the riverbed, 0 out of the river.
  float depth_at(float x, float z) const;
  // How far (x, z) lies inside the nearest island's ellipse: < 1 inside, 1 on its shore (a large
  // value without islands).
  float island_radius(float x, float z) const;

  // Checks the parameters (ranges, sizes); the message names the parameter.
  static Status validate(const ProceduralRiverParams& params);
  // Builds the water-surface strip following the centreline and width profile, its islands cut
  // out, with the riverbed's depth and slope under each vertex. Fails on bad parameters, when the
  // meander is too tight for the width (sections would cross), or when an island comes within two
  // cells of a bank, an end or another island.
  Status generate_mesh(RiverMesh* out) const;

 private:
  // Double-precision profiles: far from the origin float z loses the centimetres that section
  // placement and the centreline's slope need.
  double centre_x(double z) const;
  double centre_slope(double z) const;  // dx/dz, analytic
  double width(double z) const;
  // What the terrain reads of the centreline at one z: found once for all the points at that z
  // (a vertex and the samples of its slope across the flow), the trigonometry being most of it.
  struct Across {
    double centre_x;
    double slope;  // dx/dz
    float width;
  };
  Across across_at(float z) const { return {centre_x(z), centre_slope(z), width_at(z)}; }
  float lateral_distance(float x, const Across& at) const;
  float terrain_height(float x, float z, const Across& at) const;
  float depth_at(float x, float z, const Across& at) const;
  float island_radius(float x, float z, const Across& at) const;
  // The riverbed's slope at (x, z) by central differences.
  float bed_slope(float x, float z, const Across& at) const;
  // Cuts the islands' quads out of `mesh` (a full grid strip), naming an island too close to a
  // bank, an end or another island.
  Status cut_islands(RiverMesh* mesh) const;

  // With a confluence: the tongue's half-width at z (0 from its tip on), and where its middle
  // lies as a fraction of the half-width from the centreline (+ left).
  double tongue_half_width(double z) const;
  // The tongue's vertex at the tip in a section of `across` vertices.
  static uint32_t tongue_vertex(const ProceduralRiverParams& params, double half_width_at_tip);

  ProceduralRiverParams params_;
  double tongue_fraction_ = 0.0;
  float phase_a_ = 0.0f;  // seeded phases of the two meander harmonics
  float phase_b_ = 0.0f;
  float phase_w_ = 0.0f;  // seeded phase of the width profile
};

}  // namespace siviflow
