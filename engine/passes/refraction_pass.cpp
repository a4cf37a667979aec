#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

DataHandle<RefractionCopy> add_refraction_copy_pass(FrameGraph& graph, ImageHandle color,
                                                    ImageHandle* copy) {
  const auto frame = graph.declare_data<RefractionCopy>("refraction copy area");
  PassBuilder pass = graph.add_pass("refraction copy", PassKind::Transfer);
  pass.transfer_read(color);
  *copy = pass.transfer_write(*copy);
  const ImageHandle source = color;
  const ImageHandle target = *copy;
  pass.record([frame, source, target](const PassContext& ctx) {
    const RefractionCopy& what = ctx.data(frame);
    if (what.area.extent.width == 0 || what.area.extent.height == 0) return Status::success();
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.srcOffset = {what.viewport_offset.x + what.area.offset.x,
                        what.viewport_offset.y + what.area.offset.y, 0};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstOffset = {what.area.offset.x, what.area.offset.y, 0};
    region.extent = {what.area.extent.width, what.area.extent.height, 1};
    ctx.table().vkCmdCopyImage(ctx.cmd(), ctx.image(source), ctx.layout(source), ctx.image(target),
                               ctx.layout(target), 1, &region);
    return Status::success();
  });
  return frame;
}

}  // namespace siviflow
