// A river as a host hands it to the renderer (CreateInfo::river), from the fuzzer's bytes: a
// strip of sections, or a network of arms with its ends named or not, with extreme, degenerate
// and duplicated positions, depths and slopes; flow
// parameters; circle and polygon obstacles with keys. Through the same checks, the river
// surface, the stream-function solve, obstacles added, moved, replaced and removed at runtime,
// keyframed time, point queries, and a few frames of particles and flow textures under fuzzed
// cameras: everything of a frame up to, not including, the GPU.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "fuzz_values.h"
#include "river_simulation.h"

namespace {

using siviflow::fuzzing::extreme_or;
using siviflow::fuzzing::extreme_vec2;
using siviflow::fuzzing::extreme_vec3;
using siviflow::fuzzing::mostly;

constexpr uint32_t kMaxSections = 24;
constexpr uint32_t kMaxAcross = 8;

// A strip of quads along +z, `across` vertices a section, each nudged or thrown by the fuzzer.
void fuzz_strip(FuzzedDataProvider& in, std::vector<glm::vec3>* positions,
                std::vector<uint32_t>* indices) {
  const uint32_t sections = in.ConsumeIntegralInRange<uint32_t>(1, kMaxSections);
  const uint32_t across = in.ConsumeIntegralInRange<uint32_t>(1, kMaxAcross);
  const float width = mostly(in, 8.0f, 0.0f, 40.0f);
  const float spacing = mostly(in, 2.0f, 0.0f, 10.0f);
  for (uint32_t s = 0; s < sections; ++s) {
    for (uint32_t a = 0; a < across; ++a) {
      const float u = across > 1 ? static_cast<float>(a) / static_cast<float>(across - 1) : 0.5f;
      glm::vec3 p((u - 0.5f) * width, 0.0f, static_cast<float>(s) * spacing);
      if (in.ConsumeIntegralInRange<int>(0, 5) == 0) p += extreme_vec3(in, -1.0f, 1.0f);
      if (!positions->empty() && in.ConsumeIntegralInRange<int>(0, 15) == 0) p = positions->back();
      positions->push_back(p);
    }
  }
  for (uint32_t s = 0; s + 1 < sections; ++s) {
    for (uint32_t a = 0; a + 1 < across; ++a) {
      const uint32_t v = s * across + a;
      indices->insert(indices->end(), {v, v + across, v + 1, v + 1, v + across, v + across + 1});
    }
  }
  // Now and then a broken index or triangle.
  if (!indices->empty() && in.ConsumeIntegralInRange<int>(0, 7) == 0) {
    (*indices)[in.ConsumeIntegralInRange<size_t>(0, indices->size() - 1)] = in.ConsumeIntegral<uint32_t>();
  }
  if (in.ConsumeIntegralInRange<int>(0, 15) == 0) indices->push_back(0);
}

// A network: 2 or 3 arms of `across` cells joining at z = 0 into a channel on to +z, their
// tongues widening upstream by the fuzzer's spread, each vertex nudged or thrown now and then.
// Its ends go to `ends`, named or not, their discharges balanced or not.
void fuzz_fan(FuzzedDataProvider& in, std::vector<glm::vec3>* positions, std::vector<uint32_t>* indices,
              std::vector<siviflow::WaterRiverEnd>* ends) {
  const uint32_t arms = in.ConsumeIntegralInRange<uint32_t>(2, 3);
  const uint32_t across = in.ConsumeIntegralInRange<uint32_t>(1, kMaxAcross / 2);
  const float arm_width = mostly(in, 4.0f, 0.0f, 20.0f);
  const float spacing = mostly(in, 1.0f, 0.0f, 10.0f);
  const float spread = mostly(in, 0.25f, -1.0f, 3.0f);
  auto row = [&](float z, float left, float right, uint32_t cells) {
    std::vector<uint32_t> ids;
    for (uint32_t j = 0; j <= cells; ++j) {
      glm::vec3 p(left + (right - left) * float(j) / float(cells), 0.0f, z);
      if (in.ConsumeIntegralInRange<int>(0, 7) == 0) p += extreme_vec3(in, -1.0f, 1.0f);
      ids.push_back(uint32_t(positions->size()));
      positions->push_back(p);
    }
    return ids;
  };
  auto zip = [&](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    for (size_t j = 0; j + 1 < a.size(); ++j) indices->insert(indices->end(), {a[j], b[j], a[j + 1], a[j + 1], b[j], b[j + 1]});
  };
  const float half = 0.5f * float(arms) * arm_width;
  std::vector<uint32_t> tips = row(0.0f, half, -half, arms * across), prev = tips;
  for (uint32_t k = 1, rows = in.ConsumeIntegralInRange<uint32_t>(1, kMaxSections / 2); k <= rows; ++k) {
    std::vector<uint32_t> next = row(float(k) * spacing, half, -half, arms * across);
    zip(prev, next);
    prev = std::move(next);
  }
  const bool named = in.ConsumeBool();
  std::vector<float> inflow(arms);
  float total = 0.0f;
  for (float& q : inflow) total += q = mostly(in, 2.0f, -1.0f, 50.0f);
  if (named) ends->push_back({prev[prev.size() / 2], false, mostly(in, total, -1.0f, 100.0f)});
  for (uint32_t i = 0; i < arms; ++i) {
    prev.assign(tips.begin() + i * across, tips.begin() + (i + 1) * across + 1);
    const float shift_rate = (0.5f * float(arms - 1) - float(i)) * 2.0f * spread;
    for (uint32_t k = 1, rows = in.ConsumeIntegralInRange<uint32_t>(1, kMaxSections / 2); k <= rows; ++k) {
      const float left = half - float(i) * arm_width + float(k) * spacing * shift_rate;
      std::vector<uint32_t> next = row(-float(k) * spacing, left, left - arm_width, across);
      zip(next, prev);
      prev = std::move(next);
    }
    if (named) ends->push_back({in.ConsumeIntegralInRange<int>(0, 15) == 0 ? in.ConsumeIntegral<uint32_t>() : prev[prev.size() / 2],
                                in.ConsumeIntegralInRange<int>(0, 15) != 0, inflow[i]});
  }
}

siviflow::WaterObstacle fuzz_obstacle(FuzzedDataProvider& in, float length) {
  siviflow::WaterObstacle o;
  o.centre = {extreme_or(in, -10.0f, 10.0f), mostly(in, 0.0f, -2.0f, 2.0f),
              extreme_or(in, 0.0f, length)};
  o.height = mostly(in, 1.0f, 0.0f, 3.0f);
  if (in.ConsumeBool()) {
    o.radius = extreme_or(in, 0.0f, 4.0f);
  } else {
    o.polygon.resize(in.ConsumeIntegralInRange<size_t>(0, 8));
    for (glm::vec2& p : o.polygon) p = extreme_vec2(in, -3.0f, 3.0f);
    o.rotation_rad = mostly(in, 0.0f, -7.0f, 7.0f);
  }
  const size_t keys = in.ConsumeIntegralInRange<size_t>(0, 3);
  double t = 0.0;
  for (size_t k = 0; k < keys; ++k) {
    t += mostly(in, 1.0f, -1.0f, 5.0f);
    o.keys.push_back({t, {extreme_or(in, -10.0f, 10.0f), 0.0f, extreme_or(in, 0.0f, length)}});
  }
  return o;
}

// A camera somewhere about the river, looking at it; sometimes a degenerate or extreme one.
glm::mat4 fuzz_view_proj(FuzzedDataProvider& in, float length) {
  const glm::vec3 eye(extreme_or(in, -30.0f, 30.0f, true), mostly(in, 8.0f, -5.0f, 50.0f),
                      extreme_or(in, -20.0f, length, true));
  const glm::vec3 target(extreme_or(in, -5.0f, 5.0f, true), 0.0f, extreme_or(in, 0.0f, length, true));
  const float fov = mostly(in, 0.9f, 0.0f, 3.2f);
  glm::mat4 projection = glm::perspectiveRH_ZO(fov, 16.0f / 9.0f, mostly(in, 0.1f, 0.0f, 10.0f),
                                               mostly(in, 500.0f, 0.0f, 1e6f));
  projection[1][1] *= -1.0f;
  return projection * glm::lookAtRH(eye, target, glm::vec3(0.0f, 1.0f, 0.0f));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<siviflow::WaterRiverEnd> ends;
  if (in.ConsumeIntegralInRange<int>(0, 3) == 0) {
    fuzz_fan(in, &positions, &indices, &ends);
  } else {
    fuzz_strip(in, &positions, &indices);
  }
  std::vector<float> depth(positions.size());
  std::vector<float> slope(positions.size());
  for (float& d : depth) d = mostly(in, 1.5f, -1.0f, 10.0f);
  for (float& s : slope) s = mostly(in, 0.002f, -0.1f, 1.0f);
  float length = 1.0f;
  for (const glm::vec3& p : positions) length = std::max(length, std::isfinite(p.z) ? std::min(p.z, 1e3f) : 0.0f);
  std::vector<siviflow::WaterObstacle> obstacles(in.ConsumeIntegralInRange<size_t>(0, 3));
  for (siviflow::WaterObstacle& o : obstacles) o = fuzz_obstacle(in, length);

  siviflow::WaterRiver host;
  host.positions = positions;
  host.indices = indices;
  host.depth = depth;
  host.slope = slope;
  host.flow.discharge = mostly(in, 20.0f, -10.0f, 1e4f);
  host.flow.shepard_power = mostly(in, 1.5f, -1.0f, 8.0f);
  host.flow.search_radius = mostly(in, 0.0f, -1.0f, 1e3f);
  host.obstacles = obstacles;
  host.ends = ends;
  // As Renderer::create takes it.
  siviflow::RiverInput input;
  if (!siviflow::river_input_from(host, {}, &input).ok()) return 0;
  std::vector<siviflow::Obstacle> flow_obstacles;
  for (size_t i = 0; i < obstacles.size(); ++i) {
    if (!siviflow::check_obstacle(obstacles[i], i).ok()) return 0;
    flow_obstacles.push_back(siviflow::flow_obstacle(obstacles[i]));
  }
  siviflow::RiverFlow flow;
  const siviflow::FlowParams params = siviflow::river_flow_params(host.flow, input);
  if (!flow.create(std::move(input), params, std::move(flow_obstacles)).ok()) {
    return 0;
  }
  siviflow::RiverView view;
  const glm::uvec2 viewport(in.ConsumeIntegralInRange<uint32_t>(1, 96), in.ConsumeIntegralInRange<uint32_t>(1, 64));
  const bool has_view = view.create(flow, in.ConsumeIntegral<uint32_t>(), viewport).ok();
  std::vector<std::byte> staging(has_view ? view.layout().total_bytes : 0);
  double time = 0.0;
  for (int step = 0; step < 6 && in.remaining_bytes() > 0; ++step) {
    switch (in.ConsumeIntegralInRange<int>(0, 5)) {
      case 0: {
        const siviflow::WaterObstacle o = fuzz_obstacle(in, length);
        if (siviflow::check_obstacle(o, flow.obstacle_count()).ok()) {
          (void)flow.add_obstacle(siviflow::flow_obstacle(o));
        }
        break;
      }
      case 1:
        if (flow.obstacle_count() > 0) {
          (void)flow.move_obstacle(in.ConsumeIntegralInRange<size_t>(0, flow.obstacle_count() - 1),
                                   extreme_vec3(in, -10.0f, length));
        }
        break;
      case 2:
        if (flow.obstacle_count() > 0) {
          (void)flow.remove_obstacle(in.ConsumeIntegralInRange<size_t>(0, flow.obstacle_count() - 1));
        }
        break;
      case 3:
        time += mostly(in, 0.5f, -1.0f, 10.0f);
        (void)flow.set_time(time);
        break;
      case 4: {
        std::vector<glm::vec3> points(in.ConsumeIntegralInRange<size_t>(1, 8));
        for (glm::vec3& p : points) p = extreme_vec3(in, -20.0f, length + 10.0f, true);
        std::vector<siviflow::WaterSample> samples(points.size());
        flow.query(points, samples);
        break;
      }
      default:
        if (has_view && view.simulate(fuzz_view_proj(in, length), std::abs(extreme_or(in, 0.0f, 0.1f, true))).ok()) {
          (void)view.pack(staging);
        }
        break;
    }
  }
  return 0;
}
