// Embeds an installed SiViFlow as an engine would: the host owns the device (here the small
// headless host), the command buffer and its colour and depth images; it draws its world into
// them (here the built-in one), and SiViFlow records the water over them.
// Exits 0 only when the frame rendered, read back non-black, with no validation error.
#include <cstdio>
#include <memory>

#include <siviflow/headless_context.h>
#include <siviflow/host_frame.h>
#include <siviflow/renderer.h>
#include <siviflow/world.h>

int main() {
  using namespace siviflow;
  HeadlessContextOptions options;
  options.enable_validation = true;
  options.require_validation = true;
  std::unique_ptr<HeadlessContext> host;
  Status status = HeadlessContext::create(options, &host);
  if (!status.ok()) return std::fprintf(stderr, "%s\n", status.message().c_str()), 1;

  const VkExtent2D extent{64, 36};
  const VkFormat color = VK_FORMAT_R8G8B8A8_UNORM;
  const VkFormat depth = VK_FORMAT_D32_SFLOAT;
  std::unique_ptr<World> world;
  status = World::create(host->world_create_info(color, depth), &world);
  if (!status.ok()) return std::fprintf(stderr, "%s\n", status.message().c_str()), 1;
  CreateInfo info = host->renderer_create_info(extent, color);
  info.depth_format = depth;
  info.readback_images = kAllReadbackImages;
  info.reflection = &World::draw_reflection;
  info.reflection_user = world.get();
  std::unique_ptr<Renderer> renderer;
  status = Renderer::create(info, &renderer);
  if (!status.ok()) return std::fprintf(stderr, "%s\n", status.message().c_str()), 1;

  HostTargets targets;
  if (!create_host_targets(*host, color, depth, extent,
                           {VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_GENERAL},
                           &targets).ok()) {
    return 1;
  }
  HostBuffer readback[kReadbackImageCount];
  ReadbackTargets buffers;
  for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
    if (!host->create_readback_buffer(renderer->readback_bytes(static_cast<ReadbackImage>(i)), &readback[i]).ok()) {
      return 1;
    }
    buffers.buffers[i] = readback[i].buffer;
  }
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  const View view = camera_view(world->scene_camera(0.0), extent);
  if (!host->begin_slot(0, &cmd).ok() || !renderer->begin_frame(0).ok() ||
      !renderer->update(view, 0.0).ok() ||
      !record_world_and_water(cmd, 0, *world, *renderer, view, 0.0, buffers, &targets).ok() ||
      !host->end_slot_and_submit(0).ok() || !host->wait_slot(0).ok()) {
    return std::fprintf(stderr, "frame failed\n"), 1;
  }
  const auto* texels = static_cast<const unsigned char*>(readback[0].data);
  unsigned long sum = 0;
  for (int i = 0; i < 64 * 36 * 4; ++i) sum += texels[i];
  renderer.reset();
  world.reset();
  const unsigned errors = host->validation_error_count();
  std::printf("mean texel %.1f, validation errors %u\n", sum / (64.0 * 36 * 4), errors);
  return sum > 0 && errors == 0 ? 0 : 1;
}
