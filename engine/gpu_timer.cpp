#include "gpu_timer.h"

#include "vk/device_table.h"
#include "vk/pipeline.h"

namespace siviflow {

Status GpuTimer::create(const GpuContext& gpu, VkPhysicalDevice physical_device,
                        uint32_t queue_family, uint32_t slots) {
  const DeviceTable& vk = *gpu.table;
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  vk.vkGetPhysicalDeviceProperties2(physical_device, &props);
  period_ns_ = props.properties.limits.timestampPeriod;
  uint32_t family_count = 0;
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical_device, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical_device, &family_count, families.data());
  const uint32_t bits = families[queue_family].timestampValidBits;
  if (bits == 0) {
    return Status::error("enable_timing: the queue family has no timestamps",
                         VK_ERROR_FEATURE_NOT_PRESENT);
  }
  mask_ = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  VkQueryPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  pool_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  pool_info.queryCount = 2 * kMaxTimedPasses;
  pools_.assign(slots, VK_NULL_HANDLE);
  timed_passes_.assign(slots, 0);
  for (VkQueryPool& pool : pools_) {
    SIVIFLOW_TRY(vk_status(vk.vkCreateQueryPool(vk.device, &pool_info, gpu.allocation_callbacks, &pool),
                           "vkCreateQueryPool"));
  }
  return Status::success();
}

void GpuTimer::destroy(const GpuContext& gpu) {
  for (VkQueryPool pool : pools_) {
    if (pool != VK_NULL_HANDLE) gpu.table->vkDestroyQueryPool(gpu.table->device, pool, gpu.allocation_callbacks);
  }
  pools_.clear();
}

Status GpuTimer::begin(const DeviceTable& vk, VkCommandBuffer cmd, uint32_t slot, uint32_t passes,
                       FrameGraph::Timestamps* out) {
  if (passes > kMaxTimedPasses) {
    return Status::error(std::to_string(passes) +
                         " passes, more than the timer's " + std::to_string(kMaxTimedPasses));
  }
  out->pool = pools_[slot];
  vk.vkCmdResetQueryPool(cmd, out->pool, 0, 2 * passes);
  timed_passes_[slot] = passes;
  return Status::success();
}

Status GpuTimer::pass_times(const DeviceTable& vk, uint32_t slot,
                            const std::vector<std::string>& names,
                            std::vector<PassTime>* out) const {
  out->clear();
  const uint32_t passes = timed_passes_[slot];
  if (passes == 0) return Status::success();
  std::vector<uint64_t> ticks(2 * passes);
  SIVIFLOW_TRY(vk_status(vk.vkGetQueryPoolResults(vk.device, pools_[slot], 0, 2 * passes,
                                                  ticks.size() * sizeof(uint64_t), ticks.data(),
                                                  sizeof(uint64_t),
                                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                         "vkGetQueryPoolResults"));
  // Differences modulo the valid bits, so a counter that wrapped still gives the right span.
  const auto span = [this](uint64_t from, uint64_t to) {
    return static_cast<double>((to - from) & mask_) * period_ns_;
  };
  for (uint32_t i = 0; i < passes && i < names.size(); ++i) {
    const double begin_ns = span(ticks[0], ticks[2 * i]);
    const double ns = span(ticks[2 * i], ticks[2 * i + 1]);
    out->push_back({names[i], begin_ns * 1e-6, ns * 1e-6});
  }
  return Status::success();
}

}  // namespace siviflow
