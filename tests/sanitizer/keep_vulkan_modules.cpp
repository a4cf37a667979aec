// Preloaded into the GPU test programs (and the siviflow processes they start) of an
// AddressSanitizer build: opens the lavapipe driver and the Vulkan layers they load with
// RTLD_NODELETE, so they stay mapped to the end of the process. The Vulkan loader unloads them at
// vkDestroyInstance; what their globals still held would then be reported as leaks from an
// "unknown module" that no suppression can name. Opened RTLD_LOCAL: none of their symbols can
// stand in for the loader's vk* functions.
#include <dlfcn.h>

namespace {

struct KeepVulkanModules {
  KeepVulkanModules() {
    const char* modules[] = {SIVIFLOW_LAVAPIPE_LIBRARY, "libVkLayer_khronos_validation.so",
                             "libVkLayer_MESA_device_select.so"};
    for (const char* module : modules) dlopen(module, RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);
  }
};
const KeepVulkanModules keep;

}  // namespace
