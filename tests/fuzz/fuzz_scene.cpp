// The scene file, and then the whole scene it describes up to, not including, the GPU: each
// river's surface and flow as the renderer solves it (obstacles checked as it checks them), the
// glTF objects placed, the ground and beds the world builds, the occluders' ray-cast hierarchy,
// and the floats released and drifted through the flow. Relative paths resolve against the seeds'
// own folder, tests/fuzz/seeds/scene/, so "../gltf/channel.gltf" and the other glTF seeds are
// real files (read, never written); procedural rivers past a size are skipped, to keep each
// input quick.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "river_simulation.h"
#include "scene/default_scene.h"
#include "scene/scene_objects.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_floats.h"
#include "siviflow/scene_river.h"

namespace {

constexpr double kMaxRiverVertices = 20000.0;

bool too_big(const siviflow::SceneRiver& river) {
  if (river.source != siviflow::SceneRiver::Source::kProcedural) return false;
  const siviflow::ProceduralRiverParams& p = river.procedural;
  const double sections = static_cast<double>(p.length) / static_cast<double>(p.section_spacing);
  return !(sections * p.vertices_across <= kMaxRiverVertices);
}

// Everything the renderers and the world would build from `scene`, on the CPU.
void build_scene(const siviflow::SceneFile& scene) {
  std::vector<std::unique_ptr<siviflow::RiverFlow>> flows;
  for (size_t i = 0; i < scene.rivers.size(); ++i) {
    siviflow::SceneRiverData data;
    if (!siviflow::scene_river_data(&scene, i, &data).ok()) return;
    const siviflow::WaterRiver river = data.river();
    siviflow::RiverInput input;
    if (!siviflow::river_input_from(river, {}, &input).ok()) return;
    std::vector<siviflow::Obstacle> obstacles;
    for (size_t k = 0; k < river.obstacles.size(); ++k) {
      if (!siviflow::check_obstacle(river.obstacles[k], k).ok()) return;
      obstacles.push_back(siviflow::flow_obstacle(river.obstacles[k]));
    }
    auto flow = std::make_unique<siviflow::RiverFlow>();
    if (!flow->create(std::move(input), {river.flow.discharge, river.flow.shepard_power,
                                         river.flow.search_radius},
                      std::move(obstacles)).ok()) {
      return;
    }
    flows.push_back(std::move(flow));
  }
  siviflow::SceneObjects objects;
  if (!siviflow::load_scene_objects(scene, &objects).ok()) return;
  siviflow::SceneRiverData shape;
  if (!siviflow::scene_river_shape(&scene, 0, &shape).ok()) return;
  siviflow::SceneGeometry geometry;
  if (shape.procedural) {
    geometry = siviflow::build_scene_geometry(*shape.procedural, scene.obstacles);
  } else if (!siviflow::build_riverbed_geometry(shape.mesh, scene.obstacles, {}, &geometry).ok()) {
    return;
  }
  std::vector<glm::vec3> positions;
  for (const siviflow::SceneVertex& v : geometry.vertices) positions.push_back(v.position);
  for (const siviflow::SceneVertex& v : objects.vertices) positions.push_back(v.position);
  // Every 3 positions a triangle, as far as they go: the hierarchy over all of them.
  (void)flows.front()->set_occluders(std::span(positions).first(positions.size() / 3 * 3), {});
  std::vector<siviflow::WaterQueryFunction> queries;
  for (const auto& flow : flows) {
    queries.push_back([river = flow.get()](std::span<const glm::vec3> p,
                                           std::span<siviflow::WaterSample> s) {
      river->query(p, s);
      return siviflow::Status::success();
    });
  }
  siviflow::SceneFloats floats;
  if (!siviflow::SceneFloats::create(scene, std::move(queries), &floats).ok()) return;
  for (int frame = 1; frame <= 4; ++frame) {
    if (!floats.advance(frame / scene.render.fps).ok()) return;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  siviflow::SceneFile scene;
  if (!siviflow::parse_scene_file(text, "fuzz.json", SIVIFLOW_SCENE_SEEDS, &scene).ok()) return 0;
  for (const siviflow::SceneRiver& river : scene.rivers) {
    if (too_big(river)) return 0;
  }
  build_scene(scene);
  return 0;
}
