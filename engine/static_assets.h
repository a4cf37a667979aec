// Geometry and textures that never change: created once, copied to the GPU by a small graph of
// their own in the first frame, then only read by the frame graph, so later frames carry no
// upload barriers for them. Shared by the water renderer and the built-in world.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan.h>

#include "passes/passes.h"
#include "siviflow/status.h"
#include "vk/access.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"

namespace siviflow {

// The bytes of a contiguous container, for a static upload.
template <typename Items>
std::span<const uint8_t> byte_view(const Items& items) {
  return {reinterpret_cast<const uint8_t*>(items.data()), items.size() * sizeof(items[0])};
}
template <typename Items>
std::vector<uint8_t> bytes_of(const Items& items) {
  const std::span<const uint8_t> bytes = byte_view(items);
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

class StaticAssets {
 public:
  struct BufferSpec {
    const char* name = "";
    Access read_as = Access::VertexBufferRead;  // how the frame graph reads it
    VkBufferUsageFlags usage = 0;
    std::vector<uint8_t> bytes;  // kept until staged
    // Instead of `bytes`: the owner's, unchanged and alive until staged (a long river's mesh is
    // not copied for its upload).
    std::span<const uint8_t> borrowed;
    std::span<const uint8_t> source() const { return borrowed.empty() ? bytes : borrowed; }
  };
  struct ImageSpec {
    const char* name = "";
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkExtent2D extent{};
    std::vector<uint8_t> texels;      // every mip level, kept until staged
    std::vector<size_t> mip_offsets;  // into texels; one per level
    Access read_as = Access::SampledFragment;
  };
  // Before create(): each returns the asset's index.
  uint32_t add_buffer(BufferSpec spec);
  uint32_t add_image(ImageSpec spec);
  // Creates every buffer and image and declares their upload; a buffer in memory the host maps
  // (a unified-memory device's) is filled here instead, and its bytes freed.
  Status create(const GpuContext& gpu);
  // The buffers alone, those added and not yet created, as create() makes them: a buffer's
  // memory can then be read (buffer(i).mapped) before the images are added. create() does the rest.
  Status create_buffers(const GpuContext& gpu);
  void destroy(const GpuContext& gpu);

  // Copies every byte into one host-visible staging buffer, once, before the first upload.
  Status stage(const GpuContext& gpu);
  bool staged() const { return staging_.buffer != VK_NULL_HANDLE; }
  bool uploaded() const { return uploaded_; }
  // Records the copies into `cmd` (after stage()). Until finish_upload() the staging buffer is
  // kept, so a frame whose recording failed can record the upload again.
  Status record_upload(const DeviceTable& table, VkCommandBuffer cmd);
  // The frame that recorded the upload was recorded whole: the staging buffer is freed once
  // the ring's current slot comes round again.
  void finish_upload(FrameRing& ring, const GpuContext& gpu);

  // The assets as one frame graph knows them, by their indices.
  struct GraphHandles {
    std::vector<BufferHandle> buffers;
    std::vector<ImageHandle> images;
  };
  // Imports every asset into `graph` in the state it is read in, both ways. Several graphs may
  // import the same assets (the views of one river).
  GraphHandles import_into(FrameGraph& graph) const;
  void bind(FrameBindings& bindings, const GraphHandles& handles) const;
  const Buffer& buffer(uint32_t index) const { return buffers_[index].buffer; }
  const Image& image(uint32_t index) const { return images_[index].image; }
  size_t image_count() const { return images_.size(); }

 private:
  struct StaticBuffer {
    BufferSpec spec;
    Buffer buffer;
  };
  struct StaticImage {
    ImageSpec spec;
    Image image;
  };
  std::vector<StaticBuffer> buffers_;
  size_t created_buffers_ = 0;  // buffers_[0 .. created_buffers_) exist
  bool staging_declared_ = false;
  std::vector<uint32_t> staged_buffers_;  // those copied from staging, in uploads_.buffers' order
  std::vector<StaticImage> images_;
  FrameGraph upload_graph_;
  BufferHandle staging_handle_;
  UploadList uploads_;
  DataHandle<UploadList> uploads_data_;  // where the upload graph reads uploads_
  Buffer staging_;
  bool uploaded_ = false;
};

}  // namespace siviflow
