#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

void add_upload_pass(FrameGraph& graph, const UploadList& list, UploadPassHandles* handles) {
  PassBuilder pass = graph.add_pass("upload", PassKind::Transfer);
  pass.transfer_read(handles->staging);
  for (BufferHandle& buffer : handles->buffers) buffer = pass.transfer_write(buffer);
  for (ImageHandle& image : handles->images) image = pass.transfer_write(image);
  const BufferHandle staging = handles->staging;
  // Declared every frame, copying only what `list` holds: data that changes per frame is in it
  // every frame, static data only on the first; the barriers of an idle frame cost nothing.
  pass.record([&list, staging](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkBuffer source = ctx.buffer(staging);
    for (const BufferUpload& upload : list.buffers) {
      VkBufferCopy region{upload.staging_offset, 0, upload.size};
      vk.vkCmdCopyBuffer(ctx.cmd(), source, upload.destination, 1, &region);
    }
    for (const ImageUpload& upload : list.images) {
      VkBufferImageCopy region{};
      region.bufferOffset = upload.staging_offset;
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {upload.extent.width, upload.extent.height, 1};
      vk.vkCmdCopyBufferToImage(ctx.cmd(), source, ctx.image(upload.destination),
                                ctx.layout(upload.destination), 1, &region);
    }
    return Status::success();
  });
}

}  // namespace siviflow
