// The device features SiViFlow needs, and the check that names each one a device lacks.
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "siviflow/headless_context.h"
#include "siviflow/renderer.h"

namespace siviflow {
namespace {

// Testing hook: a comma list of feature names to report as missing, so the "missing feature"
// path can be exercised on lavapipe, which has them all.
bool hidden_by_environment(const char* feature) {
  const char* hidden = std::getenv("SIVIFLOW_HIDE_DEVICE_FEATURES");
  if (hidden == nullptr) return false;
  std::stringstream list(hidden);
  std::string item;
  while (std::getline(list, item, ',')) {
    if (item == feature) return true;
  }
  return false;
}

}  // namespace

RequiredDeviceFeatures required_device_features() {
  RequiredDeviceFeatures required;
  required.features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  required.features2.features.shaderClipDistance = VK_TRUE;  // reflection clip plane
  required.vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  required.vulkan13.dynamicRendering = VK_TRUE;
  required.vulkan13.synchronization2 = VK_TRUE;
  required.vulkan13.maintenance4 = VK_TRUE;  // glslang's vulkan1.3 compute output needs it
  required.link();
  return required;
}

std::vector<std::string> missing_required_features(PFN_vkGetInstanceProcAddr get_instance_proc_addr,
                                                   VkInstance instance, VkPhysicalDevice device) {
  auto get_features = reinterpret_cast<PFN_vkGetPhysicalDeviceFeatures2>(
      get_instance_proc_addr(instance, "vkGetPhysicalDeviceFeatures2"));
  VkPhysicalDeviceVulkan13Features vulkan13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features2.pNext = &vulkan13;
  get_features(device, &features2);

  std::vector<std::string> missing;
  const auto check = [&](bool present, const char* name) {
    if (!present || hidden_by_environment(name)) missing.emplace_back(name);
  };
  check(features2.features.shaderClipDistance, "shaderClipDistance");
  check(vulkan13.dynamicRendering, "dynamicRendering");
  check(vulkan13.synchronization2, "synchronization2");
  check(vulkan13.maintenance4, "maintenance4");
  return missing;
}

}  // namespace siviflow
