#include "vk/frame_ring.h"

#include <memory>
#include <string>

namespace siviflow {

bool LinearAllocator::allocate(VkDeviceSize size, VkDeviceSize alignment, VkDeviceSize* offset) {
  if (alignment == 0 || (alignment & (alignment - 1)) != 0) return false;  // not a power of two
  const VkDeviceSize aligned = (used_ + alignment - 1) & ~(alignment - 1);
  if (aligned > capacity_ || size > capacity_ - aligned) return false;
  *offset = aligned;
  used_ = aligned + size;
  return true;
}

void DeferredDeletions::run_all() {
  for (std::function<void()>& destroy : pending_) destroy();
  pending_.clear();
}

Status FrameRing::init(const GpuContext& gpu, uint32_t slot_count,
                       VkDeviceSize staging_bytes_per_slot) {
  gpu_ = gpu;
  slots_.resize(slot_count);
  if (staging_bytes_per_slot == 0) return Status::success();  // deletions only
  for (uint32_t i = 0; i < slot_count; ++i) {
    const std::string name = "staging slot " + std::to_string(i);
    SIVIFLOW_TRY(create_buffer(gpu, staging_bytes_per_slot, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                               /*host_visible=*/true, name.c_str(), &slots_[i].staging));
    slots_[i].allocator = LinearAllocator(staging_bytes_per_slot);
  }
  return Status::success();
}

Status FrameRing::ensure_staging_capacity(VkDeviceSize bytes) {
  for (uint32_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    if (slot.allocator.capacity() >= bytes) continue;
    // Frames in flight may still read the old block: retire it once every slot came round.
    Buffer larger;
    const std::string name = "staging slot " + std::to_string(i);
    SIVIFLOW_TRY(create_buffer(gpu_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, /*host_visible=*/true,
                               name.c_str(), &larger));
    defer_deletion_until_all_slots(
        [gpu_context = gpu_, retired = slot.staging]() mutable { destroy_buffer(gpu_context, &retired); });
    slot.staging = larger;
    slot.allocator = LinearAllocator(bytes);
  }
  return Status::success();
}

void FrameRing::destroy() {
  for (Slot& slot : slots_) {
    slot.deletions.run_all();
    destroy_buffer(gpu_, &slot.staging);
  }
  slots_.clear();
}

Status FrameRing::begin_slot(uint32_t slot) {
  if (slot >= slots_.size()) {
    return Status::error("frame slot " + std::to_string(slot) + " out of range (frames in flight: " +
                         std::to_string(slots_.size()) + ")");
  }
  current_ = slot;
  slots_[slot].deletions.run_all();
  slots_[slot].allocator.reset();
  return Status::success();
}

Status FrameRing::allocate_staging(VkDeviceSize size, VkDeviceSize alignment,
                                   StagingAllocation* out) {
  Slot& slot = slots_[current_];
  VkDeviceSize offset = 0;
  if (!slot.allocator.allocate(size, alignment, &offset)) {
    return Status::error("staging block of frame slot full: " + std::to_string(size) +
                             " bytes requested, " + std::to_string(slot.allocator.used()) + " of " +
                             std::to_string(slot.allocator.capacity()) + " used",
                         VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  out->buffer = slot.staging.buffer;
  out->offset = offset;
  out->data = static_cast<uint8_t*>(slot.staging.mapped) + offset;
  return Status::success();
}

void FrameRing::defer_deletion(std::function<void()> destroy) {
  slots_[current_].deletions.defer(std::move(destroy));
}

void FrameRing::defer_deletion_until_all_slots(std::function<void()> destroy) {
  // Each slot holds one reference; the last slot to come round runs the deletion.
  auto shared = std::make_shared<std::function<void()>>(std::move(destroy));
  for (Slot& slot : slots_) {
    slot.deletions.defer([shared]() mutable {
      if (shared.use_count() == 1) (*shared)();
      shared.reset();
    });
  }
}


}  // namespace siviflow
