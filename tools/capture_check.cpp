#include "capture_check.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <span>
#include <string>

#include "scene/scene_objects.h"
#include "siviflow/frame_folder.h"
#include "siviflow/renderer.h"
#include "siviflow/scene_digest.h"
#include "siviflow/text_format.h"
#include "siviflow/version.h"

namespace siviflow {
namespace {

// Lavapipe does not enforce its 2 GiB heap (reliability notes), so the capture enforces a budget
// on what grows with the size: the renderers' views, the host's colour (RGBA16F) and depth (D32)
// that every frame in flight shares, and per frame in flight the readback buffers.
constexpr uint64_t kHostBytesPerPixel = 8 + 4;
constexpr uint64_t kMaxCaptureBytes = 2ull << 30;

Status check_output_dir(const std::string& dir) {
  struct stat info {};
  if (stat(dir.c_str(), &info) != 0) {
    return Status::error("output folder '" + dir + "': " + std::strerror(errno));
  }
  if (!S_ISDIR(info.st_mode)) return Status::error("output folder '" + dir + "' is not a folder");
  if (access(dir.c_str(), W_OK | X_OK) != 0) {
    return Status::error("output folder '" + dir + "' is not writable: " + std::strerror(errno));
  }
  return Status::success();
}

Status check_aovs(const CaptureOptions& options, size_t river_count) {
  if (river_count > 1 && water_layers(options)) {
    return Status::error(
        "--aov flow, particles, normal, reflection and foam are of one river; the scene has " +
        std::to_string(river_count) + " (depth works with any number)");
  }
  return Status::success();
}

// Refuses, before anything is allocated, a size and AOV set over the budget, with the figure it
// would need: the colour, and what the requested AOVs are made from.
Status check_memory_budget(const CaptureOptions& options, size_t river_count) {
  CreateInfo info;
  info.extent = {options.size.width, options.size.height};
  info.color_format = kCaptureColorFormat;
  info.depth_format = kCaptureDepthFormat;
  info.frames_in_flight = kCaptureFramesInFlight;
  const uint64_t pixels = uint64_t{options.size.width} * options.size.height;
  uint64_t needed = pixels * kHostBytesPerPixel;
  for (size_t i = 0; i < river_count; ++i) {  // the last river's renderer reads back
    info.readback_images = i + 1 == river_count ? capture_readback_images(options) : 0;
    ViewMemory view;
    SIVIFLOW_TRY(view_memory(info, &view));
    needed += view.renderer_bytes + kCaptureFramesInFlight * view.readback_bytes;
  }
  if (needed <= kMaxCaptureBytes) return Status::success();
  return Status::error(text_format(
      "--size %ux%u (with the AOVs asked for) needs %llu MiB of device memory (the renderers' "
      "images and staging, the colour and depth targets, the frames' readback buffers), more than "
      "the %llu MiB budget",
      options.size.width, options.size.height,
      static_cast<unsigned long long>((needed + (1u << 20) - 1) >> 20),
      static_cast<unsigned long long>(kMaxCaptureBytes >> 20)));
}

// What every frame of this capture carries: what a resumed capture trusts a frame by.
FrameExpectation frame_expectation(const CaptureOptions& options) {
  FrameExpectation expected;
  expected.scene_digest = options.scene_digest;
  expected.fps = options.fps;
  expected.seed = static_cast<int>(options.seed);
  expected.width = static_cast<int>(options.size.width);
  expected.height = static_cast<int>(options.size.height);
  expected.aovs = aov_names(options);
  // Each channel with its pixel type: every water layer and the motion are HALF, depth FLOAT.
  std::vector<std::string>& names = expected.channels;
  const auto add = [&names](std::span<const char* const> channels, const char* type) {
    for (const char* channel : channels) names.push_back(text_format("%s:%s", channel, type));
  };
  const char* const beauty[] = {"R", "G", "B", "A"};
  add(beauty, "half");
  if (options.depth_aov) add({&kDepthChannel, 1}, "float");
  if (water_layers(options)) add({&kWaterMaskChannel, 1}, "half");
  if (options.flow_aov) add(kFlowChannels, "half");
  if (options.particles_aov) add({&kParticleIdChannel, 1}, "uint");
  if (options.normal_aov) add(kNormalChannels, "half");
  if (options.reflection_aov) add(kReflectionChannels, "half");
  if (options.foam_aov) add({&kFoamChannel, 1}, "half");
  if (options.motion_aov) add(kMotionChannels, "half");
  std::sort(names.begin(), names.end());
  expected.software_version = version_string();
  return expected;
}

// Which frames of the range to render. A frame of another capture is refused, naming it, unless
// --force: in the range, where it would be overwritten, or the folder's first complete frame
// outside it, where the folder would mix two captures. Frames of this capture are rendered
// again, unless --resume keeps the complete ones.
Status frames_to_render(const CaptureOptions& options, std::vector<bool>* render) {
  render->assign(options.end_frame - options.first_frame, true);
  // Then every frame of the range is rendered whatever the folder holds, and nothing it holds is
  // read: a frame is read whole to be checked (3840x2160 with every AOV: 400 MB and a second).
  if (options.force && !options.resume) return Status::success();
  const FrameExpectation expected = frame_expectation(options);
  const std::string folder = options.out_dir + "/";
  for (uint32_t frame = options.first_frame; frame < options.end_frame; ++frame) {
    const FrameCheck check = check_frame(options.out_dir, frame, expected, "this capture");
    if (check.state == FrameState::kMismatch && !options.force) {
      return Status::error(folder + frame_file_name(frame) + " " + check.problem +
                           "; nothing was overwritten (--force re-renders such frames)");
    }
    if (options.resume)
      (*render)[frame - options.first_frame] = check.state != FrameState::kComplete;
  }
  if (options.force) return Status::success();  // with --resume
  std::vector<uint32_t> present;
  SIVIFLOW_TRY(list_frames(options.out_dir, &present));
  for (uint32_t frame : present) {
    if (frame >= options.first_frame && frame < options.end_frame) continue;
    const FrameCheck check = check_frame(options.out_dir, frame, expected, "this capture");
    if (check.state == FrameState::kMismatch) {
      return Status::error(folder + frame_file_name(frame) + ", outside the range, " +
                           check.problem +
                           ": the folder holds another capture (--force renders beside it)");
    }
    if (check.state == FrameState::kComplete) break;  // one frame stands for the folder
  }
  return Status::success();
}

}  // namespace

uint32_t capture_readback_images(const CaptureOptions& options) {
  uint32_t images = readback_bit(ReadbackImage::kColor);
  if (options.depth_aov || options.motion_aov) images |= readback_bit(ReadbackImage::kDepth);
  if (water_layers(options) || options.motion_aov) {
    images |= readback_bit(ReadbackImage::kWaterMask);
  }
  if (options.flow_aov || options.particles_aov) {
    images |= readback_bit(ReadbackImage::kFlowTexture);
  }
  if (options.normal_aov) images |= readback_bit(ReadbackImage::kNormal);
  if (options.reflection_aov) images |= readback_bit(ReadbackImage::kReflection);
  if (options.foam_aov) images |= readback_bit(ReadbackImage::kFoam);
  return images;
}

Status plan_capture(CaptureOptions* options, CapturePlan* out) {
  CapturePlan plan;
  SIVIFLOW_TRY(check_output_dir(options->out_dir));
  if (!options->scene_path.empty()) {
    SceneFile& scene = plan.scene.emplace();
    SIVIFLOW_TRY(load_scene_file(options->scene_path, &scene));
    // The scene's render settings, unless a flag said otherwise.
    if (!options->size_given) options->size = {scene.render.width, scene.render.height};
    if (!options->fps_given) options->fps = static_cast<float>(scene.render.fps);
    if (!options->seed_given) options->seed = scene.render.seed;
  }
  const SceneFile* scene = plan.scene ? &*plan.scene : nullptr;
  const size_t river_count = scene != nullptr ? scene->rivers.size() : 1;
  SIVIFLOW_TRY(check_aovs(*options, river_count));
  SIVIFLOW_TRY(check_memory_budget(*options, river_count));
  plan.rivers.resize(river_count);
  for (size_t i = 0; i < river_count; ++i) {
    SIVIFLOW_TRY(scene_river_data(scene, i, &plan.rivers[i]));
  }
  if (scene != nullptr) {
    SceneObjects objects;  // only checked here: the world loads its own
    SIVIFLOW_TRY(load_scene_objects(*scene, &objects));
  }
  SIVIFLOW_TRY(scene_content_digest(scene, &options->scene_digest));
  SIVIFLOW_TRY(frames_to_render(*options, &plan.render));
  *out = std::move(plan);
  return Status::success();
}

}  // namespace siviflow
