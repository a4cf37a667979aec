#include "vk/access.h"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string_view>

#include "vk/vk_text.h"

namespace siviflow {
namespace {

constexpr VkPipelineStageFlags2 kFragmentTests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
constexpr VkPipelineStageFlags2 kGraphicsShaders =
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
constexpr VkImageLayout kNoLayout = VK_IMAGE_LAYOUT_UNDEFINED;

// ALL_TRANSFER rather than COPY: upload passes may also clear or fill, which are not copies.
// Attachment rows include the read bit: LOAD_OP_LOAD and blending read the attachment.
const AccessInfo kTable[] = {
    {Access::None, "None", VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, kNoLayout, 0, 0},
    {Access::TransferRead, "TransferRead", VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
     VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
     VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_BUFFER_USAGE_TRANSFER_SRC_BIT},
    {Access::TransferWrite, "TransferWrite", VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
     VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_BUFFER_USAGE_TRANSFER_DST_BIT},
    {Access::ColorAttachmentWrite, "ColorAttachmentWrite",
     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
     VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 0},
    {Access::DepthAttachmentWrite, "DepthAttachmentWrite", kFragmentTests,
     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
     VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0},
    {Access::DepthAttachmentRead, "DepthAttachmentRead", kFragmentTests,
     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0},
    {Access::SampledVertex, "SampledVertex", VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
     VK_IMAGE_USAGE_SAMPLED_BIT, 0},
    {Access::SampledFragment, "SampledFragment", VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
     VK_IMAGE_USAGE_SAMPLED_BIT, 0},
    {Access::SampledCompute, "SampledCompute", VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
     VK_IMAGE_USAGE_SAMPLED_BIT, 0},
    {Access::StorageReadGraphics, "StorageReadGraphics", kGraphicsShaders,
     VK_ACCESS_2_SHADER_STORAGE_READ_BIT, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_USAGE_STORAGE_BIT,
     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    {Access::StorageReadCompute, "StorageReadCompute", VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
     VK_ACCESS_2_SHADER_STORAGE_READ_BIT, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_USAGE_STORAGE_BIT,
     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    {Access::StorageWriteCompute, "StorageWriteCompute", VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
     VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
     VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_USAGE_STORAGE_BIT, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT},
    {Access::VertexBufferRead, "VertexBufferRead", VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT,
     VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT, kNoLayout, 0, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT},
    {Access::IndexBufferRead, "IndexBufferRead", VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT,
     VK_ACCESS_2_INDEX_READ_BIT, kNoLayout, 0, VK_BUFFER_USAGE_INDEX_BUFFER_BIT},
    {Access::UniformRead, "UniformRead", kGraphicsShaders | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
     VK_ACCESS_2_UNIFORM_READ_BIT, kNoLayout, 0, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT},
    {Access::HostRead, "HostRead", VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT,
     kNoLayout, 0, 0},
    {Access::HostWrite, "HostWrite", VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT,
     kNoLayout, 0, 0},
};
static_assert(std::size(kTable) == kAccessCount, "one row per Access value");

constexpr VkAccessFlags2 kWriteAccess =
    VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
    VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT |
    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

// The dumps name these bits, in this order, as the tests read them (others print as hex); each
// name is vk_text's without its prefix and "_BIT".
constexpr VkPipelineStageFlags2 kStageDumpOrder[] = {
    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
    VK_PIPELINE_STAGE_2_ALL_GRAPHICS_BIT,
    VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
    VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT,
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
    VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT,
    VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT,
    VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT,
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
    VK_PIPELINE_STAGE_2_COPY_BIT,
    VK_PIPELINE_STAGE_2_RESOLVE_BIT,
    VK_PIPELINE_STAGE_2_BLIT_BIT,
    VK_PIPELINE_STAGE_2_CLEAR_BIT,
    VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT,
    VK_PIPELINE_STAGE_2_HOST_BIT,
};

constexpr VkAccessFlags2 kAccessDumpOrder[] = {
    VK_ACCESS_2_MEMORY_READ_BIT,
    VK_ACCESS_2_MEMORY_WRITE_BIT,
    VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT,
    VK_ACCESS_2_INDEX_READ_BIT,
    VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT,
    VK_ACCESS_2_UNIFORM_READ_BIT,
    VK_ACCESS_2_INPUT_ATTACHMENT_READ_BIT,
    VK_ACCESS_2_SHADER_READ_BIT,
    VK_ACCESS_2_SHADER_WRITE_BIT,
    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
    VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
    VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
    VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT,
    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
    VK_ACCESS_2_TRANSFER_READ_BIT,
    VK_ACCESS_2_TRANSFER_WRITE_BIT,
    VK_ACCESS_2_HOST_READ_BIT,
    VK_ACCESS_2_HOST_WRITE_BIT,
};

// The layouts the dumps name; any other prints as LAYOUT_ and its number.
constexpr VkImageLayout kDumpLayouts[] = {
    VK_IMAGE_LAYOUT_UNDEFINED,
    VK_IMAGE_LAYOUT_GENERAL,
    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
    VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
    VK_IMAGE_LAYOUT_PREINITIALIZED,
    VK_IMAGE_LAYOUT_READ_ONLY_OPTIMAL,
    VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL,
    VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
};

// "VK_ACCESS_2_TRANSFER_WRITE_BIT" -> "TRANSFER_WRITE".
std::string dump_name(std::string name, std::string_view prefix) {
  if (name.starts_with(prefix)) name.erase(0, prefix.size());
  if (name.ends_with("_BIT")) name.resize(name.size() - 4);
  return name;
}

std::string stage_dump_name(uint64_t bit) {
  // The dumps have always called ALL_TRANSFER by its alias.
  if (bit == VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT) return "TRANSFER";
  return dump_name(stage_text(bit), "VK_PIPELINE_STAGE_2_");
}

std::string access_dump_name(uint64_t bit) { return dump_name(access_text(bit), "VK_ACCESS_2_"); }

template <std::size_t N>
std::string flags_name(uint64_t flags, const uint64_t (&order)[N],
                       std::string (*name_of)(uint64_t bit)) {
  if (flags == 0) return "NONE";
  std::string out;
  for (const uint64_t bit : order) {
    if ((flags & bit) == 0) continue;
    if (!out.empty()) out += '|';
    out += name_of(bit);
    flags &= ~bit;
  }
  if (flags != 0) {
    char hex[32];
    std::snprintf(hex, sizeof(hex), "0x%llx", static_cast<unsigned long long>(flags));
    if (!out.empty()) out += '|';
    out += hex;
  }
  return out;
}

}  // namespace

const AccessInfo& access_info(Access access) {
  const auto index = static_cast<std::size_t>(access);
  return index < kAccessCount ? kTable[index] : kTable[0];
}

ResourceState state_of(Access access) {
  const AccessInfo& info = access_info(access);
  return {info.stage, info.access, info.layout};
}

VkImageLayout image_layout(Access access, VkFormat format) {
  const bool sampled = access == Access::SampledVertex || access == Access::SampledFragment ||
                       access == Access::SampledCompute;
  // Valid for sampling and for read-only depth/stencil attachments (unlike SHADER_READ_ONLY).
  if (sampled && (aspect_of(format) & VK_IMAGE_ASPECT_COLOR_BIT) == 0) {
    return VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
  }
  return access_info(access).layout;
}

VkAccessFlags2 write_bits(VkAccessFlags2 access) { return access & kWriteAccess; }

std::string stage_flags_name(VkPipelineStageFlags2 stages) {
  return flags_name(stages, kStageDumpOrder, stage_dump_name);
}

std::string access_flags_name(VkAccessFlags2 access) {
  return flags_name(access, kAccessDumpOrder, access_dump_name);
}

std::string layout_name(VkImageLayout layout) {
  if (std::find(std::begin(kDumpLayouts), std::end(kDumpLayouts), layout) ==
      std::end(kDumpLayouts)) {
    return "LAYOUT_" + std::to_string(static_cast<int>(layout));
  }
  return dump_name(layout_text(layout), "VK_IMAGE_LAYOUT_");
}

VkImageAspectFlags aspect_of(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D32_SFLOAT: return VK_IMAGE_ASPECT_DEPTH_BIT;
    case VK_FORMAT_D16_UNORM_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    case VK_FORMAT_S8_UINT: return VK_IMAGE_ASPECT_STENCIL_BIT;
    default: return VK_IMAGE_ASPECT_COLOR_BIT;
  }
}

}  // namespace siviflow
