#include "siviflow/scene_file.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <new>
#include <unordered_set>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "default_river.h"
#include "scene/gltf_import.h"
#include "scene/look_fields.h"
#include "siviflow/sha256.h"
#include "siviflow/sim/river_tuning.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

using Json = nlohmann::json;

// Thrown from the parse callback only, caught in parse_scene_file.
struct ParseAbort {
  std::string message;
};

// The ProceduralRiverParams fields, by type: the single list the parser and
// procedural_river_keys() use.
struct FloatField {
  const char* name;
  float ProceduralRiverParams::*member;
};
struct UintField {
  const char* name;
  uint32_t ProceduralRiverParams::*member;
};
constexpr FloatField kProceduralFloats[] = {
    {"length", &ProceduralRiverParams::length},
    {"meander_amplitude", &ProceduralRiverParams::meander_amplitude},
    {"meander_wavelength", &ProceduralRiverParams::meander_wavelength},
    {"width", &ProceduralRiverParams::width},
    {"width_variation", &ProceduralRiverParams::width_variation},
    {"depth", &ProceduralRiverParams::depth},
    {"bank_height", &ProceduralRiverParams::bank_height},
    {"valley_half_width", &ProceduralRiverParams::valley_half_width},
    {"valley_wall_height", &ProceduralRiverParams::valley_wall_height},
    {"section_spacing", &ProceduralRiverParams::section_spacing},
};
constexpr UintField kProceduralUints[] = {
    {"seed", &ProceduralRiverParams::seed},
    {"vertices_across", &ProceduralRiverParams::vertices_across},
};

std::string join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string element(const std::string& path, size_t i) { return path + text_format("[%zu]", i); }

class Reader {
 public:
  explicit Reader(const std::string& file) : file_(file) {}

  Status fail(const std::string& path, const std::string& what) const {
    return Status::error(file_ + ": " + path + ": " + what);
  }

  Status object(const Json& v, const std::string& path) const {
    if (!v.is_object()) return fail(path, std::string("must be an object, not ") + v.type_name());
    return Status::success();
  }

  // Every key of the object `v` must be one of `allowed`.
  Status keys(const Json& v, const std::string& path,
              const std::vector<std::string_view>& allowed) const {
    for (const auto& item : v.items()) {
      bool known = false;
      for (const std::string_view a : allowed) known = known || item.key() == a;
      if (!known) {
        std::string list;
        for (const std::string_view a : allowed)
          list += (list.empty() ? "" : ", ") + std::string(a);
        return fail(join(path, item.key()), "unknown key (allowed here: " + list + ")");
      }
    }
    return Status::success();
  }

  Status array(const Json& v, const std::string& path, size_t max_size) const {
    if (!v.is_array()) return fail(path, std::string("must be an array, not ") + v.type_name());
    if (v.size() > max_size) {
      return fail(path,
                  text_format("has %zu elements, more than the limit of %zu", v.size(), max_size));
    }
    return Status::success();
  }

  Status number(const Json& v, const std::string& path, double* out) const {
    if (!v.is_number()) return fail(path, std::string("must be a number, not ") + v.type_name());
    const double d = v.get<double>();
    if (!std::isfinite(d)) return fail(path, "must be a finite number");
    *out = d;
    return Status::success();
  }

  Status real(const Json& v, const std::string& path, float* out) const {
    double d = 0.0;
    SIVIFLOW_TRY(number(v, path, &d));
    if (std::abs(d) > double(std::numeric_limits<float>::max())) {
      return fail(path, text_format("%g is not a finite 32-bit float", d));
    }
    *out = static_cast<float>(d);
    return Status::success();
  }

  Status positive(const Json& v, const std::string& path, float* out) const {
    SIVIFLOW_TRY(real(v, path, out));
    if (!(*out > 0.0f)) return fail(path, text_format("%g must be > 0", double(*out)));
    return Status::success();
  }

  // A non-negative integer <= max (an integral float such as 7.0 is accepted).
  Status integer(const Json& v, const std::string& path, uint64_t max, uint64_t* out) const {
    uint64_t u = 0;
    if (v.is_number_unsigned()) {
      u = v.get<uint64_t>();
    } else if (v.is_number_integer()) {
      return fail(
          path, text_format("%lld must not be negative", static_cast<long long>(v.get<int64_t>())));
    } else if (v.is_number_float()) {
      const double d = v.get<double>();
      if (!(d >= 0.0 && d <= double(max) && std::floor(d) == d)) {
        return fail(path, text_format("%g must be an integer in 0 .. %llu", d,
                                      static_cast<unsigned long long>(max)));
      }
      u = static_cast<uint64_t>(d);
    } else {
      return fail(path, std::string("must be an integer, not ") + v.type_name());
    }
    if (u > max) {
      return fail(path, text_format("%llu is more than the limit of %llu",
                                    static_cast<unsigned long long>(u),
                                    static_cast<unsigned long long>(max)));
    }
    *out = u;
    return Status::success();
  }

  Status uint32(const Json& v, const std::string& path, uint32_t* out) const {
    uint64_t u = 0;
    SIVIFLOW_TRY(integer(v, path, std::numeric_limits<uint32_t>::max(), &u));
    *out = static_cast<uint32_t>(u);
    return Status::success();
  }

  Status boolean(const Json& v, const std::string& path, bool* out) const {
    if (!v.is_boolean())
      return fail(path, std::string("must be true or false, not ") + v.type_name());
    *out = v.get<bool>();
    return Status::success();
  }

  Status string(const Json& v, const std::string& path, std::string* out) const {
    if (!v.is_string()) return fail(path, std::string("must be a string, not ") + v.type_name());
    *out = v.get<std::string>();
    if (out->empty()) return fail(path, "must not be empty");
    return Status::success();
  }

  Status floats(const Json& v, const std::string& path, size_t n, float* out) const {
    if (!v.is_array() || v.size() != n) {
      return fail(path,
                  v.is_array()
                      ? text_format("must be an array of %zu numbers, not %zu", n, v.size())
                      : text_format("must be an array of %zu numbers, not %s", n, v.type_name()));
    }
    for (size_t i = 0; i < n; ++i) SIVIFLOW_TRY(real(v[i], element(path, i), &out[i]));
    return Status::success();
  }

  Status vec3(const Json& v, const std::string& path, glm::vec3* out) const {
    float f[3];
    SIVIFLOW_TRY(floats(v, path, 3, f));
    *out = glm::vec3(f[0], f[1], f[2]);
    return Status::success();
  }

  // Keys must have strictly increasing t.
  Status key_time(const Json& v, const std::string& path, size_t index, double previous,
                  double* t) const {
    SIVIFLOW_TRY(number(v, path, t));
    if (index > 0 && !(*t > previous)) {
      return fail(path, *t == previous
                            ? text_format("two keys at t = %g; times must strictly increase", *t)
                            : text_format("keys are not sorted by t (%g after %g)", *t, previous));
    }
    return Status::success();
  }

  std::string resolve(const std::string& folder, const std::string& file) const {
    const std::filesystem::path p(file);
    return (p.is_absolute() ? p : std::filesystem::path(folder) / p).lexically_normal().string();
  }

 private:
  const std::string& file_;
};

const Json* find(const Json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

Status parse_procedural(const Reader& r, const Json& v, const std::string& path,
                        ProceduralRiverParams* out) {
  SIVIFLOW_TRY(r.object(v, path));
  const std::vector<std::string> names = procedural_river_keys();
  SIVIFLOW_TRY(r.keys(v, path, std::vector<std::string_view>(names.begin(), names.end())));
  ProceduralRiverParams params;
  for (const FloatField& f : kProceduralFloats) {
    if (const Json* x = find(v, f.name))
      SIVIFLOW_TRY(r.real(*x, join(path, f.name), &(params.*f.member)));
  }
  for (const UintField& f : kProceduralUints) {
    if (const Json* x = find(v, f.name))
      SIVIFLOW_TRY(r.uint32(*x, join(path, f.name), &(params.*f.member)));
  }
  if (const Json* islands = find(v, "islands")) {
    const std::string at = join(path, "islands");
    SIVIFLOW_TRY(r.array(*islands, at, kMaxProceduralIslands));
    for (size_t i = 0; i < islands->size(); ++i) {
      const Json& item = (*islands)[i];
      const std::string item_path = element(at, i);
      SIVIFLOW_TRY(r.object(item, item_path));
      SIVIFLOW_TRY(r.keys(item, item_path, {"center_z", "offset", "length", "width"}));
      ProceduralIsland island;
      if (const Json* x = find(item, "center_z")) SIVIFLOW_TRY(r.real(*x, join(item_path, "center_z"), &island.center_z));
      if (const Json* x = find(item, "offset")) SIVIFLOW_TRY(r.real(*x, join(item_path, "offset"), &island.offset));
      if (const Json* x = find(item, "length")) SIVIFLOW_TRY(r.positive(*x, join(item_path, "length"), &island.length));
      if (const Json* x = find(item, "width")) SIVIFLOW_TRY(r.positive(*x, join(item_path, "width"), &island.width));
      params.islands.push_back(island);
    }
  }
  if (const Json* c = find(v, "confluence")) {
    const std::string at = join(path, "confluence");
    SIVIFLOW_TRY(r.object(*c, at));
    SIVIFLOW_TRY(r.keys(*c, at, {"tip_z", "offset", "angle_deg"}));
    ProceduralConfluence confluence;
    if (const Json* x = find(*c, "tip_z")) SIVIFLOW_TRY(r.real(*x, join(at, "tip_z"), &confluence.tip_z));
    if (const Json* x = find(*c, "offset")) SIVIFLOW_TRY(r.real(*x, join(at, "offset"), &confluence.offset));
    if (const Json* x = find(*c, "angle_deg")) SIVIFLOW_TRY(r.positive(*x, join(at, "angle_deg"), &confluence.angle_deg));
    params.confluence = confluence;
  }
  const Status valid = ProceduralRiver::validate(params);
  if (!valid.ok()) {
    std::string message = valid.message();
    constexpr std::string_view kPrefix = "procedural river: ";  // our path already says it
    if (message.rfind(kPrefix, 0) == 0) message.erase(0, kPrefix.size());
    return r.fail(path, message);
  }
  *out = params;
  return Status::success();
}

Status parse_flow(const Reader& r, const Json& v, const std::string& path, FlowParams* out) {
  SIVIFLOW_TRY(r.object(v, path));
  SIVIFLOW_TRY(r.keys(v, path, {"discharge", "p", "search_radius"}));
  if (const Json* x = find(v, "discharge"))
    SIVIFLOW_TRY(r.positive(*x, join(path, "discharge"), &out->discharge));
  if (const Json* x = find(v, "p")) {
    SIVIFLOW_TRY(r.positive(*x, join(path, "p"), &out->p));
    if (out->p > 16.0f)
      return r.fail(join(path, "p"), text_format("%g must be at most 16", double(out->p)));
  }
  if (const Json* x = find(v, "search_radius")) {
    SIVIFLOW_TRY(r.positive(*x, join(path, "search_radius"), &out->search_radius));
  }
  return Status::success();
}

// A river's "ends": each a vertex or a point near it, and an inflow or an outflow of a discharge
// >= 0; together they balance.
Status parse_ends(const Reader& r, const Json& v, const std::string& path,
                  std::vector<SceneRiverEnd>* out) {
  SIVIFLOW_TRY(r.array(v, path, kMaxSceneRiverEnds));
  if (v.size() < 2) return r.fail(path, text_format("%zu ends given: a river has at least two", v.size()));
  std::vector<SceneRiverEnd> ends;
  double in = 0.0, out_sum = 0.0;
  std::string in_list, out_list;
  for (size_t i = 0; i < v.size(); ++i) {
    const Json& item = v[i];
    const std::string at = element(path, i);
    SIVIFLOW_TRY(r.object(item, at));
    SIVIFLOW_TRY(r.keys(item, at, {"vertex", "near", "inflow", "outflow"}));
    SceneRiverEnd end;
    const Json* vertex = find(item, "vertex");
    const Json* near = find(item, "near");
    if ((vertex != nullptr) == (near != nullptr)) {
      return r.fail(at, "needs either 'vertex' (a vertex on the end) or 'near' (a point by it)");
    }
    end.by_vertex = vertex != nullptr;
    if (vertex) SIVIFLOW_TRY(r.uint32(*vertex, join(at, "vertex"), &end.vertex));
    if (near) SIVIFLOW_TRY(r.vec3(*near, join(at, "near"), &end.near));
    const Json* inflow = find(item, "inflow");
    const Json* outflow = find(item, "outflow");
    if ((inflow != nullptr) == (outflow != nullptr)) {
      return r.fail(at, "needs either 'inflow' or 'outflow' (the discharge through it, m^2/s)");
    }
    end.inflow = inflow != nullptr;
    const std::string key = join(at, end.inflow ? "inflow" : "outflow");
    SIVIFLOW_TRY(r.real(end.inflow ? *inflow : *outflow, key, &end.discharge));
    if (end.discharge < 0.0f) {
      return r.fail(key, text_format("%g is negative: a discharge is 0 or more", double(end.discharge)));
    }
    (end.inflow ? in : out_sum) += end.discharge;
    std::string& list = end.inflow ? in_list : out_list;
    list += text_format("%s%g", list.empty() ? "" : " + ", double(end.discharge));
    ends.push_back(end);
  }
  if (std::abs(in - out_sum) > 1e-5 * std::max({in, out_sum, 1e-30})) {
    return r.fail(path, text_format("the ends do not balance: %g m^2/s flows in (%s) and %g "
                                    "m^2/s out (%s)",
                                    in, in_list.empty() ? "none" : in_list.c_str(), out_sum,
                                    out_list.empty() ? "none" : out_list.c_str()));
  }
  if (!(in > 0.0)) return r.fail(path, "no water flows in: the inflows' discharges are all 0");
  *out = std::move(ends);
  return Status::success();
}

// One river at `path`: "river" (its flow from the top-level "flow") or an element of "rivers"
// (which may carry a "flow" of its own, else the top-level one's).
Status parse_river(const Reader& r, const Json& v, const std::string& path,
                   const std::string& folder, bool own_flow, const FlowParams& flow,
                   SceneRiver* out) {
  SIVIFLOW_TRY(r.object(v, path));
  if (own_flow) {
    SIVIFLOW_TRY(r.keys(v, path, {"gltf", "mesh", "procedural", "flow", "ends"}));
  } else {
    SIVIFLOW_TRY(r.keys(v, path, {"gltf", "mesh", "procedural", "ends"}));
  }
  const Json* gltf = find(v, "gltf");
  const Json* mesh = find(v, "mesh");
  const Json* procedural = find(v, "procedural");
  if (gltf && procedural) return r.fail(path, "give either 'gltf' or 'procedural', not both");
  if (!gltf && !procedural) return r.fail(path, "needs 'gltf' (a river mesh file) or 'procedural'");
  SceneRiver river;
  river.flow = flow;
  river.key = path;
  if (gltf) {
    river.source = SceneRiver::Source::kGltf;
    SIVIFLOW_TRY(r.string(*gltf, join(path, "gltf"), &river.gltf));
    river.gltf = r.resolve(folder, river.gltf);
    if (mesh) SIVIFLOW_TRY(r.string(*mesh, join(path, "mesh"), &river.mesh));
  } else {
    if (mesh) return r.fail(join(path, "mesh"), "only goes with 'gltf'");
    river.source = SceneRiver::Source::kProcedural;
    SIVIFLOW_TRY(parse_procedural(r, *procedural, join(path, "procedural"), &river.procedural));
  }
  if (const Json* x = own_flow ? find(v, "flow") : nullptr) {
    SIVIFLOW_TRY(parse_flow(r, *x, join(path, "flow"), &river.flow));
  }
  if (const Json* x = find(v, "ends")) {
    SIVIFLOW_TRY(parse_ends(r, *x, join(path, "ends"), &river.ends));
    river.flow.discharge = 0.0f;  // the inflows bring it
    for (const SceneRiverEnd& end : river.ends) river.flow.discharge += end.inflow ? end.discharge : 0.0f;
  }
  *out = std::move(river);
  return Status::success();
}


// The water's look: every field of WaterLook under its own name, each optional, then the ranges
// the renderer accepts (so a file the parser takes is one the renderer takes).
Status parse_look(const Reader& r, const Json& v, WaterLook* out) {
  SIVIFLOW_TRY(r.object(v, "look"));
  std::vector<std::string_view> allowed{"material"};
  for (const auto& s : kLookScalarFields) allowed.push_back(s.name);
  for (const auto& s : kLookVectorFields) allowed.push_back(s.name);
  SIVIFLOW_TRY(r.keys(v, "look", allowed));
  WaterLook look;
  if (const Json* x = find(v, "material")) {
    std::string name;
    SIVIFLOW_TRY(r.string(*x, "look.material", &name));
    if (!water_material_from_name(name, &look.material)) {
      return r.fail("look.material", "'" + name + "' is not a material (" +
                                         water_material_name(WaterMaterial::kTiledDirectionalFlow) +
                                         " or " + water_material_name(WaterMaterial::kFlowMap) + ")");
    }
  }
  for (const auto& s : kLookScalarFields) {
    if (const Json* x = find(v, s.name)) SIVIFLOW_TRY(r.real(*x, join("look", s.name), &(look.*s.member)));
  }
  for (const auto& s : kLookVectorFields) {
    if (const Json* x = find(v, s.name)) SIVIFLOW_TRY(r.vec3(*x, join("look", s.name), &(look.*s.member)));
  }
  std::string problem;
  const std::string field = water_look_error(look, &problem);
  if (!field.empty()) return r.fail(join("look", field), problem);
  *out = look;
  return Status::success();
}

double cross2(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

// Whether the closed segments ab and cd share a point (touching and collinear overlap count).
bool segments_touch(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
  const auto side = [](glm::dvec2 p, glm::dvec2 q, glm::dvec2 x) {
    const double turn = cross2(q - p, x - p);
    return (turn > 0.0) - (turn < 0.0);
  };
  const auto within = [](glm::dvec2 p, glm::dvec2 q, glm::dvec2 x) {
    return std::min(p.x, q.x) <= x.x && x.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= x.y &&
           x.y <= std::max(p.y, q.y);
  };
  const int d1 = side(a, b, c), d2 = side(a, b, d), d3 = side(c, d, a), d4 = side(c, d, b);
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && within(a, b, c)) || (d2 == 0 && within(a, b, d)) ||
         (d3 == 0 && within(c, d, a)) || (d4 == 0 && within(c, d, b));
}

// Why the closed polygon `p` (>= 3 finite points) is not simple, or empty when it is. Stricter
// than validate_obstacle: hand-typed points that touch or double back are named here too.
std::string polygon_problem(const std::vector<glm::vec2>& p) {
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec2 a(p[i]), b(p[(i + 1) % n]), c(p[(i + 2) % n]);
    if (a == b) {
      return (i + 1) % n == 0
                 ? text_format("point %zu repeats point 0 (the polygon closes by itself: do not "
                               "repeat the first point)", i)
                 : text_format("point %zu repeats point %zu", (i + 1) % n, i);
    }
    if (n > 3 && cross2(b - a, c - b) == 0.0 && glm::dot(b - a, c - b) < 0.0) {
      return text_format("the outline doubles back on itself at point %zu", (i + 1) % n);
    }
  }
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbouring edges share a point
      if (segments_touch(glm::dvec2(p[i]), glm::dvec2(p[(i + 1) % n]), glm::dvec2(p[j]),
                         glm::dvec2(p[(j + 1) % n]))) {
        return text_format("is not a simple polygon: edges %zu and %zu cross or touch", i, j);
      }
    }
  }
  return {};
}

// A footprint polygon: [[x, z], ...] offsets from the centre, >= 3 points, simple, either winding.
Status parse_polygon(const Reader& r, const Json& v, const std::string& path,
                     std::vector<glm::vec2>* out) {
  SIVIFLOW_TRY(r.array(v, path, kMaxPolygonPoints));
  if (v.size() < 3) {
    return r.fail(path,
                  text_format("has %zu points; a footprint polygon needs at least 3", v.size()));
  }
  std::vector<glm::vec2> points(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    float xz[2];
    SIVIFLOW_TRY(r.floats(v[i], element(path, i), 2, xz));
    points[i] = glm::vec2(xz[0], xz[1]);
  }
  if (const std::string problem = polygon_problem(points); !problem.empty())
    return r.fail(path, problem);
  // The sim's own check (zero area, ...); its "obstacle N: " prefix is what our path says.
  Obstacle probe;
  probe.polygon = points;
  const Status valid = validate_obstacle(probe, 0);
  if (!valid.ok()) {
    std::string message = valid.message();
    constexpr std::string_view kPrefix = "obstacle 0: ";
    if (message.rfind(kPrefix, 0) == 0) message.erase(0, kPrefix.size());
    return r.fail(path, message);
  }
  *out = std::move(points);
  return Status::success();
}

Status parse_obstacles(const Reader& r, const Json& v, std::vector<Obstacle>* out) {
  SIVIFLOW_TRY(r.array(v, "obstacles", kMaxObstacles));
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string path = element("obstacles", i);
    const Json& o = v[i];
    SIVIFLOW_TRY(r.object(o, path));
    SIVIFLOW_TRY(r.keys(o, path, {"center", "radius", "polygon", "height", "keys"}));
    Obstacle obstacle;
    const Json* center = find(o, "center");
    const Json* radius = find(o, "radius");
    const Json* polygon = find(o, "polygon");
    if (!center) return r.fail(path, "missing required key 'center'");
    if (radius && polygon) {
      return r.fail(path, "give either 'radius' (a circle) or 'polygon' (a footprint), not both");
    }
    if (!radius && !polygon) {
      return r.fail(path, "needs 'radius' (a circle) or 'polygon' (a footprint of [x, z] points)");
    }
    SIVIFLOW_TRY(r.vec3(*center, join(path, "center"), &obstacle.centre));
    if (radius) SIVIFLOW_TRY(r.positive(*radius, join(path, "radius"), &obstacle.radius));
    if (polygon) SIVIFLOW_TRY(parse_polygon(r, *polygon, join(path, "polygon"), &obstacle.polygon));
    // Without a height, the boulder the world draws for it stands this high.
    obstacle.height = kBoulderHeightRatio * boulder_radius(obstacle);
    if (const Json* height = find(o, "height")) {
      SIVIFLOW_TRY(r.real(*height, join(path, "height"), &obstacle.height));
    }
    if (const Json* keys = find(o, "keys")) {
      const std::string keys_path = join(path, "keys");
      SIVIFLOW_TRY(r.array(*keys, keys_path, kMaxObstacleKeys));
      for (size_t k = 0; k < keys->size(); ++k) {
        const std::string key_path = element(keys_path, k);
        const Json& key = (*keys)[k];
        SIVIFLOW_TRY(r.object(key, key_path));
        SIVIFLOW_TRY(r.keys(key, key_path, {"t", "center"}));
        const Json* t = find(key, "t");
        const Json* c = find(key, "center");
        if (!t || !c) return r.fail(key_path, "needs both 't' and 'center'");
        ObstacleKey parsed;
        SIVIFLOW_TRY(r.key_time(*t, join(key_path, "t"), k, k > 0 ? obstacle.keys.back().t : 0.0,
                                &parsed.t));
        SIVIFLOW_TRY(r.vec3(*c, join(key_path, "center"), &parsed.centre));
        obstacle.keys.push_back(parsed);
      }
    }
    const Status valid = validate_obstacle(obstacle, i);
    if (!valid.ok()) return r.fail(path, valid.message());
    out->push_back(std::move(obstacle));
  }
  return Status::success();
}

Status parse_objects(const Reader& r, const Json& v, const std::string& folder,
                     std::vector<SceneObject>* out) {
  SIVIFLOW_TRY(r.array(v, "objects", kMaxSceneObjects));
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string path = element("objects", i);
    const Json& o = v[i];
    SIVIFLOW_TRY(r.object(o, path));
    SIVIFLOW_TRY(r.keys(o, path, {"gltf", "translation", "rotation", "scale", "obstacle"}));
    SceneObject object;
    const Json* gltf = find(o, "gltf");
    if (!gltf) return r.fail(path, "missing required key 'gltf'");
    SIVIFLOW_TRY(r.string(*gltf, join(path, "gltf"), &object.gltf));
    object.gltf = r.resolve(folder, object.gltf);
    if (const Json* x = find(o, "translation"))
      SIVIFLOW_TRY(r.vec3(*x, join(path, "translation"), &object.translation));
    if (const Json* x = find(o, "rotation")) {
      float q[4];
      SIVIFLOW_TRY(r.floats(*x, join(path, "rotation"), 4, q));
      const glm::quat rotation(q[3], q[0], q[1], q[2]);  // file order x, y, z, w
      const float len = glm::length(rotation);
      if (!(len > 1e-6f) || !std::isfinite(len)) {
        return r.fail(join(path, "rotation"), "must be a non-zero quaternion [x, y, z, w]");
      }
      object.rotation = rotation / len;
    }
    if (const Json* x = find(o, "scale")) {
      SIVIFLOW_TRY(r.vec3(*x, join(path, "scale"), &object.scale));
      if (object.scale.x == 0.0f || object.scale.y == 0.0f || object.scale.z == 0.0f) {
        return r.fail(join(path, "scale"), "every component must be non-zero");
      }
    }
    if (const Json* x = find(o, "obstacle"))
      SIVIFLOW_TRY(r.boolean(*x, join(path, "obstacle"), &object.obstacle));
    out->push_back(std::move(object));
  }
  return Status::success();
}

Status parse_floats(const Reader& r, const Json& v, std::vector<SceneFloat>* out) {
  SIVIFLOW_TRY(r.array(v, "floats", kMaxSceneFloats));
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string path = element("floats", i);
    const Json& o = v[i];
    SIVIFLOW_TRY(r.object(o, path));
    SIVIFLOW_TRY(r.keys(o, path, {"mesh", "release_point", "release_time", "radius", "drag"}));
    FloatMesh mesh = FloatMesh::kLog;
    if (const Json* x = find(o, "mesh")) {
      std::string name;
      SIVIFLOW_TRY(r.string(*x, join(path, "mesh"), &name));
      if (name == "leaf") {
        mesh = FloatMesh::kLeaf;
      } else if (name != "log") {
        return r.fail(join(path, "mesh"), "'" + name + "' is not a float mesh (\"log\" or \"leaf\")");
      }
    }
    SceneFloat parsed = scene_float_defaults(mesh);
    const Json* point = find(o, "release_point");
    if (!point) return r.fail(path, "missing required key 'release_point' ([x, z] on a river)");
    float xz[2];
    SIVIFLOW_TRY(r.floats(*point, join(path, "release_point"), 2, xz));
    parsed.release_point = {xz[0], xz[1]};
    if (const Json* x = find(o, "release_time")) {
      SIVIFLOW_TRY(r.number(*x, join(path, "release_time"), &parsed.release_time));
      if (parsed.release_time < 0.0) {
        return r.fail(join(path, "release_time"),
                      text_format("%g must not be negative", parsed.release_time));
      }
    }
    if (const Json* x = find(o, "radius")) {
      SIVIFLOW_TRY(r.positive(*x, join(path, "radius"), &parsed.radius));
      if (parsed.radius > kMaxFloatRadius) {
        return r.fail(join(path, "radius"), text_format("%g is past the largest float, %g metres",
                                                        double(parsed.radius), double(kMaxFloatRadius)));
      }
    }
    if (const Json* x = find(o, "drag")) {
      SIVIFLOW_TRY(r.real(*x, join(path, "drag"), &parsed.drag));
      if (parsed.drag < 0.0f) {
        return r.fail(join(path, "drag"), text_format("%g must not be negative", double(parsed.drag)));
      }
    }
    out->push_back(parsed);
  }
  return Status::success();
}

Status parse_camera(const Reader& r, const Json& v, SceneCamera* out) {
  SIVIFLOW_TRY(r.object(v, "camera"));
  SIVIFLOW_TRY(r.keys(v, "camera", {"fov_y_deg", "keys"}));
  if (const Json* x = find(v, "fov_y_deg")) {
    SIVIFLOW_TRY(r.positive(*x, "camera.fov_y_deg", &out->fov_y_deg));
    if (!(out->fov_y_deg < 180.0f)) {
      return r.fail("camera.fov_y_deg",
                    text_format("%g must be below 180", double(out->fov_y_deg)));
    }
  }
  if (const Json* keys = find(v, "keys")) {
    SIVIFLOW_TRY(r.array(*keys, "camera.keys", kMaxCameraKeys));
    for (size_t k = 0; k < keys->size(); ++k) {
      const std::string path = element("camera.keys", k);
      const Json& key = (*keys)[k];
      SIVIFLOW_TRY(r.object(key, path));
      SIVIFLOW_TRY(r.keys(key, path, {"t", "position", "target"}));
      const Json* t = find(key, "t");
      const Json* position = find(key, "position");
      const Json* target = find(key, "target");
      if (!t || !position || !target) return r.fail(path, "needs 't', 'position' and 'target'");
      CameraKey parsed;
      SIVIFLOW_TRY(r.key_time(*t, join(path, "t"), k, k > 0 ? out->keys.back().t : 0.0, &parsed.t));
      SIVIFLOW_TRY(r.vec3(*position, join(path, "position"), &parsed.position));
      SIVIFLOW_TRY(r.vec3(*target, join(path, "target"), &parsed.target));
      if (!(glm::length(parsed.target - parsed.position) > 1e-6f)) {
        return r.fail(join(path, "target"),
                      "must differ from position (the view direction is undefined)");
      }
      out->keys.push_back(parsed);
    }
  }
  return Status::success();
}

Status parse_render(const Reader& r, const Json& v, SceneRender* out) {
  SIVIFLOW_TRY(r.object(v, "render"));
  SIVIFLOW_TRY(r.keys(v, "render", {"size", "fps", "seed"}));
  if (const Json* size = find(v, "size")) {
    if (!size->is_array() || size->size() != 2) {
      return r.fail("render.size", "must be an array of 2 integers [width, height]");
    }
    uint64_t wh[2] = {0, 0};
    for (size_t i = 0; i < 2; ++i) {
      const std::string path = element("render.size", i);
      SIVIFLOW_TRY(r.integer((*size)[i], path, kMaxRenderDimension, &wh[i]));
      if (wh[i] == 0) return r.fail(path, "must be at least 1");
    }
    out->width = static_cast<uint32_t>(wh[0]);
    out->height = static_cast<uint32_t>(wh[1]);
  }
  if (const Json* x = find(v, "fps")) {
    SIVIFLOW_TRY(r.number(*x, "render.fps", &out->fps));
    if (!(out->fps > 0.0 && out->fps <= kMaxRenderFps)) {
      return r.fail("render.fps", text_format("%g must be in (0, %g]", out->fps, kMaxRenderFps));
    }
  }
  if (const Json* x = find(v, "seed")) SIVIFLOW_TRY(r.uint32(*x, "render.seed", &out->seed));
  return Status::success();
}

Status parse_root(const Reader& r, const Json& root, const std::string& file,
                  const std::string& folder, SceneFile* out) {
  if (!root.is_object()) {
    return Status::error(file + ": the top level must be a JSON object, not " + root.type_name());
  }
  // The version first: a newer file's new keys should read as "newer version", not "unknown key".
  const Json* version = find(root, "version");
  if (!version)
    return Status::error(file + ": missing required key 'version' (this build reads version 1)");
  uint64_t v = 0;
  SIVIFLOW_TRY(r.integer(*version, "version", std::numeric_limits<uint32_t>::max(), &v));
  if (v != kSceneFileVersion) {
    return r.fail("version",
                  text_format("version %llu is not supported (this build reads version %u)",
                              static_cast<unsigned long long>(v), kSceneFileVersion));
  }
  SIVIFLOW_TRY(
      r.keys(root, "",
             {"$schema", "version", "river", "rivers", "flow", "obstacles", "objects", "floats",
              "camera", "render", "look"}));
  if (const Json* schema = find(root, "$schema"); schema && !schema->is_string()) {
    return r.fail("$schema", "must be a string");
  }
  const Json* river = find(root, "river");
  const Json* rivers = find(root, "rivers");
  if (river && rivers) return r.fail("rivers", "give either 'river' or 'rivers', not both");
  if (!river && !rivers) return Status::error(file + ": missing required key 'river' (or 'rivers')");
  SceneFile scene;
  scene.path = file;
  scene.folder = folder;
  FlowParams flow{kDefaultSceneDischarge, kDefaultShepardPower, 0.0f};
  if (const Json* x = find(root, "flow")) SIVIFLOW_TRY(parse_flow(r, *x, "flow", &flow));
  if (river) {
    scene.rivers.resize(1);
    SIVIFLOW_TRY(parse_river(r, *river, "river", folder, false, flow, &scene.rivers[0]));
  } else {
    SIVIFLOW_TRY(r.array(*rivers, "rivers", kMaxSceneRivers));
    if (rivers->empty()) return r.fail("rivers", "needs at least one river");
    scene.rivers.resize(rivers->size());
    for (size_t i = 0; i < rivers->size(); ++i) {
      SIVIFLOW_TRY(parse_river(r, (*rivers)[i], element("rivers", i), folder, true, flow,
                               &scene.rivers[i]));
    }
  }
  if (const Json* x = find(root, "obstacles"))
    SIVIFLOW_TRY(parse_obstacles(r, *x, &scene.obstacles));
  if (const Json* x = find(root, "objects"))
    SIVIFLOW_TRY(parse_objects(r, *x, folder, &scene.objects));
  if (const Json* x = find(root, "floats")) SIVIFLOW_TRY(parse_floats(r, *x, &scene.floats));
  if (const Json* x = find(root, "camera")) SIVIFLOW_TRY(parse_camera(r, *x, &scene.camera));
  if (const Json* x = find(root, "render")) SIVIFLOW_TRY(parse_render(r, *x, &scene.render));
  if (const Json* x = find(root, "look")) SIVIFLOW_TRY(parse_look(r, *x, &scene.look));
  *out = std::move(scene);
  return Status::success();
}

}  // namespace

// A log floats heavy and long, a leaf small and quick to follow the water.
SceneFloat scene_float_defaults(FloatMesh mesh) {
  SceneFloat f;
  f.mesh = mesh;
  f.radius = mesh == FloatMesh::kLog ? 0.6f : 0.15f;
  f.drag = mesh == FloatMesh::kLog ? 1.5f : 6.0f;
  return f;
}

std::vector<std::string> procedural_river_keys() {
  std::vector<std::string> keys;
  for (const FloatField& f : kProceduralFloats) keys.emplace_back(f.name);
  for (const UintField& f : kProceduralUints) keys.emplace_back(f.name);
  keys.emplace_back("islands");
  keys.emplace_back("confluence");
  return keys;
}

Status parse_scene_file(std::string_view text, const std::string& file, const std::string& folder,
                        SceneFile* out) {
  const Reader reader(file);
  try {
    // The callback refuses duplicate keys (JSON would keep the last silently) and deep nesting
    // (bounded work and memory for hostile input) while parsing.
    std::vector<std::unordered_set<std::string>> open_objects;
    const Json::parser_callback_t guard = [&](int depth, Json::parse_event_t event, Json& value) {
      if (depth > kMaxSceneJsonDepth) {
        throw ParseAbort{text_format("JSON nested deeper than %d levels", kMaxSceneJsonDepth)};
      }
      if (event == Json::parse_event_t::object_start) {
        open_objects.emplace_back();
      } else if (event == Json::parse_event_t::object_end && !open_objects.empty()) {
        open_objects.pop_back();
      } else if (event == Json::parse_event_t::key && !open_objects.empty()) {
        const std::string& key = value.get_ref<const std::string&>();
        if (!open_objects.back().insert(key).second) {
          throw ParseAbort{"duplicate key '" + key + "' (JSON would silently keep the last one)"};
        }
      }
      return true;
    };
    Json root;
    try {
      root = Json::parse(text.begin(), text.end(), guard, /*allow_exceptions=*/true);
    } catch (const Json::exception& e) {  // syntax, and numbers like 1e400 that overflow a double
      return Status::error(file + ": not valid JSON: " + e.what());
    }
    SIVIFLOW_TRY(parse_root(reader, root, file, folder, out));
    out->text_sha256 = sha256_hex(text);
    return Status::success();
  } catch (const ParseAbort& e) {
    return Status::error(file + ": " + e.message);
  } catch (const std::bad_alloc&) {
    return Status::error(file + ": out of memory while parsing");
  } catch (const std::exception& e) {
    return Status::error(file + ": " + e.what());
  }
}

Status load_scene_file(const std::string& path, SceneFile* out) {
  std::string text;
  SIVIFLOW_TRY(read_regular_file(path, kMaxSceneFileBytes, &text));
  std::error_code ec;
  std::filesystem::path folder = std::filesystem::path(path).parent_path();
  folder = std::filesystem::absolute(folder.empty() ? std::filesystem::path(".") : folder, ec);
  if (ec) return Status::error(path + ": cannot resolve the folder of the file: " + ec.message());
  folder = folder.lexically_normal();
  if (!folder.has_filename() && folder.has_parent_path())
    folder = folder.parent_path();  // "dir/" -> "dir"
  return parse_scene_file(text, path, folder.string(), out);
}

}  // namespace siviflow
