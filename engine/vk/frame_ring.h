// N frames in flight. Each slot owns a persistently mapped staging block with a linear allocator
// and a list of deletions deferred until the GPU is done with the slot's previous frame.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <vulkan/vulkan.h>

#include "siviflow/status.h"
#include "vk/gpu_resources.h"

namespace siviflow {

// Bump allocator over [0, capacity). Pure arithmetic so that it is tested without a device.
class LinearAllocator {
 public:
  explicit LinearAllocator(VkDeviceSize capacity = 0) : capacity_(capacity) {}
  // Offset of `size` bytes aligned to `alignment`, or false when full or `alignment` is not a
  // power of two.
  bool allocate(VkDeviceSize size, VkDeviceSize alignment, VkDeviceSize* offset);
  void reset() { used_ = 0; }
  VkDeviceSize used() const { return used_; }
  VkDeviceSize capacity() const { return capacity_; }

 private:
  VkDeviceSize capacity_ = 0;
  VkDeviceSize used_ = 0;
};

// Callbacks run, in order, when their slot comes round again (or at shutdown).
class DeferredDeletions {
 public:
  void defer(std::function<void()> destroy) { pending_.push_back(std::move(destroy)); }
  void run_all();
  size_t pending() const { return pending_.size(); }

 private:
  std::vector<std::function<void()>> pending_;
};

struct StagingAllocation {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  void* data = nullptr;  // host pointer to write `size` bytes at
};

class FrameRing {
 public:
  // staging_bytes_per_slot 0: no staging blocks, the ring only defers deletions.
  Status init(const GpuContext& gpu, uint32_t slot_count, VkDeviceSize staging_bytes_per_slot);
  void destroy();  // runs every pending deletion; the GPU must be idle for this ring
  // Grows every slot's staging block to at least `bytes`, between frames (not between a slot's
  // begin and the end of its recording); old blocks are freed once every slot came round.
  Status ensure_staging_capacity(VkDeviceSize bytes);

  uint32_t slot_count() const { return static_cast<uint32_t>(slots_.size()); }
  // The host guarantees the GPU finished this slot's previous frame.
  Status begin_slot(uint32_t slot);
  Status allocate_staging(VkDeviceSize size, VkDeviceSize alignment, StagingAllocation* out);
  // Runs `destroy` when the current slot comes round again: for what only this slot's frame used.
  void defer_deletion(std::function<void()> destroy);
  // Runs `destroy` once every slot has come round again: for what frames of any slot may use.
  void defer_deletion_until_all_slots(std::function<void()> destroy);
  VkBuffer staging_buffer() const { return slots_[current_].staging.buffer; }

 private:
  struct Slot {
    Buffer staging;
    LinearAllocator allocator;
    DeferredDeletions deletions;
  };
  GpuContext gpu_;
  std::vector<Slot> slots_;
  uint32_t current_ = 0;
};

}  // namespace siviflow
