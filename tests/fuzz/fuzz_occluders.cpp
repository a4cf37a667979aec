// Occluder meshes as a host hands them to Renderer::set_occluders: positions and indices from the
// fuzzer's bytes (extreme values, duplicates, slivers, indices out of range) through the same
// checks and ray-cast hierarchy (RiverFlow::set_occluders, TriangleBvh), then the queries the
// particles and the water queries ask of it with fuzzed rays and points.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_values.h"
#include "river_simulation.h"

namespace {

using siviflow::fuzzing::extreme_or;
using siviflow::fuzzing::extreme_vec3;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider in(data, size);
  std::vector<glm::vec3> positions(in.ConsumeIntegralInRange<size_t>(0, 96));
  for (glm::vec3& p : positions) {
    // Duplicates and near-duplicates make slivers and zero-area triangles.
    p = !positions.empty() && in.ConsumeIntegralInRange<int>(0, 5) == 0 ? positions.front()
                                                                          : extreme_vec3(in, -50.0f, 50.0f);
  }
  std::vector<uint32_t> indices;
  if (in.ConsumeBool()) {
    indices.resize(in.ConsumeIntegralInRange<size_t>(0, 3 * 64));
    const uint32_t top = static_cast<uint32_t>(positions.size()) + (in.ConsumeBool() ? 1u : 0u);
    for (uint32_t& i : indices) i = in.ConsumeIntegralInRange<uint32_t>(0, top == 0 ? 0 : top - 1);
  }
  siviflow::RiverFlow flow;  // set_occluders needs no river: the hierarchy is its own
  if (!flow.set_occluders(positions, indices).ok()) return 0;
  const auto bvh = flow.occluders();
  if (bvh == nullptr) return 0;
  // The queries' callers pass finite rays and points (a camera's, a checked query's).
  for (int q = 0; q < 16 && in.remaining_bytes() > 0; ++q) {
    const glm::vec3 origin = extreme_vec3(in, -60.0f, 60.0f, true);
    const glm::vec3 direction = extreme_vec3(in, -1.0f, 1.0f, true);
    const float t_max = extreme_or(in, 0.0f, 200.0f, true);
    siviflow::RayHit hit;
    (void)bvh->intersect(origin, direction, t_max, &hit);
    (void)bvh->any_hit(origin, direction, extreme_or(in, 0.0f, 1.0f, true), t_max);
    glm::dvec3 weights;
    (void)bvh->locate_xz(origin.x, origin.z, &weights);
    const uint32_t hint = in.ConsumeIntegralInRange<uint32_t>(
        0, static_cast<uint32_t>(bvh->triangle_count() - 1));
    (void)bvh->nearest_vertex(origin, extreme_or(in, 0.0f, 10.0f, true), hint);
  }
  return 0;
}
