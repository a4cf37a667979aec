// `siviflow info`: the device, the driver, the required features and the validation layer.
#include <cstdio>
#include <memory>

#include "cli.h"
#include "commands.h"
#include "siviflow/headless_context.h"
#include "siviflow/renderer.h"

namespace siviflow {

int run_info(int argc, char** argv) {
  cli::ArgReader args(argc, argv, 2);
  while (!args.done()) {
    const std::string_view arg = args.next();
    if (arg == "--help" || arg == "-h") {
      std::printf("usage: siviflow info\n  Prints the Vulkan device SiViFlow would use.\n");
      return cli::kExitOk;
    }
    return cli::fail("info", "unknown argument '" + std::string(arg) + "'");
  }
  const bool layer = validation_layer_present();
  std::unique_ptr<HeadlessContext> context;
  const Status status = HeadlessContext::create(HeadlessContextOptions{}, &context);
  std::printf("validation layer VK_LAYER_KHRONOS_validation: %s\n", layer ? "present" : "missing");
  if (!status.ok()) return cli::fail("info", status.message());
  const DeviceReport& report = context->report();
  std::printf("device: %s\n", report.device_name.c_str());
  std::printf("driver: %s (%s)%s\n", report.driver_name.c_str(), report.driver_info.c_str(),
              report.driver_id == VK_DRIVER_ID_MESA_LLVMPIPE ? " [lavapipe]" : "");
  std::printf("api version: %u.%u.%u\n", VK_API_VERSION_MAJOR(report.api_version),
              VK_API_VERSION_MINOR(report.api_version), VK_API_VERSION_PATCH(report.api_version));
  std::printf("max image dimension: %u\n", report.max_image_dimension_2d);
  // The device was created with every required feature enabled, or creation failed naming them.
  for (const std::string& feature : required_device_feature_names()) {
    std::printf("required feature %s: supported, enabled\n", feature.c_str());
  }
  return cli::kExitOk;
}

}  // namespace siviflow
