// What the views of one river share (CreateInfo::share_river_with): the river's flow, its
// obstacles and the host's occluders, and its static GPU data (surface geometry, normal map, water heights). The first
// renderer of a river makes it and every renderer that shares it keeps it alive; it holds its
// own Vulkan function table, so it outlives the renderer that made it.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "index_range.h"
#include "river_simulation.h"
#include "siviflow/renderer.h"
#include "static_assets.h"
#include "vk/device_table.h"
#include "vk/gpu_resources.h"

namespace siviflow {

struct SharedRiver {
  enum StaticBufferId : uint32_t { kRiverVertices, kRiverIndices };
  enum StaticImageId : uint32_t { kNormalMap, kWaterHeights };

  // Solves the river's flow and creates its static GPU data (uploaded by the first frame that
  // any of its renderers records).
  static Status create(const DeviceTable& table, const VkAllocationCallbacks* callbacks,
                       RiverInput input, const FlowParams& flow, std::vector<Obstacle> obstacles,
                       std::shared_ptr<SharedRiver>* out);
  SharedRiver() = default;
  ~SharedRiver();
  SharedRiver(const SharedRiver&) = delete;
  SharedRiver& operator=(const SharedRiver&) = delete;

  DeviceTable table;
  GpuContext gpu;  // points at `table`
  RiverFlow flow;
  StaticAssets assets;
  // The surface's triangles in runs of consecutive ones (neighbours along the river), each with
  // its bounds in river space: a view draws the runs it can see.
  struct Chunk {
    IndexRange indices;
    glm::vec3 lo{0.0f};
    glm::vec3 hi{0.0f};
  };
  std::vector<Chunk> chunks;
  glm::vec3 surface_min{0.0f};  // bounds of the surface, river space
  glm::vec3 surface_max{0.0f};
  glm::vec2 water_lo{0.0f};     // XZ bounds of the surface
  glm::vec2 water_hi{0.0f};
  glm::vec2 heights_origin{0.0f};  // world x, z of the water heights' sample (0, 0)
  float heights_spacing = 1.0f;    // metres between the samples

  // Obstacles the hosts added (Renderer::add_obstacle), in the flow's order after the scene's.
  struct RuntimeObstacle {
    uint32_t id = 0;
    WaterObstacle placed;  // as last placed: centre and rotation
  };
  std::vector<RuntimeObstacle> runtime_obstacles;
  size_t scene_obstacle_count = 0;  // the flow's obstacles before the runtime ones
  uint32_t next_obstacle_id = 1;

 private:
  void add_water_heights();
  void cut_into_chunks();
};

}  // namespace siviflow
