// Vulkan values by name: exact strings for a few values of each kind, the fallbacks that keep an
// unknown value's number, and a name for every 1.0 format.
#include "vk/vk_text.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace siviflow {
namespace {

TEST(VkText, FormatNamesAreTheHeadersNames) {
  EXPECT_EQ(format_name(VK_FORMAT_UNDEFINED), "VK_FORMAT_UNDEFINED");
  EXPECT_EQ(format_name(VK_FORMAT_R8_UNORM), "VK_FORMAT_R8_UNORM");
  EXPECT_EQ(format_name(VK_FORMAT_B10G11R11_UFLOAT_PACK32), "VK_FORMAT_B10G11R11_UFLOAT_PACK32");
  EXPECT_EQ(format_name(VK_FORMAT_D32_SFLOAT), "VK_FORMAT_D32_SFLOAT");
  EXPECT_EQ(format_name(VK_FORMAT_ASTC_12x12_SRGB_BLOCK), "VK_FORMAT_ASTC_12x12_SRGB_BLOCK");
  EXPECT_EQ(format_name(VK_FORMAT_G16_B16_R16_3PLANE_444_UNORM),
            "VK_FORMAT_G16_B16_R16_3PLANE_444_UNORM");
  EXPECT_EQ(format_name(VK_FORMAT_G8_B8R8_2PLANE_444_UNORM), "VK_FORMAT_G8_B8R8_2PLANE_444_UNORM");
  EXPECT_EQ(format_name(VK_FORMAT_A4B4G4R4_UNORM_PACK16), "VK_FORMAT_A4B4G4R4_UNORM_PACK16");
  EXPECT_EQ(format_name(VK_FORMAT_ASTC_12x12_SFLOAT_BLOCK), "VK_FORMAT_ASTC_12x12_SFLOAT_BLOCK");
  // An extension's alias of a core format is the same value: the core name.
  EXPECT_EQ(format_name(VK_FORMAT_G8B8G8R8_422_UNORM_KHR), "VK_FORMAT_G8B8G8R8_422_UNORM");
}

TEST(VkText, UnknownFormatsKeepTheirNumber) {
  EXPECT_EQ(format_name(static_cast<VkFormat>(123456789)), "VkFormat 123456789");
  EXPECT_EQ(format_name(static_cast<VkFormat>(185)), "VkFormat 185");
  EXPECT_EQ(format_name(static_cast<VkFormat>(-1)), "VkFormat -1");
  EXPECT_EQ(format_name(VK_FORMAT_PVRTC1_2BPP_UNORM_BLOCK_IMG), "VkFormat 1000054000");
}

TEST(VkText, EveryCoreFormatOfVulkan10HasItsOwnName) {
  std::set<std::string> names;
  for (int value = VK_FORMAT_UNDEFINED; value <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK; ++value) {
    const std::string name = format_name(static_cast<VkFormat>(value));
    EXPECT_EQ(name.rfind("VK_FORMAT_", 0), 0u) << value << ": " << name;
    EXPECT_TRUE(names.insert(name).second) << value << ": " << name << " twice";
    // A colour format has both a size and channels; any other has neither, and no alpha.
    const VkFormat format = static_cast<VkFormat>(value);
    EXPECT_EQ(color_texel_bytes(format) == 0, color_channel_count(format) == 0) << name;
    EXPECT_TRUE(!color_has_alpha(format) || color_texel_bytes(format) != 0) << name;
  }
}

TEST(VkText, ColorTexelBytes) {
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R8_UNORM), 1u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R8G8B8_SRGB), 3u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R16G16_SFLOAT), 4u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_B10G11R11_UFLOAT_PACK32), 4u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_A2B10G10R10_UNORM_PACK32), 4u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32), 4u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R16G16B16A16_SFLOAT), 8u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R32G32B32A32_SFLOAT), 16u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R64G64B64A64_SFLOAT), 32u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_A4B4G4R4_UNORM_PACK16), 2u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R10X6G10X6_UNORM_2PACK16), 4u);
  // Not an uncompressed single-plane colour format.
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_UNDEFINED), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_D32_SFLOAT), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_D24_UNORM_S8_UINT), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_S8_UINT), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_BC7_UNORM_BLOCK), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_ASTC_4x4_SFLOAT_BLOCK), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_G8B8G8R8_422_UNORM), 0u);
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_R10X6G10X6B10X6A10X6_UNORM_4PACK16), 0u);  // YCbCr 4:4:4
  EXPECT_EQ(color_texel_bytes(VK_FORMAT_G8_B8R8_2PLANE_420_UNORM), 0u);
  EXPECT_EQ(color_texel_bytes(static_cast<VkFormat>(123456789)), 0u);
}

TEST(VkText, ColorChannelsAndAlpha) {
  EXPECT_EQ(color_channel_count(VK_FORMAT_R8_UNORM), 1u);
  EXPECT_EQ(color_channel_count(VK_FORMAT_R16G16_SFLOAT), 2u);
  EXPECT_EQ(color_channel_count(VK_FORMAT_B10G11R11_UFLOAT_PACK32), 3u);
  EXPECT_EQ(color_channel_count(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32), 3u);  // the exponent is shared
  EXPECT_EQ(color_channel_count(VK_FORMAT_A2B10G10R10_UNORM_PACK32), 4u);
  EXPECT_EQ(color_channel_count(VK_FORMAT_D32_SFLOAT), 0u);
  EXPECT_EQ(color_channel_count(VK_FORMAT_BC1_RGBA_UNORM_BLOCK), 0u);
  EXPECT_TRUE(color_has_alpha(VK_FORMAT_R8G8B8A8_UNORM));
  EXPECT_TRUE(color_has_alpha(VK_FORMAT_A2B10G10R10_UNORM_PACK32));
  EXPECT_TRUE(color_has_alpha(VK_FORMAT_R16G16B16A16_SFLOAT));
  EXPECT_FALSE(color_has_alpha(VK_FORMAT_B10G11R11_UFLOAT_PACK32));
  EXPECT_FALSE(color_has_alpha(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32));
  EXPECT_FALSE(color_has_alpha(VK_FORMAT_D32_SFLOAT));
  EXPECT_FALSE(color_has_alpha(static_cast<VkFormat>(123456789)));
}

TEST(VkText, ImageUsage) {
  EXPECT_EQ(image_usage_text(0), "0");
  EXPECT_EQ(image_usage_text(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
            "VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT");
  EXPECT_EQ(image_usage_text(VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT | 0x40000000u),
            "VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT | 0x40000000");
  EXPECT_EQ(image_usage_text(0x40000000u), "0x40000000");
  // Bits of extensions join the one hex number.
  EXPECT_EQ(image_usage_text(VK_IMAGE_USAGE_SAMPLED_BIT |
                             VK_IMAGE_USAGE_FRAGMENT_DENSITY_MAP_BIT_EXT | 0x40000000u),
            "VK_IMAGE_USAGE_SAMPLED_BIT | 0x40000200");
}

TEST(VkText, FormatFeatures) {
  EXPECT_EQ(format_feature_text(0), "0");
  EXPECT_EQ(
      format_feature_text(VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                          VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT),
      "VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | "
      "VK_FORMAT_FEATURE_BLIT_DST_BIT");
  // 1.2's MINMAX (0x10000) sits between 1.1's TRANSFER_DST (0x8000) and MIDPOINT (0x20000).
  EXPECT_EQ(
      format_feature_text(VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT |
                          VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_MINMAX_BIT |
                          VK_FORMAT_FEATURE_TRANSFER_DST_BIT),
      "VK_FORMAT_FEATURE_TRANSFER_DST_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_MINMAX_BIT | "
      "VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT");
  EXPECT_EQ(format_feature_text(VK_FORMAT_FEATURE_DISJOINT_BIT |
                                VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_CUBIC_BIT_EXT),
            "VK_FORMAT_FEATURE_DISJOINT_BIT | 0x2000");
}

TEST(VkText, Stages) {
  EXPECT_EQ(stage_text(VK_PIPELINE_STAGE_2_NONE), "VK_PIPELINE_STAGE_2_NONE");
  EXPECT_EQ(stage_text(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT),
            "VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT");
  EXPECT_EQ(
      stage_text(VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT),
      "VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | "
      "VK_PIPELINE_STAGE_2_COPY_BIT");
  EXPECT_EQ(stage_text(VK_PIPELINE_STAGE_2_PRE_RASTERIZATION_SHADERS_BIT),
            "VK_PIPELINE_STAGE_2_PRE_RASTERIZATION_SHADERS_BIT");
  EXPECT_EQ(stage_text(VK_PIPELINE_STAGE_2_HOST_BIT |
                       VK_PIPELINE_STAGE_2_TRANSFORM_FEEDBACK_BIT_EXT | (1ull << 63)),
            "VK_PIPELINE_STAGE_2_HOST_BIT | 0x8000000001000000");
}

TEST(VkText, Accesses) {
  EXPECT_EQ(access_text(VK_ACCESS_2_NONE), "VK_ACCESS_2_NONE");
  EXPECT_EQ(access_text(VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT |
                        (1ull << 60)),
            "VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | "
            "0x1000000000000000");
  EXPECT_EQ(access_text(VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT),
            "VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_MEMORY_READ_BIT");
}

TEST(VkText, Layouts) {
  EXPECT_EQ(layout_text(VK_IMAGE_LAYOUT_UNDEFINED), "VK_IMAGE_LAYOUT_UNDEFINED");
  EXPECT_EQ(layout_text(VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL),
            "VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL");
  EXPECT_EQ(layout_text(VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL),
            "VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL");
  EXPECT_EQ(layout_text(VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL), "VK_IMAGE_LAYOUT_ATTACHMENT_OPTIMAL");
  EXPECT_EQ(layout_text(VK_IMAGE_LAYOUT_PRESENT_SRC_KHR), "VK_IMAGE_LAYOUT_PRESENT_SRC_KHR");
  EXPECT_EQ(layout_text(static_cast<VkImageLayout>(123456789)), "VkImageLayout 123456789");
}

}  // namespace
}  // namespace siviflow
