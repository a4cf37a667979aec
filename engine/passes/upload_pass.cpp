#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

DataHandle<UploadList> add_upload_pass(FrameGraph& graph, BufferHandle staging, UploadList* list) {
  const DataHandle<UploadList> frame_list = graph.declare_data<UploadList>("upload list");
  PassBuilder pass = graph.add_pass("upload", PassKind::Transfer);
  pass.transfer_read(staging);
  for (BufferUpload& upload : list->buffers) upload.destination = pass.transfer_write(upload.destination);
  // One write per image, whatever the number of mip levels copied into it.
  for (size_t i = 0; i < list->images.size(); ++i) {
    ImageUpload& upload = list->images[i];
    const ImageHandle declared = upload.destination;
    upload.destination = pass.transfer_write(declared);
    for (size_t j = i + 1; j < list->images.size() && list->images[j].destination == declared; ++j) {
      list->images[j].destination = upload.destination;
      i = j;
    }
  }
  // Lookups in the pass context go by resource, so the written versions name the same images.
  pass.record([frame_list, staging](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkBuffer source = ctx.buffer(staging);
    const VkDeviceSize source_base = ctx.offset(staging);
    const UploadList& uploads = ctx.data(frame_list);
    for (const BufferUpload& upload : uploads.buffers) {
      const BufferHandle target = upload.destination;
      VkBufferCopy region{source_base + upload.staging_offset, ctx.offset(target), upload.size};
      vk.vkCmdCopyBuffer(ctx.cmd(), source, ctx.buffer(target), 1, &region);
    }
    for (const ImageUpload& upload : uploads.images) {
      const ImageHandle target = upload.destination;
      VkBufferImageCopy region{};
      region.bufferOffset = source_base + upload.staging_offset;
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, upload.mip_level, 0, 1};
      region.imageExtent = {upload.extent.width, upload.extent.height, 1};
      vk.vkCmdCopyBufferToImage(ctx.cmd(), source, ctx.image(target), ctx.layout(target), 1, &region);
    }
    return Status::success();
  });
  return frame_list;
}

}  // namespace siviflow
