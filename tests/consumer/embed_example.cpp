// Embeds an installed SiViFlow as an engine would: the host owns the device (here the small
// headless host), the command buffer and the target image; SiViFlow records one frame into it.
// Exits 0 only when the frame rendered, read back non-black, with no validation error.
#include <cstdio>
#include <memory>

#include <siviflow/headless_context.h>
#include <siviflow/renderer.h>

int main() {
  using namespace siviflow;
  HeadlessContextOptions options;
  options.enable_validation = true;
  options.require_validation = true;
  std::unique_ptr<HeadlessContext> host;
  Status status = HeadlessContext::create(options, &host);
  if (!status.ok()) return std::fprintf(stderr, "%s\n", status.message().c_str()), 1;

  CreateInfo info = host->renderer_create_info({64, 36}, VK_FORMAT_R8G8B8A8_UNORM);
  info.enable_readback = true;
  std::unique_ptr<Renderer> renderer;
  status = Renderer::create(info, &renderer);
  if (!status.ok()) return std::fprintf(stderr, "%s\n", status.message().c_str()), 1;

  HostImage target;
  if (!host->create_target_image(VK_FORMAT_R8G8B8A8_UNORM, {64, 36}, &target).ok()) return 1;
  HostBuffer readback[kReadbackImageCount];
  FrameInputs inputs;
  for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
    if (!host->create_readback_buffer(renderer->readback_bytes(static_cast<ReadbackImage>(i)), &readback[i]).ok()) {
      return 1;
    }
    inputs.readback.buffers[i] = readback[i].buffer;
  }
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  inputs.output = {target.image, target.view, ImageState{},
                   {VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_GENERAL}};
  if (!host->begin_slot(0, &cmd).ok() || !renderer->begin_frame(0).ok() ||
      !renderer->update(renderer->scene_camera(0.0), 0.0).ok() || !renderer->record(cmd, inputs).ok() ||
      !host->end_slot_and_submit(0).ok() || !host->wait_slot(0).ok()) {
    return std::fprintf(stderr, "frame failed\n"), 1;
  }
  const auto* texels = static_cast<const unsigned char*>(readback[0].data);
  unsigned long sum = 0;
  for (int i = 0; i < 64 * 36 * 4; ++i) sum += texels[i];
  renderer.reset();
  const unsigned errors = host->validation_error_count();
  std::printf("mean texel %.1f, validation errors %u\n", sum / (64.0 * 36 * 4), errors);
  return sum > 0 && errors == 0 ? 0 : 1;
}
