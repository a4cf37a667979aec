// GPU timestamps around every pass of a frame graph, per frame slot (CreateInfo::enable_timing):
// one query pool a slot, reset and written as the slot's frame is recorded, read once the host
// has waited for it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "siviflow/renderer.h"
#include "siviflow/status.h"
#include "vk/frame_graph.h"
#include "vk/gpu_resources.h"

namespace siviflow {

class GpuTimer {
 public:
  static constexpr uint32_t kMaxTimedPasses = 16;

  // Fails when the queue family writes no timestamps. Messages name no owner: the caller's
  // guard adds its prefix.
  Status create(const GpuContext& gpu, VkPhysicalDevice physical_device, uint32_t queue_family,
                uint32_t slots);
  void destroy(const GpuContext& gpu);
  bool enabled() const { return !pools_.empty(); }

  // Resets the slot's queries for a graph of `passes` passes and says where the graph writes.
  Status begin(const DeviceTable& vk, VkCommandBuffer cmd, uint32_t slot, uint32_t passes,
               FrameGraph::Timestamps* out);
  // The passes (named in graph order) of the frame last recorded in `slot`.
  Status pass_times(const DeviceTable& vk, uint32_t slot, const std::vector<std::string>& names,
                    std::vector<PassTime>* out) const;

 private:
  std::vector<VkQueryPool> pools_;
  std::vector<uint32_t> timed_passes_;  // per slot: passes recorded with timestamps
  float period_ns_ = 1.0f;
  uint64_t mask_ = ~uint64_t{0};  // the queue's valid timestamp bits
};

}  // namespace siviflow
