// Cost of gameplay's water queries (RiverFlow::query, what Renderer::query_water runs) and of
// drift_bodies on the default river (the procedural one with its two boulders): points a second
// on one core, and a frame's drift of 1,000 floats. Not a ctest test; run it in a Release build:
//   water_query_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "default_river.h"
#include "river_simulation.h"
#include "siviflow/drift.h"

namespace siviflow {
namespace {

RiverFlow& default_river() {
  static std::unique_ptr<RiverFlow> flow = [] {
    // As Renderer::create makes it for CreateInfo::river null.
    auto f = std::make_unique<RiverFlow>();
    const ProceduralRiver procedural(default_river_params());
    RiverInput input;
    const RiverFlowParams params;
    if (!procedural_river_input(procedural, &input).ok() ||
        !f->create(std::move(input), {params.discharge, params.shepard_power, params.search_radius},
                   default_scene_obstacles(procedural)).ok()) {
      std::abort();
    }
    return f;
  }();
  return *flow;
}

// Points over the river's box: most on the water, some on the banks and in the boulders.
std::vector<glm::vec3> points_over_river(size_t count) {
  std::mt19937 random(11);
  std::uniform_real_distribution<float> x(-20.0f, 19.0f), z(-122.0f, 123.0f);
  std::vector<glm::vec3> points(count);
  for (glm::vec3& p : points) p = {x(random), 1.0f, z(random)};
  return points;
}

void BM_QueryWater(benchmark::State& state) {
  const RiverFlow& flow = default_river();
  const std::vector<glm::vec3> points = points_over_river(65536);
  std::vector<WaterSample> out(points.size());
  for (auto _ : state) {
    flow.query(points, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(points.size()));
}
BENCHMARK(BM_QueryWater)->Unit(benchmark::kMillisecond);

void BM_DriftThousandFloats(benchmark::State& state) {
  const RiverFlow& flow = default_river();
  const WaterQueryFunction ask = [&](std::span<const glm::vec3> p, std::span<WaterSample> s) {
    flow.query(p, s);
    return Status::success();
  };
  std::vector<glm::vec3> starts = points_over_river(4000);
  std::vector<WaterSample> samples(starts.size());
  flow.query(starts, samples);
  std::vector<FloatingBody> bodies;
  for (size_t i = 0; i < starts.size() && bodies.size() < 1000; ++i) {
    if (samples[i].wet) bodies.push_back({starts[i], samples[i].velocity, 0.3f, 2.0f, false});
  }
  for (auto _ : state) {
    if (!drift_bodies(bodies, 1.0f / 60.0f, ask).ok()) state.SkipWithError("drift failed");
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(bodies.size()));
}
BENCHMARK(BM_DriftThousandFloats)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace siviflow

BENCHMARK_MAIN();
