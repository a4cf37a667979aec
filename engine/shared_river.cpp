#include "shared_river.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "passes/passes.h"
#include "water_normal_map.h"
#include "sim/water_heights.h"

namespace siviflow {
namespace {

constexpr VkFormat kNormalMapFormat = VK_FORMAT_R8G8B8A8_UNORM;
// The water heights sit on a fixed grid whatever the tile size: half the default tile apart,
// reaching over half the largest tile beyond the water (on the samples a one-tile margin had).
constexpr float kWaterHeightSpacing = 1.5f;
constexpr float kWaterHeightMargin = 5.0f * kWaterHeightSpacing;
static_assert(kWaterHeightMargin >= 0.5f * kMaxTileSizeM);
constexpr uint32_t kMaxWaterHeightSamples = 2048;
// Triangles of a surface chunk: a few hundred metres of a river, culled or drawn whole.
constexpr uint32_t kChunkTriangles = 1024;  // per axis: 16 MiB at most, samples widen beyond

// The longest triangle edge of a mesh, seen from above.
float longest_edge_xz(std::span<const glm::vec3> positions, std::span<const uint32_t> indices) {
  float longest = 0.0f;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 d = positions[indices[t + e]] - positions[indices[t + (e + 1) % 3]];
      longest = std::max(longest, glm::length(glm::vec2(d.x, d.z)));
    }
  }
  return longest;
}

}  // namespace

Status SharedRiver::create(const DeviceTable& table, const VkAllocationCallbacks* callbacks,
                           RiverInput input, const FlowParams& flow,
                           std::vector<Obstacle> obstacles, std::shared_ptr<SharedRiver>* out) {
  auto river = std::make_shared<SharedRiver>();
  river->table = table;
  river->gpu = make_gpu_context(river->table, callbacks);
  StaticAssets& assets = river->assets;
  // The mesh's buffers are made before the flow is solved: on a unified-memory device the solve,
  // the ray-cast structure and the foam then read them, the flow's own copy freed first.
  const auto home = [&river, &assets](std::span<const glm::vec3> positions,
                                      std::span<const uint32_t> indices,
                                      RiverFlow::PlacedMesh* placed) {
    StaticAssets::BufferSpec vertices{"river vertices", Access::VertexBufferRead,
                                      VK_BUFFER_USAGE_VERTEX_BUFFER_BIT};
    vertices.borrowed = byte_view(positions);
    assets.add_buffer(std::move(vertices));
    StaticAssets::BufferSpec triangles{"river indices", Access::IndexBufferRead,
                                       VK_BUFFER_USAGE_INDEX_BUFFER_BIT};
    triangles.borrowed = byte_view(indices);
    assets.add_buffer(std::move(triangles));
    SIVIFLOW_TRY(assets.create_buffers(river->gpu));
    const Buffer& vertex_buffer = assets.buffer(kRiverVertices);
    const Buffer& index_buffer = assets.buffer(kRiverIndices);
    if (vertex_buffer.host_cached && index_buffer.host_cached) {
      placed->positions = {static_cast<const glm::vec3*>(vertex_buffer.mapped), positions.size()};
      placed->indices = {static_cast<const uint32_t*>(index_buffer.mapped), indices.size()};
    }
    return Status::success();
  };
  SIVIFLOW_TRY(river->flow.create(std::move(input), flow, std::move(obstacles), home));
  river->scene_obstacle_count = river->flow.obstacle_count();
  river->cut_into_chunks();
  WaterNormalMap normal_map = make_water_normal_map();
  assets.add_image({"water normal map", kNormalMapFormat, {normal_map.size, normal_map.size},
                    std::move(normal_map.texels), std::move(normal_map.mip_offsets)});
  river->add_water_heights();
  SIVIFLOW_TRY(assets.create(river->gpu));
  *out = std::move(river);
  return Status::success();
}

SharedRiver::~SharedRiver() {
  if (gpu.table != nullptr) assets.destroy(gpu);
}

void SharedRiver::cut_into_chunks() {
  const std::span<const glm::vec3> positions = flow.positions();
  const std::span<const uint32_t> indices = flow.indices();
  const auto count = static_cast<uint32_t>(indices.size());
  for (uint32_t first = 0; first < count; first += 3 * kChunkTriangles) {
    Chunk chunk;
    chunk.indices = {first, std::min(3 * kChunkTriangles, count - first)};
    chunk.lo = glm::vec3(std::numeric_limits<float>::max());
    chunk.hi = glm::vec3(std::numeric_limits<float>::lowest());
    for (uint32_t i = first; i < first + chunk.indices.index_count; ++i) {
      chunk.lo = glm::min(chunk.lo, positions[indices[i]]);
      chunk.hi = glm::max(chunk.hi, positions[indices[i]]);
    }
    chunks.push_back(chunk);
  }
}

// The water height under every tile centre the water material may read (shaders/shared.h),
// for any tile size the look allows.
void SharedRiver::add_water_heights() {
  const std::span<const glm::vec3> surface = flow.positions();
  const WaterHeights heights =
      water_heights(surface, kWaterHeightSpacing, kWaterHeightMargin, kMaxWaterHeightSamples);
  heights_origin = heights.origin;
  heights_spacing = heights.spacing;
  surface_min = glm::vec3(std::numeric_limits<float>::max());
  surface_max = glm::vec3(std::numeric_limits<float>::lowest());
  for (const glm::vec3& p : surface) {
    surface_min = glm::min(surface_min, p);
    surface_max = glm::max(surface_max, p);
  }
  water_lo = glm::vec2(surface_min.x, surface_min.z);
  water_hi = glm::vec2(surface_max.x, surface_max.z);
  // A tile centre is within a tile of water it covers, and water within its longest triangle
  // edge of a vertex: samples farther than both (at the largest tile) are no tile's. Steps go
  // along the axes, so a distance d takes up to d sqrt(2) / spacing of them, plus one for the
  // vertex's own sample.
  const float reach = (kMaxTileSizeM + longest_edge_xz(surface, flow.indices())) * std::sqrt(2.0f);
  const auto reach_steps = static_cast<uint32_t>(std::ceil(reach / heights.spacing)) + 1;
  std::vector<float> texels(heights.heights.size());
  for (size_t i = 0; i < texels.size(); ++i) {
    texels[i] = heights.steps[i] <= reach_steps ? heights.heights[i]
                                                : static_cast<float>(SIVIFLOW_FAR_FROM_WATER);
  }
  assets.add_image({"water heights", FlowPass::kWaterHeightsFormat, {heights.columns, heights.rows},
                    bytes_of(texels), {0}, Access::SampledCompute});
}

}  // namespace siviflow
