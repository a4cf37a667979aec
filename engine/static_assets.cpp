#include "static_assets.h"

#include <algorithm>
#include <cstring>

namespace siviflow {

uint32_t StaticAssets::add_buffer(BufferSpec spec) {
  buffers_.push_back({std::move(spec), {}});
  return static_cast<uint32_t>(buffers_.size() - 1);
}

uint32_t StaticAssets::add_image(ImageSpec spec) {
  images_.push_back({std::move(spec), {}});
  return static_cast<uint32_t>(images_.size() - 1);
}

Status StaticAssets::create_buffers(const GpuContext& gpu) {
  if (!staging_declared_) {
    staging_handle_ = upload_graph_.import_buffer({"static staging", 0}, ResourceState{});
    staging_declared_ = true;
  }
  for (; created_buffers_ < buffers_.size(); ++created_buffers_) {
    const auto n = static_cast<uint32_t>(created_buffers_);
    StaticBuffer& b = buffers_[n];
    const std::span<const uint8_t> source = b.spec.source();
    SIVIFLOW_TRY(create_device_buffer(gpu, source.size(),
                                      b.spec.usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, b.spec.name,
                                      &b.buffer));
    if (b.buffer.mapped != nullptr) {
      // The device's memory is the host's: filled in place, no staging copy. The first submit
      // that reads it makes the host's writes visible.
      std::memcpy(b.buffer.mapped, source.data(), source.size());
      b.spec.bytes = std::vector<uint8_t>();
      b.spec.borrowed = {};
      continue;
    }
    const BufferHandle handle = upload_graph_.import_buffer(
        {b.spec.name, b.buffer.size}, ResourceState{}, state_of(b.spec.read_as));
    uploads_.buffers.push_back({0, handle, b.buffer.size});
    staged_buffers_.push_back(n);
  }
  return Status::success();
}

Status StaticAssets::create(const GpuContext& gpu) {
  SIVIFLOW_TRY(create_buffers(gpu));
  std::vector<ImageHandle> handles;
  for (const StaticImage& i : images_) {
    const ImageHandle handle = upload_graph_.import_image(
        {i.spec.name, i.spec.format, i.spec.extent, {}}, ResourceState{}, state_of(i.spec.read_as));
    handles.push_back(handle);
    for (uint32_t level = 0; level < i.spec.mip_offsets.size(); ++level) {
      const VkExtent2D extent{std::max(1u, i.spec.extent.width >> level),
                              std::max(1u, i.spec.extent.height >> level)};
      uploads_.images.push_back({0, handle, extent, level});
    }
  }
  uploads_data_ = add_upload_pass(upload_graph_, staging_handle_, &uploads_);
  SIVIFLOW_TRY(upload_graph_.compile());
  for (size_t n = 0; n < images_.size(); ++n) {
    StaticImage& i = images_[n];
    // The frame graph only samples them.
    const VkImageUsageFlags usage =
        upload_graph_.image_usage(handles[n]) | VK_IMAGE_USAGE_SAMPLED_BIT;
    SIVIFLOW_TRY(create_image(gpu, i.spec.format, i.spec.extent, usage, i.spec.name, &i.image,
                              static_cast<uint32_t>(i.spec.mip_offsets.size())));
  }
  return Status::success();
}

void StaticAssets::destroy(const GpuContext& gpu) {
  for (StaticImage& i : images_) destroy_image(gpu, &i.image);
  for (StaticBuffer& b : buffers_) destroy_buffer(gpu, &b.buffer);
  destroy_buffer(gpu, &staging_);
}

Status StaticAssets::stage(const GpuContext& gpu) {
  VkDeviceSize total = 0;
  for (const StaticImage& i : images_) total += i.spec.texels.size();
  for (const uint32_t n : staged_buffers_) total += buffers_[n].spec.source().size();
  SIVIFLOW_TRY(create_buffer(gpu, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, /*host_visible=*/true,
                             "static staging", &staging_));
  auto* bytes = static_cast<uint8_t*>(staging_.mapped);
  // Images first: every copy offset into them stays a multiple of their 4-byte texels.
  VkDeviceSize offset = 0;
  size_t upload = 0;
  for (StaticImage& i : images_) {
    std::memcpy(bytes + offset, i.spec.texels.data(), i.spec.texels.size());
    for (size_t level = 0; level < i.spec.mip_offsets.size(); ++level) {
      uploads_.images[upload++].staging_offset = offset + i.spec.mip_offsets[level];
    }
    offset += i.spec.texels.size();
    i.spec.texels = std::vector<uint8_t>();  // the staging copy is the only one needed now
  }
  for (size_t upload_index = 0; upload_index < staged_buffers_.size(); ++upload_index) {
    BufferSpec& spec = buffers_[staged_buffers_[upload_index]].spec;
    const std::span<const uint8_t> source = spec.source();
    std::memcpy(bytes + offset, source.data(), source.size());
    uploads_.buffers[upload_index].staging_offset = offset;
    offset += source.size();
    spec.bytes = std::vector<uint8_t>();
    spec.borrowed = {};
  }
  return Status::success();
}

Status StaticAssets::record_upload(const DeviceTable& table, VkCommandBuffer cmd) {
  FrameBindings bindings;
  bindings.bind_buffer(staging_handle_, staging_.buffer);
  for (size_t upload_index = 0; upload_index < staged_buffers_.size(); ++upload_index) {
    bindings.bind_buffer(uploads_.buffers[upload_index].destination,
                         buffers_[staged_buffers_[upload_index]].buffer.buffer);
  }
  size_t upload = 0;
  for (const StaticImage& i : images_) {
    bindings.bind_image(uploads_.images[upload].destination, i.image.image, i.image.view);
    upload += i.spec.mip_offsets.size();
  }
  bindings.bind_data(uploads_data_, &uploads_);
  return upload_graph_.execute(table, cmd, bindings);
}

void StaticAssets::finish_upload(FrameRing& ring, const GpuContext& gpu) {
  // The GPU reads the staging buffer until this slot's frame completes.
  ring.defer_deletion([gpu, retired = staging_]() mutable { destroy_buffer(gpu, &retired); });
  staging_ = Buffer{};
  uploaded_ = true;
}

StaticAssets::GraphHandles StaticAssets::import_into(FrameGraph& graph) const {
  GraphHandles handles;
  for (const StaticBuffer& b : buffers_) {
    handles.buffers.push_back(graph.import_buffer(
        {b.spec.name, b.buffer.size}, state_of(b.spec.read_as), state_of(b.spec.read_as)));
  }
  for (const StaticImage& i : images_) {
    handles.images.push_back(graph.import_image({i.spec.name, i.spec.format, i.spec.extent, {}},
                                                state_of(i.spec.read_as), state_of(i.spec.read_as)));
  }
  return handles;
}

void StaticAssets::bind(FrameBindings& bindings, const GraphHandles& handles) const {
  for (size_t n = 0; n < buffers_.size(); ++n) {
    bindings.bind_buffer(handles.buffers[n], buffers_[n].buffer.buffer);
  }
  for (size_t n = 0; n < images_.size(); ++n) {
    bindings.bind_image(handles.images[n], images_[n].image.image, images_[n].image.view);
  }
}

}  // namespace siviflow
