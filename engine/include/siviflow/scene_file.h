// The scene file, version 1: JSON that says which river to simulate, how it flows, what stands in
// it, where the camera goes and how to render. Its JSON Schema (draft 2020-12) is
// engine/scene/scene.schema.json; keep the two in step.
//
//   { "$schema": "...",                                   optional, ignored (for editors)
//     "version": 1,                                       required, must be 1
//     "river": { "gltf": "river.glb", "mesh": "River" }   required: a glTF river (mesh optional:
//            | { "procedural": { ...params..., "seed": 7 } }        first mesh), or the generator
//     | "rivers": [ { ...as "river"..., "flow": {...} }, ... ]     or several, each with its flow
//     "flow":      { "discharge": 20.0, "p": 1.5, "search_radius": 30.0 },   "river"'s flow, and
//                                                  the default of "rivers" without their own
//     "obstacles": [ { "center": [x,y,z], "radius": 1.5,            a circle, or a footprint:
//                      | "polygon": [[x,z], [x,z], [x,z], ...],      offsets around center
//                      "height": 1.4,                                above center
//                      "keys": [ { "t": 0.0, "center": [..] } ] } ],
//     "objects":   [ { "gltf": "duck.glb", "translation": [..], "rotation": [x,y,z,w],
//                      "scale": [..], "obstacle": true } ],
//     "floats":    [ { "mesh": "log" | "leaf", "release_point": [x, z], "release_time": 2.0,
//                      "radius": 0.6, "drag": 1.5 } ],
//     "camera":    { "fov_y_deg": 50, "keys": [ { "t": 0.0, "position": [..], "target": [..] } ] },
//     "render":    { "size": [1280, 720], "fps": 30, "seed": 1 },
//     "look":      { "water_color": [r,g,b], "absorption_per_metre": 1.4, ... } }   WaterLook
//
// Defaults of everything optional (metres, seconds, degrees; glTF axes: +Y up):
//   river.mesh              first mesh of the file
//   river.procedural.*      each field of ProceduralRiverParams (siviflow/sim/procedural_river.h)
//                           is optional with that struct's default; see procedural_river_keys()
//   flow.discharge          kDefaultSceneDischarge (20 m^2/s)
//   flow.p                  kDefaultShepardPower (1.5)
//   flow.search_radius      absent: 3 x the widest section (FlowParams::search_radius = 0)
//   obstacles               none; keys: none (the obstacle stays at `center`)
//   obstacles[].radius | polygon   exactly one is required. polygon: 3 .. kMaxPolygonPoints
//                           [x, z] offsets in metres from `center` in the XZ plane, either
//                           winding, convex or not, but simple (no crossing or touching edges,
//                           no repeated points; the outline closes by itself)
//   obstacles[].height      0.95 of the footprint's reach from `center` (the boulder drawn for
//                           it): how far it stands above `center`, hiding the water behind it
//   objects[] obstacle      its height: the top of its transformed mesh
//   objects[].translation   [0, 0, 0];  rotation [0, 0, 0, 1] (normalised on load);
//   objects[].scale         [1, 1, 1];  obstacle false. An obstacle object is static (no keys):
//                           its footprint is the XZ convex hull of its transformed mesh where it
//                           dips below the water (see scene_river.h)
//   floats                  none. mesh "log"; release_time 0 (>= 0); radius 0.6 for a log, 0.15
//                           for a leaf (half its length, in (0, kMaxFloatRadius]); drag 1.5 for a log, 6 for a leaf
//                           (1/s, >= 0; siviflow/drift.h). The release point must lie on a
//                           river: captures refuse the scene otherwise (scene_floats.h)
//   camera.fov_y_deg        kDefaultCameraFovYDeg (50)
//   camera.keys             none: the built-in camera that glides down the river
//   render.size             [1280, 720];  fps 30;  seed 1
//   look.*                  each field of WaterLook (siviflow/water_look.h), by its name, with
//                           that struct's default and range
//
// Rules: unknown keys and duplicate keys are errors; numbers must be finite; key lists are
// strictly increasing in t; `gltf` paths are relative to the scene file's folder (absolute paths
// are kept). Every error message is "<file>: <json path>: <what is wrong>", e.g.
// "scene.json: obstacles[1].keys[2].t: keys are not sorted by t (1.5 after 2)".
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "siviflow/sim/obstacle.h"
#include "siviflow/sim/procedural_river.h"
#include "siviflow/sim/stream_function.h"
#include "siviflow/status.h"
#include "siviflow/water_look.h"

namespace siviflow {

// --- Limits and defaults of the scene file, in one place ---------------------------------------
inline constexpr uint32_t kSceneFileVersion = 1;
inline constexpr size_t kMaxSceneFileBytes = size_t{16} << 20;  // hand-written JSON is tiny
inline constexpr int kMaxSceneJsonDepth = 64;  // the format nests 5 levels; deeper is hostile
inline constexpr uint32_t kMaxRenderDimension = 16384;  // maxImageDimension2D of common devices
inline constexpr double kMaxRenderFps = 1000.0;
inline constexpr size_t kMaxSceneObjects = 4096;
inline constexpr size_t kMaxSceneRivers = 64;
inline constexpr size_t kMaxSceneFloats = 4096;
inline constexpr float kMaxFloatRadius = 50.0f;  // metres: a raft, a fallen tree; not an island
inline constexpr size_t kMaxCameraKeys = size_t{1} << 20;
inline constexpr float kDefaultSceneDischarge = 20.0f;  // m^2/s: ~1.7 m/s in the default 12 m river
inline constexpr float kDefaultCameraFovYDeg = 50.0f;
inline constexpr uint32_t kDefaultRenderWidth = 1280;
inline constexpr uint32_t kDefaultRenderHeight = 720;
inline constexpr double kDefaultRenderFps = 30.0;
inline constexpr uint32_t kDefaultRenderSeed = 1;

// One end of a scene's river: a vertex on it, or the point it is nearest, and the discharge
// through it.
struct SceneRiverEnd {
  bool by_vertex = true;
  uint32_t vertex = 0;      // by_vertex: the river mesh's vertex
  glm::vec3 near{0.0f};     // else: the end nearest this point
  bool inflow = true;
  float discharge = 0.0f;   // m^2/s, >= 0
};
inline constexpr size_t kMaxSceneRiverEnds = 256;

struct SceneRiver {
  enum class Source : uint8_t { kProcedural, kGltf };
  Source source = Source::kProcedural;
  std::string gltf;                  // kGltf: the file, resolved against the scene's folder
  std::string mesh;                  // kGltf: mesh name; empty: the first mesh
  ProceduralRiverParams procedural;  // kProcedural: the generator's parameters
  FlowParams flow{kDefaultSceneDischarge, kDefaultShepardPower, 0.0f};  // its own flow
  // Every end with its discharge (flow.discharge is then their inflows' sum), or none.
  std::vector<SceneRiverEnd> ends;
  std::string key = "river";  // where the file gives it: "river" or "rivers[i]", for messages
};

struct SceneObject {
  std::string gltf;  // resolved against the scene's folder
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // unit; the file writes it x, y, z, w as glTF does
  glm::vec3 scale{1.0f};                       // every component non-zero
  bool obstacle = false;                       // its footprint on the water plane cuts the river
};

// A floating body the scene releases onto the water: the hosts drift it with siviflow/drift.h
// and the world draws it (a built-in mesh, modelled along +x, turned to where it drifts).
enum class FloatMesh : uint8_t { kLog, kLeaf };

struct SceneFloat {
  FloatMesh mesh = FloatMesh::kLog;
  glm::vec2 release_point{0.0f};  // [x, z], metres: it starts on the water surface there
  double release_time = 0.0;      // seconds, >= 0: absent before
  float radius = 0.6f;            // metres, (0, kMaxFloatRadius]: half its length
  float drag = 1.5f;              // 1/s, >= 0: how fast it takes the water's velocity
};

struct CameraKey {
  double t = 0.0;  // seconds
  glm::vec3 position{0.0f};
  glm::vec3 target{0.0f};  // differs from position
};

struct SceneCamera {
  float fov_y_deg = kDefaultCameraFovYDeg;  // in (0, 180)
  std::vector<CameraKey> keys;  // strictly increasing t; empty: the built-in river camera
};

struct SceneRender {
  uint32_t width = kDefaultRenderWidth;  // 1 .. kMaxRenderDimension
  uint32_t height = kDefaultRenderHeight;
  double fps = kDefaultRenderFps;  // (0, kMaxRenderFps]
  uint32_t seed = kDefaultRenderSeed;
};

struct SceneFile {
  std::string path;    // the file as given
  std::string text_sha256;  // SHA-256 (hex) of the text it was parsed from: what captures record
  std::string folder;  // absolute folder that relative paths were resolved against
  std::vector<SceneRiver> rivers{1};  // at least one; each with its own flow
  std::vector<Obstacle> obstacles;  // in every river they touch  // circles (radius > 0) or polygons, keys optional
  std::vector<SceneObject> objects;
  std::vector<SceneFloat> floats;
  SceneCamera camera;
  SceneRender render;
  WaterLook look;  // the water's starting look (Renderer::set_look() changes it at runtime)
};

// Reads and checks a scene file (regular file, at most kMaxSceneFileBytes). `out` is left
// untouched on failure. Does not open the glTF files it names.
Status load_scene_file(const std::string& path, SceneFile* out);

// The same from text already in memory: `file` names it in messages and `folder` is what
// relative paths are resolved against (for tests and fuzzing).
Status parse_scene_file(std::string_view text, const std::string& file, const std::string& folder,
                        SceneFile* out);

// A float of `mesh` with its defaults: a log 0.6 m radius, drag 1.5; a leaf 0.15 m, drag 6.
SceneFloat scene_float_defaults(FloatMesh mesh);

// The keys `river.procedural` accepts: the fields of ProceduralRiverParams.
std::vector<std::string> procedural_river_keys();

}  // namespace siviflow
