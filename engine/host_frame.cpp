#include "siviflow/host_frame.h"

#include "vk/access.h"

namespace siviflow {
namespace {

ImageState image_state(Access access, VkFormat format) {
  const ResourceState state = state_of(access);
  return {state.stage, state.access, image_layout(access, format)};
}

}  // namespace

Status create_host_targets(HeadlessContext& context, VkFormat color_format, VkFormat depth_format,
                           VkExtent2D extent, ImageState color_final, HostTargets* out) {
  HostImage color;
  HostImage depth;
  SIVIFLOW_TRY(context.create_target_image(color_format, extent, &color));
  SIVIFLOW_TRY(context.create_depth_image(depth_format, extent, &depth));
  out->color = {color.image, color.view, color_format, extent, ImageState{}, color_final};
  out->depth = {depth.image, depth.view, depth_format, extent, ImageState{},
                image_state(Access::DepthAttachmentRead, depth_format)};
  return Status::success();
}

Status record_world_and_water(VkCommandBuffer cmd, uint32_t slot, World& world,
                              Renderer& renderer, const View& view, double time_seconds,
                              const ReadbackTargets& readback, HostTargets* targets) {
  // The world leaves its images as attachments; the water takes them from there.
  ExternalImage color = targets->color;
  ExternalImage depth = targets->depth;
  color.final = image_state(Access::ColorAttachmentWrite, color.format);
  depth.final = image_state(Access::DepthAttachmentWrite, depth.format);
  SIVIFLOW_TRY(world.begin_frame(slot));
  SIVIFLOW_TRY(world.record(cmd, view, time_seconds, color, depth));
  FrameInputs inputs;
  inputs.color = targets->color;
  inputs.depth = targets->depth;
  inputs.color.current = color.final;
  inputs.depth.current = depth.final;
  inputs.readback = readback;
  SIVIFLOW_TRY(renderer.record(cmd, inputs));
  targets->color.current = targets->color.final;
  targets->depth.current = targets->depth.final;
  return Status::success();
}

}  // namespace siviflow
