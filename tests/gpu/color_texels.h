// Host colour texels of the formats the renderer takes, decoded to linear RGBA floats as a
// shader would sample them (SRGB decoded, BGR swizzled, a missing alpha 1).
#pragma once

#include <vulkan/vulkan.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/gtc/packing.hpp>
#include <vector>

namespace siviflow::testing {

inline float srgb_to_linear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

// `pixels` texels of `format` at `data`, as 4 floats each; empty for a format not listed.
inline std::vector<float> decode_color(VkFormat format, const void* data, size_t pixels) {
  std::vector<float> out(pixels * 4);
  const auto* bytes = static_cast<const uint8_t*>(data);
  for (size_t i = 0; i < pixels; ++i) {
    float* rgba = &out[i * 4];
    uint32_t word = 0;
    switch (format) {
      case VK_FORMAT_R16G16B16A16_SFLOAT:
        for (int c = 0; c < 4; ++c) {
          uint16_t half;
          std::memcpy(&half, bytes + i * 8 + c * 2, 2);
          rgba[c] = glm::unpackHalf1x16(half);
        }
        break;
      case VK_FORMAT_R32G32B32A32_SFLOAT:
        std::memcpy(rgba, bytes + i * 16, 16);
        break;
      case VK_FORMAT_B10G11R11_UFLOAT_PACK32: {
        std::memcpy(&word, bytes + i * 4, 4);
        const glm::vec3 rgb = glm::unpackF2x11_1x10(word);
        rgba[0] = rgb.r;
        rgba[1] = rgb.g;
        rgba[2] = rgb.b;
        rgba[3] = 1.0f;
        break;
      }
      case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
        std::memcpy(&word, bytes + i * 4, 4);
        rgba[0] = static_cast<float>(word & 0x3ff) / 1023.0f;
        rgba[1] = static_cast<float>((word >> 10) & 0x3ff) / 1023.0f;
        rgba[2] = static_cast<float>((word >> 20) & 0x3ff) / 1023.0f;
        rgba[3] = static_cast<float>(word >> 30) / 3.0f;
        break;
      case VK_FORMAT_R8G8B8A8_UNORM:
      case VK_FORMAT_R8G8B8A8_SRGB:
      case VK_FORMAT_B8G8R8A8_UNORM:
      case VK_FORMAT_B8G8R8A8_SRGB: {
        const bool bgr = format == VK_FORMAT_B8G8R8A8_UNORM || format == VK_FORMAT_B8G8R8A8_SRGB;
        const bool srgb = format == VK_FORMAT_R8G8B8A8_SRGB || format == VK_FORMAT_B8G8R8A8_SRGB;
        for (int c = 0; c < 4; ++c) {
          const int source = bgr && c < 3 ? 2 - c : c;
          const float value = static_cast<float>(bytes[i * 4 + source]) / 255.0f;
          rgba[c] = srgb && c < 3 ? srgb_to_linear(value) : value;
        }
        break;
      }
      default:
        return {};
    }
  }
  return out;
}

}  // namespace siviflow::testing
