// Google Benchmark of the river simulation core: surface build, full solve and an obstacle move
// on procedural rivers of 10k to 4M vertices (issue 3, "Speed"), the foam after a move and the
// ray-cast hierarchy's build.
#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "siviflow/sim/procedural_river.h"
#include "siviflow/sim/river_surface.h"
#include "siviflow/sim/stream_function.h"
#include "sim/foam.h"
#include "sim/grid_holes.h"
#include "sim/triangle_bvh.h"
#include "unit/foam_inputs.h"
#include "unit/river_network_meshes.h"

namespace siviflow {
namespace {

constexpr uint32_t kAcross = 41;

// A procedural river of about `vertices` vertices: 41 across, sections 0.3 m apart.
const RiverMesh& river_mesh(int64_t vertices) {
  static std::map<int64_t, std::unique_ptr<RiverMesh>> cache;
  auto& slot = cache[vertices];
  if (!slot) {
    ProceduralRiverParams params;
    params.vertices_across = kAcross;
    params.section_spacing = 0.3f;
    // Length along Z such that the arc length gives the wanted section count.
    const double sections = double(vertices) / kAcross;
    params.length = float(sections * params.section_spacing / 1.07);
    slot = std::make_unique<RiverMesh>();
    if (!ProceduralRiver(params).generate_mesh(slot.get()).ok()) slot->positions.clear();
  }
  return *slot;
}

StreamFunction make_flow(const RiverMesh& mesh) {
  RiverSurface surface;
  StreamFunction flow;
  if (!RiverSurface::build(mesh.positions, mesh.indices, {}, &surface).ok() ||
      !StreamFunction::create(std::move(surface), {20.0f, 1.5f, 0.0f}, &flow).ok()) {
    std::abort();
  }
  return flow;
}

// The river above with ten islands cut out along it, alternately left and right of the middle:
// each 9 quads across (of 40) and 80 sections (24 m) long.
const RiverMesh& river_with_islands(int64_t vertices) {
  static std::map<int64_t, std::unique_ptr<RiverMesh>> cache;
  auto& slot = cache[vertices];
  if (!slot) {
    slot = std::make_unique<RiverMesh>(river_mesh(vertices));
    const double sections = double(slot->section_count);
    cut_grid_quads(
        kAcross,
        [&](uint32_t k, uint32_t j) {
          const int island = int(double(k) * 10.0 / sections);
          const double dk = (double(k) + 0.5 - (island + 0.5) * sections / 10.0) / 40.0;
          const double dj = (double(j) + 0.5 - (island % 2 == 0 ? 16.0 : 24.0)) / 4.5;
          return dk * dk + dj * dj < 1.0;
        },
        &slot->positions, &slot->indices, &slot->depth);
    slot->slope.clear();  // the cut compacts the depth only: the slope, stale, is not read here
  }
  return *slot;
}

// A network of about 100k vertices with four ends: three arms of 13 quads across (240 m)
// joining into a channel of 40 (525 m), 0.3 m rows, ten islands cut from the channel as above.
struct Network {
  test::FanMesh fan;
  RiverSurfaceOptions options;
};
const Network& river_network() {
  static const Network network = [] {
    Network n;
    const uint32_t rows = 1750;
    n.fan = test::fan_channel(4.0f, 0.3f * rows, {240.0f, 240.0f, 240.0f}, 0.05f, 0.3f, 13,
                              [&](uint32_t k, uint32_t j) {
                                const int island = int(double(k) * 10.0 / rows);
                                const double dk = (double(k) + 0.5 - (island + 0.5) * rows / 10.0) / 40.0;
                                const double dj = (double(j) + 0.5 - (island % 2 == 0 ? 16.0 : 24.0)) / 4.5;
                                return dk * dk + dj * dj < 1.0;
                              });
    n.options.ends.push_back({n.fan.main_end, false});
    for (const uint32_t end : n.fan.arm_ends) n.options.ends.push_back({end, true});
    return n;
  }();
  return network;
}

// The surface and the obstacle-free solve, as a river is loaded: a strip against the same river
// with ten islands, and against a network of four ends with ten islands (issue 29: at most 2x).
void BM_LoadFlow(benchmark::State& state) {
  const int kind = int(state.range(1));  // 0: strip, 1: ten islands, 2: the network
  const std::vector<glm::vec3>& positions = kind == 2 ? river_network().fan.mesh.positions
                                            : kind == 1 ? river_with_islands(state.range(0)).positions
                                                        : river_mesh(state.range(0)).positions;
  const std::vector<uint32_t>& indices = kind == 2 ? river_network().fan.mesh.indices
                                         : kind == 1 ? river_with_islands(state.range(0)).indices
                                                     : river_mesh(state.range(0)).indices;
  const RiverSurfaceOptions options = kind == 2 ? river_network().options : RiverSurfaceOptions{};
  for (auto _ : state) {
    RiverSurface surface;
    StreamFunction flow;
    const Status built = RiverSurface::build(positions, indices, options, &surface);
    if (!built.ok() || !StreamFunction::create(std::move(surface), {20.0f, 1.5f, 0.0f}, &flow).ok()) {
      state.SkipWithError(("the river did not load: " + built.message()).c_str());
      return;
    }
    benchmark::DoNotOptimize(flow.node_velocity().data());
  }
  state.counters["islands"] = double(kind != 0 ? 10 : 0);
  state.counters["ends"] = double(kind == 2 ? 4 : 2);
  state.counters["vertices"] = double(positions.size());
}

void BM_SurfaceBuild(benchmark::State& state) {
  const RiverMesh& mesh = river_mesh(state.range(0));
  for (auto _ : state) {
    RiverSurface surface;
    benchmark::DoNotOptimize(RiverSurface::build(mesh.positions, mesh.indices, {}, &surface).ok());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(mesh.positions.size()));
}

void BM_FullSolve(benchmark::State& state) {
  const RiverMesh& mesh = river_mesh(state.range(0));
  StreamFunction flow = make_flow(mesh);
  Obstacle rock;
  rock.centre = mesh.positions[mesh.positions.size() / 2];
  rock.radius = 1.5f;
  if (!flow.set_obstacles({rock}).ok()) std::abort();
  for (auto _ : state) {
    flow.solve_full();
    benchmark::DoNotOptimize(flow.node_velocity().data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(mesh.positions.size()));
}

// A boat drifting 5 cm per frame, back and forth: its offset at frame `step`.
glm::vec3 boat_drift(int step) {
  return {0.0f, 0.0f, 0.05f * float(step % 40 < 20 ? step % 40 : 40 - step % 40)};
}

void BM_MoveObstacle(benchmark::State& state) {
  const RiverMesh& mesh = river_mesh(state.range(0));
  StreamFunction flow = make_flow(mesh);
  Obstacle rock;
  const glm::vec3 centre = mesh.positions[mesh.positions.size() / 2];
  rock.centre = centre;
  rock.radius = 1.5f;
  if (!flow.set_obstacles({rock}).ok()) std::abort();
  int step = 0;
  for (auto _ : state) {
    if (!flow.move_obstacle(0, centre + boat_drift(step)).ok()) std::abort();
    ++step;
  }
  state.counters["resolved"] = double(flow.last_update().nodes_resolved);
}

// The foam after each move of BM_MoveObstacle's boat: derived again over the whole river
// (range(1) 0) or only where the flow changed (1); each vertex's section read from a list
// (range(2) 0) or searched among the surface's runs of nodes (1), as the engine's are.
void BM_FoamAfterMove(benchmark::State& state) {
  const RiverMesh& mesh = river_mesh(state.range(0));
  const bool local = state.range(1) != 0;
  const bool runs = state.range(2) != 0;
  StreamFunction flow = make_flow(mesh);
  Obstacle rock;
  const glm::vec3 centre = mesh.positions[mesh.positions.size() / 2];
  rock.centre = centre;
  rock.radius = 1.5f;
  TriangleBvh bvh;
  if (!flow.set_obstacles({rock}).ok() ||
      !TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok()) {
    std::abort();
  }
  const size_t count = mesh.positions.size();
  const auto [bank, section] = test::foam_inputs(flow.surface(), count);
  if (runs && flow.surface().node_count() != count) {
    state.SkipWithError("the river's nodes are not its vertices: no runs to search");
    return;
  }
  FoamField field;
  const NodeSections sections = runs ? flow.surface().node_section() : NodeSections(section);
  if (!FoamField::create(mesh.positions, mesh.indices, sections, &bvh, {}, &field).ok()) {
    std::abort();
  }
  std::vector<glm::vec3> velocity(count);
  std::vector<float> foam(count);
  for (size_t v = 0; v < count; ++v) velocity[v] = flow.velocity(v);
  field.compute(velocity, bank, foam);
  int step = 0;
  for (auto _ : state) {
    state.PauseTiming();
    if (!flow.move_obstacle(0, centre + boat_drift(step)).ok()) std::abort();
    for (size_t v = 0; v < count; ++v) velocity[v] = flow.velocity(v);
    ++step;
    state.ResumeTiming();
    if (local) {
      field.update(velocity, bank, flow.last_update().velocity_changed, foam);
    } else {
      field.compute(velocity, bank, foam);
    }
    benchmark::DoNotOptimize(foam.data());
  }
  state.counters["rederived"] = double(field.last_rederived());
}

// The ray-cast hierarchy over the river's triangles, as RiverFlow::create builds it.
void BM_HierarchyBuild(benchmark::State& state) {
  const RiverMesh& mesh = river_mesh(state.range(0));
  for (auto _ : state) {
    TriangleBvh bvh;
    if (!TriangleBvh::build(mesh.positions, mesh.indices, &bvh).ok()) std::abort();
    benchmark::DoNotOptimize(bvh.memory_bytes());
  }
}

BENCHMARK(BM_SurfaceBuild)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(4'000'000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FullSolve)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(4'000'000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_HierarchyBuild)->Arg(1'500'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MoveObstacle)->Arg(1'000'000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadFlow)->ArgsProduct({{100'000}, {0, 1, 2}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FoamAfterMove)
    ->ArgsProduct({{100'000, 1'500'000}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace siviflow

BENCHMARK_MAIN();
