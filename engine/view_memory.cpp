// What a view takes of device memory by its size (siviflow::view_memory), counted from the
// images the frame graph makes (renderer_graph.cpp) and the staging blocks of the frame ring.
#include <algorithm>

#include "passes/passes.h"
#include "renderer_impl.h"
#include "shaders/shared.h"
#include "sim/flow_textures.h"
#include "sim/particle_tuning.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// Bytes per texel of the view's own formats.
VkDeviceSize format_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT:
      return 4;
    case VK_FORMAT_R16G16B16A16_UINT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT:
      return 16;
    default:
      return texel_bytes(format);
  }
}

}  // namespace

Status view_memory(const CreateInfo& info, ViewMemory* out) {
  const VkExtent2D extent = info.extent;
  if (extent.width == 0 || extent.height == 0) {
    return Status::error("view_memory: CreateInfo::extent must be at least 1x1");
  }
  const VkFormat color_format =
      info.color_format == VK_FORMAT_UNDEFINED ? kDefaultColorFormat : info.color_format;
  const VkDeviceSize color = texel_bytes(color_format);
  if (color == 0) {
    return Status::error(text_format("view_memory: CreateInfo::color_format %d is not one the "
                                     "renderer takes", static_cast<int>(info.color_format)));
  }
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

  VkDeviceSize bytes = mirrored_pixels * (color + format_bytes(kReflectionDepthFormat));
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
