// What a view takes of device memory by its size (siviflow::view_memory), counted from the
// images the frame graph makes (renderer_graph.cpp) and the staging blocks of the frame ring.
#include <algorithm>

#include "passes/passes.h"
#include "renderer_impl.h"
#include "shaders/shared.h"
#include "sim/flow_textures.h"
#include "sim/particle_tuning.h"
#include "vk/vk_text.h"

namespace siviflow {
namespace {

// Bytes per texel of the view's own formats.
VkDeviceSize format_bytes(VkFormat format) {
  return format == VK_FORMAT_D32_SFLOAT ? 4 : color_texel_bytes(format);
}

}  // namespace

Status view_memory(const CreateInfo& info, ViewMemory* out) {
  SIVIFLOW_TRY(check_create_info(info));
  const VkExtent2D extent = info.extent;
  const VkDeviceSize color = color_texel_bytes(info.color_format);
  const VkDeviceSize reflection = color_texel_bytes(reflection_format(info.color_format));
  // The flow texture and aux data at the most particle slots any view has.
  FlowTextureLayout flow;
  SIVIFLOW_TRY(make_flow_texture_layout({extent.width, extent.height}, kDefaultFlowTexelPx,
                                        kMaxParticleSlots, &flow));
  const VkDeviceSize tile_table = VkDeviceSize{SIVIFLOW_TILE_TABLE_MAX} * SIVIFLOW_TILE_TABLE_MAX *
                                  format_bytes(FlowPass::kTileTableFormat);
  const VkDeviceSize pixels = VkDeviceSize{extent.width} * extent.height;
  const VkExtent2D mirrored = reflection_extent(extent);
  const VkDeviceSize mirrored_pixels = VkDeviceSize{mirrored.width} * mirrored.height;
  const bool aovs = (info.readback_images & kAovReadbackImages) != 0;

  VkDeviceSize bytes = mirrored_pixels * (reflection + format_bytes(kReflectionDepthFormat));
  bytes += pixels * color;  // refraction copy
  if (aovs) {
    bytes += pixels * (format_bytes(FlowPass::kMaskFormat) + format_bytes(FlowPass::kNormalFormat) +
                       format_bytes(FlowPass::kReflectionFormat) + format_bytes(FlowPass::kFoamFormat));
  }
  if (info.enable_timing && info.measure_flow_floor) bytes += pixels * color;
  bytes += flow.flow_bytes + flow.aux_bytes + tile_table;
  const uint32_t slots = info.frames_in_flight == 0 ? kDefaultFramesInFlight : info.frames_in_flight;
  const VkDeviceSize staging = info.staging_bytes_per_slot == 0 ? kDefaultStagingBytes
                                                                : info.staging_bytes_per_slot;
  bytes += slots * std::max(staging, VkDeviceSize{flow.total_bytes} + kStagingAlignment);

  VkDeviceSize readback = 0;
  for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
    const auto image = static_cast<ReadbackImage>(i);
    if ((info.readback_images & readback_bit(image)) == 0) continue;
    switch (image) {
      case ReadbackImage::kColor:
        readback += pixels * color;
        break;
      case ReadbackImage::kDepth:
      case ReadbackImage::kWaterMask:
      case ReadbackImage::kFoam:
        readback += pixels * 4;
        break;
      case ReadbackImage::kNormal:
      case ReadbackImage::kReflection:
        readback += pixels * 16;
        break;
      case ReadbackImage::kFlowTexture:
        readback += flow.flow_bytes;
        break;
      case ReadbackImage::kParticleAux:
        readback += flow.aux_bytes;
        break;
      case ReadbackImage::kTileTable:
        readback += tile_table;
        break;
    }
  }
  *out = {bytes, readback};
  return Status::success();
}

}  // namespace siviflow
