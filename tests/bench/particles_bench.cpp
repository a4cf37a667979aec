// Per-frame cost of the River Particle Processor: upkeep (Algorithm 2) and packing (flow texture
// and aux data) at 1280x720 and 1920x1080, for a 10k-vertex and a 4M-vertex tessellation of the
// same river seen along the same camera path. Not a ctest test; run it in a Release build:
//   particles_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "sim/flow_textures.h"
#include "sim/particles.h"
#include "unit/particle_scenes.h"

namespace siviflow {
namespace {

constexpr float kWidth = 40.0f;
constexpr float kLength = 4000.0f;

// The same meandering 40 m x 4 km channel, tessellated across x along.
struct River {
  test::GridRiver mesh;
  std::shared_ptr<const TriangleBvh> bvh;
};

River* river(uint32_t across, uint32_t along) {
  static std::map<std::pair<uint32_t, uint32_t>, std::unique_ptr<River>> cache;
  auto& slot = cache[{across, along}];
  if (slot) return slot.get();
  slot = std::make_unique<River>();
  const auto centre = [](float z) { return 30.0f * std::sin(z / 200.0f); };
  test::GridRiver straight = test::grid_river(
      across, along, {-0.5f * kWidth, 0.0f}, {0.5f * kWidth, kLength},
      [](float, float z) { return -0.001f * z; },
      [](float x, float) { return glm::vec3(0.0f, 0.0f, 1.0f - 4.0f * x * x / (kWidth * kWidth)); });
  for (size_t i = 0; i < straight.positions.size(); ++i) {
    glm::vec3& p = straight.positions[i];
    const float z = p.z;
    p.x += centre(z);
    const float dcdz = 0.15f * std::cos(z / 200.0f);
    straight.flow[i] = straight.flow[i].z * glm::normalize(glm::vec3(dcdz, 0.0f, 1.0f));
  }
  slot->mesh = std::move(straight);
  const auto t0 = std::chrono::steady_clock::now();
  auto bvh = std::make_shared<TriangleBvh>();
  if (!TriangleBvh::build(slot->mesh.positions, slot->mesh.indices, bvh.get()).ok()) std::abort();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "river %ux%u (%zu vertices, %zu triangles): BVH built in %.2f s, %.1f MB\n",
               across, along, slot->mesh.positions.size(), bvh->triangle_count(), s,
               bvh->memory_bytes() / 1048576.0);
  slot->bvh = std::move(bvh);
  return slot.get();
}

River* small_river() { return river(20, 500); }      // 10,000 vertices
River* large_river() { return river(200, 20000); }   // 4,000,000 vertices

// A camera 12 m over the river looking downstream, swaying and moving back and forth: a steady
// stream of perspective change, pans and edge traffic (a period of 600 frames).
ScreenCamera camera_at(uint64_t frame, glm::uvec2 viewport) {
  const float t = 6.2831853f * static_cast<float>(frame % 600) / 600.0f;
  const float z = 1000.0f + 8.0f * std::sin(t);
  const glm::vec3 eye(30.0f * std::sin(z / 200.0f) + 3.0f * std::sin(3.0f * t), 12.0f, z);
  const glm::vec3 ahead(0.25f * std::sin(2.0f * t), -0.35f, 1.0f);
  return test::look_at(eye, eye + ahead, viewport, 60.0f, {0.0f, 1.0f, 0.0f}, 0.1f, 3000.0f);
}

struct Setup {
  ParticleField field;
  FlowTextures textures;
  std::vector<std::byte> staging;
  uint64_t frame = 0;
};

std::unique_ptr<Setup> make_setup(River* r, glm::uvec2 viewport, uint64_t warmup_frames,
                                  bool advect = false) {
  auto s = std::make_unique<Setup>();
  ParticleParams params;
  params.viewport = viewport;
  params.seed = 1;
  params.advect = advect;
  if (!ParticleField::create(r->mesh.field(), r->bvh, params, &s->field).ok()) std::abort();
  if (!FlowTextures::create(s->field, kDefaultFlowTexelPx, &s->textures).ok()) std::abort();
  s->staging.resize(s->textures.layout().total_bytes);
  for (; s->frame < warmup_frames; ++s->frame) {
    if (!s->field.update(camera_at(s->frame, viewport), s->frame, 1.0f / 60.0f).ok()) std::abort();
  }
  return s;
}

struct Totals {
  uint64_t frames = 0, rays = 0, born = 0, thinned = 0, arc_checks = 0, seed_tests = 0;
  void add(const ParticleStats& s) {
    ++frames;
    rays += s.rays;
    born += s.born;
    thinned += s.thinned;
    arc_checks += s.arc_checks;
    seed_tests += s.seed_tests;
  }
};

void report(benchmark::State& state, const Setup& s, const Totals& t) {
  const double n = t.frames ? static_cast<double>(t.frames) : 1.0;
  state.counters["particles"] = static_cast<double>(s.field.particles().size());
  state.counters["rays"] = t.rays / n;
  state.counters["born"] = t.born / n;
  state.counters["thinned"] = t.thinned / n;
  state.counters["arcs"] = t.arc_checks / n;
  state.counters["seeds"] = t.seed_tests / n;
}

// Upkeep along the moving path (steady state after a warm-up of 120 frames).
void BM_Upkeep(benchmark::State& state, River* (*which)(), glm::uvec2 viewport, bool pack,
               bool advect = false) {
  River* r = which();
  auto s = make_setup(r, viewport, 120, advect);
  Totals totals;
  for (auto _ : state) {
    if (!s->field.update(camera_at(s->frame, viewport), s->frame, 1.0f / 60.0f).ok()) std::abort();
    if (pack && !s->textures.pack(s->field, s->staging).ok()) std::abort();
    benchmark::DoNotOptimize(s->staging.data());
    totals.add(s->field.stats());
    ++s->frame;
  }
  report(state, *s, totals);
}

// Packing alone.
void BM_Pack(benchmark::State& state, River* (*which)(), glm::uvec2 viewport) {
  auto s = make_setup(which(), viewport, 120);
  for (auto _ : state) {
    if (!s->textures.pack(s->field, s->staging).ok()) std::abort();
    benchmark::DoNotOptimize(s->staging.data());
  }
  report(state, *s, Totals{});
}

// The first frame (or a camera cut): everything is seeded and filled at once.
void BM_ColdFill(benchmark::State& state, River* (*which)(), glm::uvec2 viewport) {
  auto s = make_setup(which(), viewport, 0);
  Totals totals;
  for (auto _ : state) {
    s->field.reset();
    if (!s->field.update(camera_at(0, viewport), 0, 1.0f / 60.0f).ok()) std::abort();
    totals.add(s->field.stats());
  }
  report(state, *s, totals);
}

// The median of repeated runs is sensitive to whatever else shares the core; the minimum is the
// cost of the code itself. Both are reported with --benchmark_repetitions.
double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

constexpr glm::uvec2 k720{1280, 720};
constexpr glm::uvec2 k1080{1920, 1080};

BENCHMARK_CAPTURE(BM_Upkeep, 10k_720p, small_river, k720, false)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 4M_720p, large_river, k720, false)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 10k_1080p, small_river, k1080, false)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 4M_1080p, large_river, k1080, false)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 10k_1080p_with_pack, small_river, k1080, true)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 4M_1080p_with_pack, large_river, k1080, true)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Upkeep, 10k_1080p_advected, small_river, k1080, false, true)
    ->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_Pack, 1080p, small_river, k1080)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_ColdFill, 10k_1080p, small_river, k1080)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);
BENCHMARK_CAPTURE(BM_ColdFill, 4M_1080p, large_river, k1080)->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", min_of);

}  // namespace
}  // namespace siviflow

BENCHMARK_MAIN();
