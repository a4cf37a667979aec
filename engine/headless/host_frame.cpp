#include "siviflow/host_frame.h"

#include "view_math.h"
#include "vk/access.h"

namespace siviflow {
namespace {

float halton(uint32_t index, uint32_t base) {
  float result = 0.0f;
  float fraction = 1.0f / static_cast<float>(base);
  for (uint32_t i = index + 1; i > 0; i /= base) {
    result += fraction * static_cast<float>(i % base);
    fraction /= static_cast<float>(base);
  }
  return result;
}

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
  out->color = {color.image, color.view, color_format, extent, ImageState{}, color_final,
                color.usage};
  out->depth = {depth.image, depth.view, depth_format, extent, ImageState{},
                image_state(Access::DepthAttachmentRead, depth_format), depth.usage};
  return Status::success();
}

Status create_temporal_targets(HeadlessContext& context, VkFormat motion_format,
                               VkFormat reactive_format, VkExtent2D extent, HostTargets* out) {
  const auto create = [&](VkFormat format, ExternalImage* image) -> Status {
    if (format == VK_FORMAT_UNDEFINED) return Status::success();
    HostImage made;
    SIVIFLOW_TRY(context.create_target_image(format, extent, &made));
    *image = {made.image, made.view, format, extent, ImageState{},
              image_state(Access::ColorAttachmentWrite, format), made.usage};
    return Status::success();
  };
  SIVIFLOW_TRY(create(motion_format, &out->motion));
  return create(reactive_format, &out->reactive);
}

View with_taa_jitter(View view, uint32_t frame, VkExtent2D extent) {
  view.jitter = {halton(frame % 8, 2) - 0.5f, halton(frame % 8, 3) - 0.5f};
  view.projection = shifted_by_pixels(view.projection, view.jitter,
                                      glm::vec2(extent.width, extent.height));
  return view;
}

Status record_view(VkCommandBuffer cmd, World& world, std::span<Renderer* const> renderers,
                   const View& view, double time_seconds, const ReadbackTargets& readback,
                   HostTargets* targets) {
  // The world leaves its images as attachments; the water takes them from there, and each
  // river but the last hands them on as attachments to the next.
  const ImageState color_attachment = image_state(Access::ColorAttachmentWrite, targets->color.format);
  ImageState color_now = color_attachment;
  ImageState depth_now = image_state(Access::DepthAttachmentWrite, targets->depth.format);
  ExternalImage color = targets->color;
  ExternalImage depth = targets->depth;
  color.final = color_now;
  depth.final = depth_now;
  SIVIFLOW_TRY(world.record(cmd, view, time_seconds, color, depth));
  for (size_t i = 0; i < renderers.size(); ++i) {
    const bool last = i + 1 == renderers.size();
    FrameInputs inputs;
    inputs.color = targets->color;
    inputs.depth = targets->depth;
    inputs.motion = targets->motion;
    inputs.reactive = targets->reactive;
    inputs.color.current = color_now;
    inputs.depth.current = depth_now;
    if (!last) {
      // As the world left them: a river that wrote its depth would otherwise make the layout
      // change visible to the next river's depth test alone, not to its sampling.
      inputs.color.final = color_attachment;
      inputs.depth.final = image_state(Access::DepthAttachmentWrite, targets->depth.format);
    }
    if (last) inputs.readback = readback;
    SIVIFLOW_TRY(renderers[i]->record(cmd, inputs));
    color_now = inputs.color.final;
    depth_now = inputs.depth.final;
    targets->motion.current = targets->motion.final;
    targets->reactive.current = targets->reactive.final;
  }
  targets->color.current = color_now;
  targets->depth.current = depth_now;
  return Status::success();
}

Status record_world_and_water(VkCommandBuffer cmd, uint32_t slot, World& world,
                              std::span<Renderer* const> renderers, const View& view,
                              double time_seconds, const ReadbackTargets& readback,
                              HostTargets* targets) {
  SIVIFLOW_TRY(world.begin_frame(slot));
  return record_view(cmd, world, renderers, view, time_seconds, readback, targets);
}

Status record_world_and_water(VkCommandBuffer cmd, uint32_t slot, World& world,
                              Renderer& renderer, const View& view, double time_seconds,
                              const ReadbackTargets& readback, HostTargets* targets) {
  Renderer* const one[] = {&renderer};
  return record_world_and_water(cmd, slot, world, one, view, time_seconds, readback, targets);
}

}  // namespace siviflow
