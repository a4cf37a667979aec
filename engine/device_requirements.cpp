// The device features the water renderer needs (renderer.h), and the check that names each one
// a feature chain lacks.
#include <array>
#include <string>
#include <vector>

#include "siviflow/renderer.h"

namespace siviflow {
namespace {

struct FeatureSet {
  bool shader_clip_distance = false;
  bool independent_blend = false;
  bool dynamic_rendering = false;
  bool synchronization2 = false;
};

// Reads the features we need from a chain, whether the host used the Vulkan 1.3 struct or the
// per-feature structs that were promoted into it.
FeatureSet read_chain(const VkPhysicalDeviceFeatures2* features) {
  FeatureSet set;
  if (features == nullptr) return set;
  set.shader_clip_distance = features->features.shaderClipDistance == VK_TRUE;
  set.independent_blend = features->features.independentBlend == VK_TRUE;
  for (auto* node = static_cast<const VkBaseInStructure*>(features->pNext); node != nullptr;
       node = node->pNext) {
    switch (node->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES: {
        const auto* v13 = reinterpret_cast<const VkPhysicalDeviceVulkan13Features*>(node);
        set.dynamic_rendering |= v13->dynamicRendering == VK_TRUE;
        set.synchronization2 |= v13->synchronization2 == VK_TRUE;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES:
        set.dynamic_rendering |=
            reinterpret_cast<const VkPhysicalDeviceDynamicRenderingFeatures*>(node)->dynamicRendering == VK_TRUE;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES:
        set.synchronization2 |=
            reinterpret_cast<const VkPhysicalDeviceSynchronization2Features*>(node)->synchronization2 == VK_TRUE;
        break;
      default:
        break;
    }
  }
  return set;
}

}  // namespace

RequiredDeviceFeatures required_device_features() {
  RequiredDeviceFeatures required;
  required.features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  required.features2.features.shaderClipDistance = VK_TRUE;  // reflection clip plane
  required.features2.features.independentBlend = VK_TRUE;    // water blends, its AOVs do not
  required.vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  required.vulkan13.dynamicRendering = VK_TRUE;   // every pass renders without render passes
  required.vulkan13.synchronization2 = VK_TRUE;   // every barrier is a VkDependencyInfo
  required.link();
  return required;
}

std::vector<std::string> required_device_feature_names() {
  return {"shaderClipDistance", "independentBlend", "dynamicRendering", "synchronization2"};
}

std::vector<std::string> missing_device_features(const VkPhysicalDeviceFeatures2* features) {
  const FeatureSet set = read_chain(features);
  const std::array<bool, 4> present = {set.shader_clip_distance, set.independent_blend,
                                       set.dynamic_rendering, set.synchronization2};
  const std::vector<std::string> names = required_device_feature_names();
  std::vector<std::string> missing;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!present[i]) missing.push_back(names[i]);
  }
  return missing;
}

}  // namespace siviflow
