// What create() and view_memory() refuse of a CreateInfo without asking a device (its sizes,
// formats and placement), in one place so that the two refuse exactly the same, in the same
// words.
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <string>

#include "renderer_impl.h"
#include "siviflow/sim/world_limits.h"
#include "siviflow/text_format.h"
#include "vk/vk_text.h"

namespace siviflow {
namespace {

constexpr uint32_t kMaxFramesInFlight = 8;

bool is_host_depth_format(VkFormat format) {
  return format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D24_UNORM_S8_UINT ||
         format == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

// A two-channel float format: motion vectors are signed fractions of the viewport.
bool is_motion_format(VkFormat format) {
  return format == VK_FORMAT_R16G16_SFLOAT || format == VK_FORMAT_R32G32_SFLOAT;
}

// One float or normalized channel: the reactive mask is a fraction, and a channel the water
// does not write could not keep the host's values.
bool is_reactive_format(VkFormat format) {
  return format == VK_FORMAT_R8_UNORM || format == VK_FORMAT_R16_UNORM ||
         format == VK_FORMAT_R16_SFLOAT || format == VK_FORMAT_R32_SFLOAT;
}

// Whether the matrix is finite and affine (last row 0 0 0 1); the determinant of its linear part
// in `det`, which says whether it can be inverted.
bool finite_affine(const glm::mat4& m, float* det) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return false;
    }
  }
  *det = glm::determinant(glm::mat3(m));
  return m[0][3] == 0.0f && m[1][3] == 0.0f && m[2][3] == 0.0f && m[3][3] == 1.0f;
}

// The most a placement may scale an axis by, either way.
constexpr float kMaxPlacementScale = 1000.0f;

}  // namespace

Status check_create_info(const CreateInfo& info) {
  if (info.extent.width == 0 || info.extent.height == 0) {
    return argument_error("CreateInfo::extent must be at least 1x1");
  }
  if (info.frames_in_flight > kMaxFramesInFlight) {
    return argument_error("CreateInfo::frames_in_flight " + std::to_string(info.frames_in_flight) +
                          " exceeds " + std::to_string(kMaxFramesInFlight));
  }
  if (info.color_format == VK_FORMAT_UNDEFINED) {
    return argument_error(
        "CreateInfo::color_format is VK_FORMAT_UNDEFINED: name the format of the host's colour "
        "image");
  }
  if (color_channel_count(info.color_format) < 3) {
    return argument_error("CreateInfo::color_format " + format_name(info.color_format) +
                          " is not an uncompressed colour format with red, green and blue");
  }
  if (info.depth_format != VK_FORMAT_UNDEFINED && !is_host_depth_format(info.depth_format)) {
    return argument_error("CreateInfo::depth_format " + format_name(info.depth_format) +
                          " is not VK_FORMAT_D32_SFLOAT, VK_FORMAT_D24_UNORM_S8_UINT or "
                          "VK_FORMAT_D32_SFLOAT_S8_UINT");
  }
  if (info.motion_format != VK_FORMAT_UNDEFINED && !is_motion_format(info.motion_format)) {
    return argument_error("CreateInfo::motion_format " + format_name(info.motion_format) +
                          " is not VK_FORMAT_R16G16_SFLOAT or VK_FORMAT_R32G32_SFLOAT");
  }
  if (info.reactive_format != VK_FORMAT_UNDEFINED && !is_reactive_format(info.reactive_format)) {
    return argument_error("CreateInfo::reactive_format " + format_name(info.reactive_format) +
                          " is not VK_FORMAT_R8_UNORM, VK_FORMAT_R16_UNORM, VK_FORMAT_R16_SFLOAT "
                          "or VK_FORMAT_R32_SFLOAT");
  }
  if ((info.readback_images & ~kAllReadbackImages) != 0) {
    return argument_error("CreateInfo::readback_images 0x" +
                          text_format("%x", info.readback_images) + " has bits past the " +
                          std::to_string(kReadbackImageCount) + " ReadbackImage values");
  }
  float det = 0.0f;
  if (!finite_affine(info.world_from_river, &det) || !(std::abs(det) > 1e-12f) ||
      !std::isfinite(1.0f / det)) {
    const glm::mat4& m = info.world_from_river;
    std::string rows;
    for (int r = 0; r < 4; ++r) {
      rows += text_format("%s[%g %g %g %g]", r == 0 ? "" : " ", m[0][r], m[1][r], m[2][r], m[3][r]);
    }
    return argument_error("CreateInfo::world_from_river " + rows +
                          " is not a finite, invertible affine transform (last row 0 0 0 1)");
  }
  // Finite is not enough: a placement that stretches or shrinks an axis past a thousand, or
  // moves the river past the world limit, leaves the river's centimetres (or the host's, brought
  // back by its inverse) to float rounding.
  const glm::mat4& m = info.world_from_river;
  for (int c = 0; c < 3; ++c) {
    const double scale = glm::length(glm::dvec3(glm::vec3(m[c])));  // doubles: 1e30 squared overflows a float
    if (!(scale >= 1.0f / kMaxPlacementScale && scale <= kMaxPlacementScale)) {
      return argument_error(text_format("CreateInfo::world_from_river scales axis %d by %g: a "
                                        "placement (a rotation, at most a moderate scale) keeps "
                                        "each axis's scale within [1/%g, %g]",
                                        c, scale, double(kMaxPlacementScale),
                                        double(kMaxPlacementScale)));
    }
  }
  if (!within_world(glm::vec3(m[3]))) {
    return argument_error("CreateInfo::world_from_river's translation " +
                          world_limit_problem(glm::vec3(m[3])));
  }
  return Status::success();
}

}  // namespace siviflow
