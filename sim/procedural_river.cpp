#include "siviflow/sim/procedural_river.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/vec2.hpp>

#include "grid_holes.h"
#include "half_float.h"
#include "siviflow/sim/river_tuning.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr float kSlopeStep = 0.5f;  // metres: finite-difference step of the riverbed slope

}  // namespace

ProceduralRiver::ProceduralRiver(const ProceduralRiverParams& params) : params_(params) {
  // std::mt19937 is specified bit-exactly by the standard, so phases are the same everywhere.
  std::mt19937 rng(params.seed);
  const float two_pi = glm::two_pi<float>();
  phase_a_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
  phase_b_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
  phase_w_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
  if (params.confluence && params.vertices_across >= 2) {
    const uint32_t j = tongue_vertex(params, 0.5 * width(params.confluence->tip_z));
    tongue_fraction_ = 1.0 - 2.0 * double(j) / double(params.vertices_across - 1);
  }
}

uint32_t ProceduralRiver::tongue_vertex(const ProceduralRiverParams& params, double half_width_at_tip) {
  const double across = double(params.vertices_across - 1);
  const double j = std::round(across * (0.5 - 0.5 * double(params.confluence->offset) / half_width_at_tip));
  return static_cast<uint32_t>(std::clamp(j, 0.0, across));
}

double ProceduralRiver::tongue_half_width(double z) const {
  const ProceduralConfluence& c = *params_.confluence;
  const double above = double(c.tip_z) - z;
  return above > 0.0 ? above * std::tan(0.5 * double(c.angle_deg) * glm::pi<double>() / 180.0) : 0.0;
}

double ProceduralRiver::centre_x(double z) const {
  const double k = glm::two_pi<double>() / params_.meander_wavelength;
  // A second, shorter harmonic breaks the regularity of a pure sine.
  return params_.meander_amplitude *
         (0.8 * std::sin(k * z + phase_a_) + 0.2 * std::sin(2.3 * k * z + phase_b_));
}

double ProceduralRiver::centre_slope(double z) const {
  const double k = glm::two_pi<double>() / params_.meander_wavelength;
  return params_.meander_amplitude * k *
         (0.8 * std::cos(k * z + phase_a_) + 0.2 * 2.3 * std::cos(2.3 * k * z + phase_b_));
}

double ProceduralRiver::width(double z) const {
  const double k = glm::two_pi<double>() / (0.7 * params_.meander_wavelength);
  return params_.width * (1.0 + params_.width_variation * std::sin(k * z + phase_w_));
}

float ProceduralRiver::centreline_x(float z) const { return static_cast<float>(centre_x(z)); }

float ProceduralRiver::width_at(float z) const { return static_cast<float>(width(z)); }

float ProceduralRiver::lateral_distance(float x, float z) const {
  return lateral_distance(x, across_at(z));
}

float ProceduralRiver::lateral_distance(float x, const Across& at) const {
  // Project the horizontal offset onto the local normal of the centreline; exact enough while
  // the meander radius is large against the valley width.
  return static_cast<float>((x - at.centre_x) / std::sqrt(1.0 + at.slope * at.slope));
}

float ProceduralRiver::terrain_height(float x, float z) const {
  return terrain_height(x, z, across_at(z));
}

float ProceduralRiver::terrain_height(float x, float z, const Across& at) const {
  float lateral = lateral_distance(x, at);
  const float half_width = 0.5f * at.width;
  const float bank_run = 3.0f;
  // A confluence's tongue: land between the tributaries, the bed rising to it under the water
  // (and to its tip below it); out of it the tributaries' banks lie further out by its width.
  float tongue_shelf = -std::numeric_limits<float>::max();
  if (params_.confluence) {
    // Along the river, where the section through (x, z) crosses the centreline (the mesh's
    // sections are square to it, so off the centreline z runs ahead of it or behind).
    const double along = z + double(lateral) * at.slope / std::sqrt(1.0 + at.slope * at.slope);
    const float middle = half_width * static_cast<float>(tongue_fraction_);
    const float half = static_cast<float>(tongue_half_width(along));
    const float from_middle = lateral - middle;
    const float beyond_tip = std::max(0.0f, static_cast<float>(along) - params_.confluence->tip_z);
    const float outside = std::hypot(std::abs(from_middle) - half, beyond_tip);
    if (beyond_tip == 0.0f && std::abs(from_middle) < half) {
      return params_.bank_height * glm::smoothstep(0.0f, bank_run, half - std::abs(from_middle));
    }
    tongue_shelf = -kConfluenceShelfSlope * outside;
    lateral -= from_middle > 0.0f ? half : -half;
  }
  const float d = std::abs(lateral);
  if (d < half_width) {
    // Riverbed: a smooth bowl from -depth at the centre up to the waterline at the bank.
    const float t = d / half_width;
    const float bed = std::max(-params_.depth * (1.0f - t * t), tongue_shelf);
    if (params_.islands.empty()) return bed;
    // An island: a dome rising to the banks' height, its shore at the waterline, its shelf
    // sloping under the water into the bed.
    const float r = island_radius(x, z, at);
    return std::max(bed, params_.bank_height * (1.0f - r * r));
  }
  // Bank: rises to bank_height over a few metres, then the valley floor climbs to the walls.
  const float bank = params_.bank_height * glm::smoothstep(0.0f, 1.0f, (d - half_width) / bank_run);
  const float s = std::max(0.0f, (d - half_width - bank_run) /
                                     (params_.valley_half_width - half_width - bank_run));
  // The walls steepen to the valley's rim (s = 1), then round over into hills beyond it rather
  // than stopping at a flat top.
  const float beyond = std::max(0.0f, s - 1.0f);
  const float wall = params_.valley_wall_height *
                     (s <= 1.0f ? s * s : 1.0f + 2.0f * beyond / (1.0f + 2.0f * beyond));
  // Gentle undulation so the valley floor is not a perfect extrusion, growing into the hills'
  // own crests and saddles on the rim.
  const float wall_t = std::min(s, 1.0f);
  const float undulation = 0.6f * std::sin(0.11f * x + phase_b_) * std::sin(0.07f * z + phase_a_);
  const float crests = params_.valley_wall_height * 0.3f * glm::smoothstep(0.6f, 1.2f, s) *
                       (std::sin(0.045f * z + phase_a_) * std::sin(0.05f * x + phase_w_) +
                        0.4f * std::sin(0.13f * z + 2.0f * phase_b_));
  return bank + wall + undulation * wall_t + crests;
}

float ProceduralRiver::island_radius(float x, float z) const {
  return island_radius(x, z, across_at(z));
}

float ProceduralRiver::island_radius(float x, float z, const Across& at) const {
  float nearest = std::numeric_limits<float>::max();
  for (const ProceduralIsland& island : params_.islands) {
    const float along = (z - island.center_z) / (0.5f * island.length);
    if (std::abs(along) >= 2.0f) continue;  // the shelf reaches no further
    const float across = (lateral_distance(x, at) - island.offset) / (0.5f * island.width);
    nearest = std::min(nearest, std::sqrt(along * along + across * across));
  }
  return nearest;
}

float ProceduralRiver::depth_at(float x, float z) const { return depth_at(x, z, across_at(z)); }

float ProceduralRiver::depth_at(float x, float z, const Across& at) const {
  return std::max(0.0f, water_level() - terrain_height(x, z, at));
}

float ProceduralRiver::bed_slope(float x, float z, const Across& at) const {
  const float dx = terrain_height(x + kSlopeStep, z, at) - terrain_height(x - kSlopeStep, z, at);
  const float dz = terrain_height(x, z + kSlopeStep) - terrain_height(x, z - kSlopeStep);
  return std::sqrt(dx * dx + dz * dz) / (2.0f * kSlopeStep);
}

Status ProceduralRiver::validate(const ProceduralRiverParams& p) {
  const struct {
    const char* name;
    float value;
    float min;
    bool min_inclusive;
  } ranges[] = {
      {"length", p.length, 0.0f, false},
      {"meander_amplitude", p.meander_amplitude, 0.0f, true},
      {"meander_wavelength", p.meander_wavelength, 0.0f, false},
      {"width", p.width, 0.0f, false},
      {"width_variation", p.width_variation, 0.0f, true},
      {"depth", p.depth, 0.0f, true},
      {"bank_height", p.bank_height, 0.0f, true},
      {"valley_half_width", p.valley_half_width, 0.0f, false},
      {"valley_wall_height", p.valley_wall_height, 0.0f, true},
      {"section_spacing", p.section_spacing, 0.0f, false},
  };
  for (const auto& r : ranges) {
    if (!std::isfinite(r.value) || r.value < r.min || (!r.min_inclusive && r.value == r.min)) {
      return Status::error(text_format("procedural river: %s = %g must be finite and %s %g",
                                       r.name, r.value, r.min_inclusive ? ">=" : ">", r.min));
    }
  }
  if (p.depth > kLargestHalf) {
    return Status::error(text_format(
        "procedural river: depth = %g must be at most 65504 (a river keeps its depth in binary16)",
        p.depth));
  }
  if (p.width_variation >= 1.0f) {
    return Status::error(text_format(
        "procedural river: width_variation = %g must be below 1 (the width would reach zero)",
        p.width_variation));
  }
  const float widest_half = 0.5f * p.width * (1.0f + p.width_variation);
  if (p.valley_half_width <= widest_half + 3.0f) {
    return Status::error(text_format(
        "procedural river: valley_half_width = %g must exceed half the widest water (%g) plus "
        "the 3 m bank",
        p.valley_half_width, widest_half));
  }
  if (p.vertices_across < 2) {
    return Status::error(text_format(
        "procedural river: vertices_across = %u must be at least 2 (one per bank)",
        p.vertices_across));
  }
  if (p.islands.size() > kMaxProceduralIslands) {
    return Status::error(text_format("procedural river: %zu islands, more than the limit of %zu",
                                     p.islands.size(), kMaxProceduralIslands));
  }
  for (size_t i = 0; i < p.islands.size(); ++i) {
    const ProceduralIsland& island = p.islands[i];
    const struct {
      const char* name;
      float value;
      bool positive;
    } fields[] = {{"center_z", island.center_z, false},
                  {"offset", island.offset, false},
                  {"length", island.length, true},
                  {"width", island.width, true}};
    for (const auto& f : fields) {
      if (!std::isfinite(f.value) || (f.positive && !(f.value >= kMinProceduralIslandSize))) {
        return Status::error(text_format(
            "procedural river: islands[%zu].%s = %g must be finite%s", i, f.name, f.value,
            f.positive ? text_format(" and at least %g m", double(kMinProceduralIslandSize)).c_str()
                       : ""));
      }
    }
  }
  if (p.confluence) {
    const ProceduralConfluence& c = *p.confluence;
    for (const auto& [name, value] : {std::pair{"tip_z", c.tip_z}, std::pair{"offset", c.offset}}) {
      if (!std::isfinite(value)) {
        return Status::error(text_format("procedural river: confluence.%s = %g must be finite", name, value));
      }
    }
    if (!(c.angle_deg > 0.0f && c.angle_deg <= 120.0f)) {
      return Status::error(text_format(
          "procedural river: confluence.angle_deg = %g must be in (0, 120]", c.angle_deg));
    }
    if (!(std::abs(c.tip_z) < 0.5f * p.length)) {
      return Status::error(text_format(
          "procedural river: confluence.tip_z = %g lies outside the river (z in (%g, %g))",
          c.tip_z, -0.5 * p.length, 0.5 * p.length));
    }
    const uint32_t j = tongue_vertex(p, 0.5 * p.width * (1.0 - p.width_variation));
    if (p.vertices_across < 5 || j < 2 || j + 3 > p.vertices_across) {
      return Status::error(text_format(
          "procedural river: confluence.offset = %g leaves a tributary under two cells of the %u "
          "vertices across: move it towards the centreline or raise vertices_across",
          c.offset, p.vertices_across));
    }
  }
  // Bound the mesh size before allocating: the centreline's slope is at most 1.26 A k.
  const double k = glm::two_pi<double>() / p.meander_wavelength;
  const double max_slope = 1.26 * p.meander_amplitude * k;
  const double arc_bound = p.length * std::sqrt(1.0 + max_slope * max_slope);
  const double sections = arc_bound / p.section_spacing + 2.0;
  if (sections * p.vertices_across > static_cast<double>(kMaxRiverVertices)) {
    return Status::error(text_format(
        "procedural river: %.0f sections of %u vertices exceed the limit of %zu vertices (raise "
        "section_spacing or lower vertices_across)",
        sections, p.vertices_across, kMaxRiverVertices));
  }
  return Status::success();
}

Status ProceduralRiver::generate_mesh(RiverMesh* out) const {
  SIVIFLOW_TRY(validate(params_));
  const double half_length = 0.5 * params_.length;

  // Arc length of the centreline, sampled finely enough for sub-centimetre section placement.
  const size_t samples = std::clamp<size_t>(
      static_cast<size_t>(params_.length / std::min(0.05f, 0.25f * params_.section_spacing)),
      1024, size_t{1} << 22);
  std::vector<double> arc(samples + 1, 0.0);
  auto z_of = [&](size_t i) { return -half_length + params_.length * double(i) / double(samples); };
  double x_before = centre_x(z_of(0));
  for (size_t i = 1; i <= samples; ++i) {
    const double x = centre_x(z_of(i));
    const double dz = z_of(i) - z_of(i - 1);
    const double dx = x - x_before;
    arc[i] = arc[i - 1] + std::sqrt(dx * dx + dz * dz);
    x_before = x;
  }
  const double total = arc.back();
  const uint32_t section_count =
      std::max<uint32_t>(2, static_cast<uint32_t>(std::lround(total / params_.section_spacing)) + 1);
  const uint32_t across = params_.vertices_across;

  // Every section's frame: where it crosses the centreline, its left (+Y x downstream, in x/z)
  // and its half-width. Sections are perpendicular to the centreline.
  struct Frame {
    double x, z, half_width;
    glm::dvec2 left;
  };
  std::vector<Frame> frames(section_count);
  size_t seg = 1;
  for (uint32_t k = 0; k < section_count; ++k) {
    // The z where the centreline has run k / (S - 1) of its length.
    const double target = total * double(k) / double(section_count - 1);
    while (seg < samples && arc[seg] < target) ++seg;
    const double u = arc[seg] > arc[seg - 1]
                         ? std::clamp((target - arc[seg - 1]) / (arc[seg] - arc[seg - 1]), 0.0, 1.0)
                         : 0.0;
    const double z = z_of(seg - 1) + u * (z_of(seg) - z_of(seg - 1));
    const double slope = centre_slope(z);
    const double norm = std::sqrt(1.0 + slope * slope);
    frames[k] = {centre_x(z), z, 0.5 * width(z), glm::dvec2(1.0 / norm, -slope / norm)};
  }
  // With a confluence the grid starts at the tongue's tip; the sections above it are split.
  uint32_t tip = 0;
  if (params_.confluence) {
    while (tip < section_count && frames[tip].z < double(params_.confluence->tip_z)) ++tip;
    if (tip < 1 || tip + 3 > section_count) {
      return Status::error(text_format(
          "procedural river: confluence.tip_z = %g leaves no room for the tributaries above it or "
          "the river below it (it needs a section above and three below)",
          double(params_.confluence->tip_z)));
    }
  }

  RiverMesh mesh;
  mesh.section_count = section_count - tip;  // the grid's, while islands are cut
  mesh.vertices_across = across;
  const size_t vertex_count = size_t{section_count} * (across + (params_.confluence ? 1 : 0));
  mesh.positions.reserve(vertex_count);
  const float y = water_level();
  auto place = [&](const Frame& f, double offset) {
    mesh.positions.emplace_back(float(f.x + offset * f.left.x), y, float(f.z + offset * f.left.y));
    return static_cast<uint32_t>(mesh.positions.size() - 1);
  };
  // Two triangles per quad between a section (a, left to right) and the next downstream (c),
  // counter-clockwise from +Y; a quad that turns over means the two sections cross, on the
  // inside of a bend tighter than the half-width.
  auto zip = [&](const std::vector<uint32_t>& a, const std::vector<uint32_t>& c, uint32_t k) {
    for (size_t j = 0; j + 1 < a.size(); ++j) {
      for (const auto& [p, q, r] : {std::array{a[j], a[j + 1], c[j]}, std::array{a[j + 1], c[j + 1], c[j]}}) {
        const glm::vec3 e1 = mesh.positions[q] - mesh.positions[p];
        const glm::vec3 e2 = mesh.positions[r] - mesh.positions[p];
        if (!(e1.z * e2.x - e1.x * e2.z > 0.0f)) {
          return Status::error(text_format(
              "procedural river: sections %u and %u cross near z = %g (the meander is too tight "
              "for the width: raise meander_wavelength or section_spacing, or lower "
              "meander_amplitude or width%s)",
              k, k + 1, mesh.positions[a[j]].z,
              params_.confluence ? ", or the confluence's angle_deg, which widens the river above its tip" : ""));
        }
        mesh.indices.insert(mesh.indices.end(), {p, q, r});
      }
    }
    return Status::success();
  };

  std::vector<uint32_t> prev, row;
  for (uint32_t k = tip; k < section_count; ++k) {
    row.clear();
    for (uint32_t j = 0; j < across; ++j) {
      row.push_back(place(frames[k], frames[k].half_width * (1.0 - 2.0 * double(j) / double(across - 1))));
    }
    if (k > tip) SIVIFLOW_TRY(zip(prev, row, k - 1));
    prev = row;
  }
  const glm::vec3 outflow_middle = mesh.positions[prev[across / 2]];
  if (!params_.islands.empty()) SIVIFLOW_TRY(cut_islands(&mesh));
  mesh.section_count = section_count;

  if (params_.confluence) {
    // Above the tip each section has two arms: from the left bank to the tongue, and from the
    // tongue to the right bank, the banks and the tongue's shores parted by its half-width.
    // The tongue's vertex as the terrain has it (the constructor's, from the width at tip_z).
    const uint32_t j_tip = static_cast<uint32_t>(std::lround(0.5 * (1.0 - tongue_fraction_) * double(across - 1)));
    std::vector<uint32_t> prev_left(across), prev_right;
    std::iota(prev_left.begin(), prev_left.end(), 0u);  // the tip's section, first in the grid
    prev_right.assign(prev_left.begin() + j_tip, prev_left.end());
    prev_left.resize(j_tip + 1);
    std::vector<uint32_t> left, right;
    for (uint32_t k = tip; k-- > 0;) {
      const Frame& f = frames[k];
      const double half = tongue_half_width(f.z), middle = f.half_width * tongue_fraction_;
      left.clear();
      right.clear();
      for (uint32_t j = 0; j <= j_tip; ++j) {
        left.push_back(place(f, f.half_width + half - double(j) * (f.half_width - middle) / double(j_tip)));
      }
      const uint32_t right_cells = across - 1 - j_tip;
      for (uint32_t j = 0; j <= right_cells; ++j) {
        right.push_back(place(f, middle - half - double(j) * (middle + f.half_width) / double(right_cells)));
      }
      SIVIFLOW_TRY(zip(left, prev_left, k));
      SIVIFLOW_TRY(zip(right, prev_right, k));
      prev_left = left;
      prev_right = right;
    }
    const uint32_t outflow = static_cast<uint32_t>(
        std::find(mesh.positions.begin(), mesh.positions.end(), outflow_middle) - mesh.positions.begin());
    const Frame& top = frames[0];
    mesh.ends = {{outflow, false, float(2.0 * frames.back().half_width)},
                 {left[j_tip / 2], true, float(top.half_width * (1.0 - tongue_fraction_))},
                 {right[right.size() / 2], true, float(top.half_width * (1.0 + tongue_fraction_))}};
  }
  // Last, once the islands are cut: each vertex's depth and bed slope read the centreline at its
  // z once.
  mesh.depth.resize(mesh.positions.size());
  mesh.slope.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3& p = mesh.positions[v];
    const Across at = across_at(p.z);
    mesh.depth[v] = depth_at(p.x, p.z, at);
    mesh.slope[v] = bed_slope(p.x, p.z, at);
    // Kept in binary16 by the river (sim/half_float.h); `depth` is bounded by validate(), the
    // slope only by the depth over the width.
    if (!(mesh.slope[v] <= kLargestHalf)) {
      return Status::error(text_format(
          "procedural river: the bed's slope at vertex %zu is %g, above 65504, the steepest a "
          "river keeps (make it wider or shallower)",
          v, double(mesh.slope[v])));
    }
  }
  *out = std::move(mesh);
  return Status::success();
}

Status ProceduralRiver::cut_islands(RiverMesh* mesh) const {
  const uint32_t across = mesh->vertices_across, sections = mesh->section_count;
  const auto& pos = mesh->positions;
  // The island whose ellipse holds quad (k, j)'s centre, or -1.
  const auto island_at = [&](uint32_t k, uint32_t j) {
    const uint32_t a = k * across + j;
    const glm::vec3 c = 0.25f * (pos[a] + pos[a + 1] + pos[a + across] + pos[a + across + 1]);
    for (size_t i = 0; i < params_.islands.size(); ++i) {
      const ProceduralIsland& island = params_.islands[i];
      const float along = (c.z - island.center_z) / (0.5f * island.length);
      const float side = (lateral_distance(c.x, c.z) - island.offset) / (0.5f * island.width);
      if (along * along + side * side < 1.0f) return static_cast<int>(i);
    }
    return -1;
  };
  std::vector<int> owner(size_t{sections - 1} * (across - 1));
  std::vector<size_t> quads(params_.islands.size(), 0);
  for (uint32_t k = 0; k + 1 < sections; ++k) {
    for (uint32_t j = 0; j + 1 < across; ++j) {
      const int i = owner[size_t{k} * (across - 1) + j] = island_at(k, j);
      if (i < 0) continue;
      ++quads[size_t(i)];
      // Two cells from a bank or an end: the mesh keeps a whole vertex between them.
      if (j < 2 || j + 4 > across || k < 2 || k + 4 > sections) {
        return Status::error(text_format(
            "procedural river: islands[%d] comes within two cells of the %s near z = %g: move it "
            "or make it smaller",
            i, (j < 2 || j + 4 > across) ? "bank" : "river's end", pos[k * across + j].z));
      }
    }
  }
  for (size_t i = 0; i < quads.size(); ++i) {
    if (quads[i] == 0) {
      return Status::error(text_format(
          "procedural river: islands[%zu] covers no cell of the mesh (at z = %g): it is outside "
          "the river or smaller than a cell",
          i, double(params_.islands[i].center_z)));
    }
  }
  // Two islands at least two cells apart, so neither fills the gap between them when cut.
  for (uint32_t k = 0; k + 1 < sections; ++k) {
    for (uint32_t j = 0; j + 1 < across; ++j) {
      const int a = owner[size_t{k} * (across - 1) + j];
      if (a < 0) continue;
      for (uint32_t l = k; l < std::min(k + 3, sections - 1); ++l) {
        for (uint32_t m = j > 2 ? j - 2 : 0; m < std::min(j + 3, across - 1); ++m) {
          const int b = owner[size_t{l} * (across - 1) + m];
          if (b >= 0 && b != a) {
            return Status::error(text_format(
                "procedural river: islands[%d] and islands[%d] come within two cells of each "
                "other near z = %g: move them apart",
                std::min(a, b), std::max(a, b), pos[k * across + j].z));
          }
        }
      }
    }
  }
  cut_grid_quads(
      across, [&](uint32_t k, uint32_t j) { return owner[size_t{k} * (across - 1) + j] >= 0; },
      &mesh->positions, &mesh->indices);
  return Status::success();
}

}  // namespace siviflow
