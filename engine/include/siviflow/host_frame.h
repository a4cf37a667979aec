// The frame every host of ours (the capture tool, bench, the tests) records, as an engine
// would: the built-in world into the host's colour and depth, then the water over them through
// the embedding API. One place, so that every frame we render takes the embedding path.
#pragma once

#include <cstdint>
#include <span>

#include <vulkan/vulkan.h>

#include "siviflow/headless_context.h"
#include "siviflow/renderer.h"
#include "siviflow/status.h"
#include "siviflow/world.h"

namespace siviflow {

// A host's colour and depth images, and the states the last frame left them in: one frame slot's,
// or every slot's where `color.final` names a real stage (the next frame then waits on the last
// one in the queue; with VK_PIPELINE_STAGE_2_NONE only the slot's fence orders them).
struct HostTargets {
  ExternalImage color;  // current: where the last frame left it; final: what the host wants
  ExternalImage depth;
  // For renderers with CreateInfo::motion_format / reactive_format (no image: none). The
  // built-in world writes neither: off the water they keep what they held.
  ExternalImage motion;
  ExternalImage reactive;
};

// Colour (colour attachment, sampled, copy source) and depth images (HostTargets says when slots
// may share them); the colour ends each frame in `color_final`, the depth read-only.
Status create_host_targets(HeadlessContext& context, VkFormat color_format, VkFormat depth_format,
                           VkExtent2D extent, ImageState color_final, HostTargets* out);

// Motion and reactive images for one slot (VK_FORMAT_UNDEFINED: none), left as attachments.
Status create_temporal_targets(HeadlessContext& context, VkFormat motion_format,
                               VkFormat reactive_format, VkExtent2D extent, HostTargets* out);

// `view` with frame `frame`'s TAA jitter put into its projection, as a temporal-filter host
// does: the centred Halton(2,3) sequence of 8 (pixels, in View::jitter too).
View with_taa_jitter(View view, uint32_t frame, VkExtent2D extent);

// Records into `cmd`: the world seen through `view` at `time_seconds`, then the water of each
// renderer in turn (a scene's rivers; update() for this frame already called on each), the
// last one copying `readback`. Updates the targets' current states. The world's frame must have
// begun (World::begin_frame, once per frame however many views it records).
Status record_view(VkCommandBuffer cmd, World& world, std::span<Renderer* const> renderers,
                   const View& view, double time_seconds, const ReadbackTargets& readback,
                   HostTargets* targets);
// A frame of one view: the world's frame begun in `slot`, then record_view().
Status record_world_and_water(VkCommandBuffer cmd, uint32_t slot, World& world,
                              std::span<Renderer* const> renderers, const View& view,
                              double time_seconds, const ReadbackTargets& readback,
                              HostTargets* targets);
// The same with one river.
Status record_world_and_water(VkCommandBuffer cmd, uint32_t slot, World& world,
                              Renderer& renderer, const View& view, double time_seconds,
                              const ReadbackTargets& readback, HostTargets* targets);

}  // namespace siviflow
