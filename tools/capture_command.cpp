// `siviflow capture`: the offline frame-capture host. It plays the part of an embedding engine
// (own device, own command buffers and fences, own target images) and writes each frame to EXR.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "capture_check.h"
#include "capture_options.h"
#include "cli.h"
#include "commands.h"
#include "frame_writer.h"
#include "renderer_inspect.h"
#include "sim/half_float.h"
#include "siviflow/headless_context.h"
#include "siviflow/host_frame.h"
#include "siviflow/renderer.h"
#include "siviflow/scene_floats.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "capture";
// As plan_capture budgeted memory for.
constexpr uint32_t kFramesInFlight = kCaptureFramesInFlight;
constexpr VkFormat kOutputFormat = kCaptureColorFormat;
constexpr VkFormat kDepthFormat = kCaptureDepthFormat;

void print_help() {
  std::printf(
      "usage: siviflow capture [SCENE.json] [--frames N | --range A:B] [--size WxH] --out DIR\n"
      "                        [--seed S] [--fps F] [--aov LIST] [--preview] [--validation]\n"
      "                        [--resume] [--force] [--dry-run]\n"
      "  Renders the scene file (its render settings unless a flag says otherwise), or the\n"
      "  built-in default scene, into DIR/frame_NNNNN.exr. Each frame records what made it: the\n"
      "  scene's content (a SHA-256 of the scene file and every file it loads), fps, seed, size,\n"
      "  AOVs and software version. Frames of this capture already in DIR are rendered again;\n"
      "  a complete frame of another capture in the range, or the first one outside it, is\n"
      "  refused with exit 1, naming it and how it differs, unless --force.\n"
      "  --frames N     frames 0..N-1 (same as --range 0:N; default 1)\n"
      "  --range A:B    frames A..B-1; a frame is the same whatever range it is rendered in\n"
      "  --size WxH     output size in pixels (default 1280x720)\n"
      "  --out DIR      existing folder to write into (required)\n"
      "  --seed S       simulation seed, recorded in the EXR metadata (default 1)\n"
      "  --fps F        frames per second of scene time (default 30)\n"
      "  --aov LIST     comma list of extra EXR layers (docs/output.md has each one's units):\n"
      "                 depth      depth.Z: view-axis distance in metres to the nearest surface,\n"
      "                            water included; +inf where only sky is seen\n"
      "                 flow       flow.X/Y/Z: the flow texture upsampled (nearest) to the output,\n"
      "                            world space, m/s\n"
      "                 particles  particle.I (UINT): the id of the particle whose flow texel covers\n"
      "                            the pixel (0: none); and beside each frame\n"
      "                            frame_NNNNN.particles.csv: id,state,sx,sy,wx,wy,wz,fx,fy,fz,\n"
      "                            speed,depth,slope,fade\n"
      "                 normal     normal.X/Y/Z: the final water normal in world space\n"
      "                 reflection reflection.R/G/B: the reflection sample of the water before\n"
      "                            blending\n"
      "                 foam       foam.Y: how much of the water foam covers, 0 none to 1 full\n"
      "                 motion     motion.X/Y/Z/W: the nearest surface's screen motion in pixels,\n"
      "                            Blender's Vector pass layout (previous - now, now - next; y up)\n"
      "                 Each of flow, particles, normal, reflection and foam comes with water.A,\n"
      "                 1 where the river surface is visible, and is 0 wherever water.A is 0.\n"
      "  --preview      also write DIR/frame_NNNNN.png (sRGB, clamped)\n"
      "  --validation   run with the Khronos validation layer; any error fails the capture\n"
      "  --resume       render only the frames of the range that are missing or cannot be read\n"
      "                 whole; complete frames of this capture are left untouched\n"
      "  --force        render over the frames of another capture in the range (and beside\n"
      "                 those outside it) instead of refusing\n"
      "  --dry-run      check all the capture would before it asks for a device (the options,\n"
      "                 the scene file and every glTF file it names, its rivers and objects\n"
      "                 loaded, the AOVs against its rivers, the memory budget, the output folder\n"
      "                 and the frames in it), print the frames it would render, render nothing\n");
}

Status parse_options(int argc, char** argv, CaptureOptions* options, bool* help) {
  cli::ArgReader args(argc, argv, 2);
  std::string_view value;
  while (!args.done()) {
    const std::string_view arg = args.next();
    if (arg == "--help" || arg == "-h") {
      *help = true;
      return Status::success();
    } else if (arg == "--frames") {
      SIVIFLOW_TRY(args.value(arg, &value));
      uint32_t count = 0;
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &count));
      if (count == 0) return Status::error("--frames: must be at least 1");
      options->first_frame = 0;
      options->end_frame = count;
    } else if (arg == "--range") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_range(arg, value, &options->first_frame, &options->end_frame));
    } else if (arg == "--size") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_size(arg, value, &options->size));
      options->size_given = true;
    } else if (arg == "--out") {
      SIVIFLOW_TRY(args.value(arg, &value));
      options->out_dir = std::string(value);
    } else if (arg == "--seed") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &options->seed));
      options->seed_given = true;
    } else if (arg == "--fps") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_positive_float(arg, value, &options->fps));
      options->fps_given = true;
    } else if (arg == "--aov") {
      SIVIFLOW_TRY(args.value(arg, &value));
      for (const std::string& aov : cli::split_list(value)) {
        if (aov == "depth") {
          options->depth_aov = true;
        } else if (aov == "flow") {
          options->flow_aov = true;
        } else if (aov == "particles") {
          options->particles_aov = true;
        } else if (aov == "normal") {
          options->normal_aov = true;
        } else if (aov == "reflection") {
          options->reflection_aov = true;
        } else if (aov == "foam") {
          options->foam_aov = true;
        } else if (aov == "motion") {
          options->motion_aov = true;
        } else {
          return Status::error("--aov: unknown AOV '" + aov +
                               "' (available: depth, flow, particles, normal, reflection, foam, "
                               "motion)");
        }
      }
    } else if (arg == "--preview") {
      options->preview = true;
    } else if (arg == "--validation") {
      options->validation = true;
    } else if (arg == "--dry-run") {
      options->dry_run = true;
    } else if (arg == "--resume") {
      options->resume = true;
    } else if (arg == "--force") {
      options->force = true;
    } else if (!arg.empty() && arg[0] == '-') {
      return cli::unexpected_argument(arg);
    } else if (options->scene_path.empty()) {
      options->scene_path = std::string(arg);
    } else {
      return Status::error("unexpected argument '" + std::string(arg) + "': one scene file only");
    }
  }
  if (options->out_dir.empty()) return Status::error("--out DIR is required");
  return Status::success();
}

constexpr uint32_t index_of(ReadbackImage image) { return static_cast<uint32_t>(image); }

struct SlotTargets {
  HostBuffer readback[kReadbackImageCount];
  bool pending = false;  // a submitted frame whose readback has not been copied out yet
  uint32_t frame = 0;
  Camera camera;
  Camera previous_camera;  // with the motion AOV, and the bodies that move about this frame
  Camera next_camera;
  std::vector<MovingBody> bodies;  // the boulders and floats that move about this frame
  std::vector<Particle> particles;  // as simulated for this frame
};

class Capture {
 public:
  Capture(const CaptureOptions& options, CapturePlan plan)
      : options_(options), plan_(std::move(plan)) {}
  // The GPU may still run a frame after an error: let it finish before the renderer goes.
  ~Capture() {
    if (context_ != nullptr) (void)context_->wait_idle();
  }

  Status run();
  // After run(): the frames it wrote (the range, less the complete frames a resume kept).
  uint32_t frames_written() const { return frames_to_write_; }

 private:
  // With the motion AOV: the neighbouring frames' cameras and the boulders moving about `frame`.
  Status record_motion(uint32_t frame, SlotTargets* slot) const;
  // Moves the scene's floats on from `frame` to the next, through the water as updated for
  // `frame`; with a slot, first stands them in the world where they are at `frame` and, with the
  // motion AOV, adds them to the slot's moving bodies.
  Status step_floats(uint32_t frame, SlotTargets* slot);
  // Copies the slot's frame out of its readback buffers into `finished` (its buffers reused).
  void copy_out(const SlotTargets& slot, FinishedFrame* finished) const;
  void report_progress(uint32_t done_count);

  CaptureOptions options_;
  CapturePlan plan_;
  std::unique_ptr<HeadlessContext> context_;
  std::unique_ptr<World> world_;
  std::vector<std::unique_ptr<Renderer>> rivers_;  // one water renderer per river of the scene
  std::vector<Renderer*> river_renderers_;
  Renderer* renderer_ = nullptr;  // the last river's: it reads the frame back
  std::optional<SceneFloats> floats_;  // the scene's floats, if it has any
  std::vector<FloatPose> floats_before_;  // as they were in the frame before

  uint32_t frames_to_write_ = 0;  // the range, less the complete frames a resume keeps
  std::chrono::steady_clock::time_point started_;  // of the first rendered frame
};

Status Capture::run() {
  const size_t river_count = plan_.rivers.size();
  const std::vector<bool>& render = plan_.render;  // per frame of the range
  frames_to_write_ = static_cast<uint32_t>(std::count(render.begin(), render.end(), true));
  if (frames_to_write_ == 0) return Status::success();
  HeadlessContextOptions context_options;
  context_options.enable_validation = options_.validation;
  context_options.require_validation = options_.validation;
  SIVIFLOW_TRY(HeadlessContext::create(context_options, &context_));
  const uint32_t max_dimension = context_->report().max_image_dimension_2d;
  if (options_.size.width > max_dimension || options_.size.height > max_dimension) {
    return Status::error("--size " + std::to_string(options_.size.width) + "x" +
                         std::to_string(options_.size.height) + " exceeds the device limit of " +
                         std::to_string(max_dimension) + " pixels per side");
  }
  CreateInfo info = context_->renderer_create_info(
      {options_.size.width, options_.size.height}, kOutputFormat);
  info.frames_in_flight = kFramesInFlight;
  info.depth_format = kDepthFormat;
  info.seed = options_.seed;
  // Depth and motion are of the nearest surface, the water's included.
  info.write_depth = options_.depth_aov || options_.motion_aov;
  const SceneFile* scene = plan_.scene.has_value() ? &*plan_.scene : nullptr;
  info.look = scene != nullptr ? &scene->look : nullptr;
  WorldCreateInfo world_info = context_->world_create_info(kOutputFormat, kDepthFormat);
  world_info.frames_in_flight = kFramesInFlight;
  world_info.scene = scene;
  SIVIFLOW_TRY(World::create(world_info, &world_));
  info.reflection = &World::draw_reflection;
  info.reflection_user = world_.get();
  for (size_t i = 0; i < river_count; ++i) {
    const WaterRiver water = plan_.rivers[i].river();
    info.river = &water;
    info.river_copied = &SceneRiverData::release_arrays;  // the renderer holds its copy
    info.river_copied_user = &plan_.rivers[i];
    info.readback_images = i + 1 == river_count ? capture_readback_images(options_) : 0;
    rivers_.emplace_back();
    SIVIFLOW_TRY(Renderer::create(info, &rivers_.back()));
    SIVIFLOW_TRY(rivers_.back()->set_occluders(world_->occluders()));
    river_renderers_.push_back(rivers_.back().get());
  }
  renderer_ = river_renderers_.back();
  if (scene != nullptr && !scene->floats.empty()) {
    std::vector<WaterQueryFunction> queries;
    for (Renderer* river : river_renderers_) {
      queries.push_back([river](std::span<const glm::vec3> p, std::span<WaterSample> s) {
        return river->query_water(p, s);
      });
    }
    floats_.emplace();
    SIVIFLOW_TRY(SceneFloats::create(*scene, std::move(queries), &*floats_));
  }
  const VkExtent2D extent{options_.size.width, options_.size.height};
  // The particles and floats carry state from frame to frame: a shard starting at frame A first
  // advances them through frames 0..A-1, without rendering, so that its frames equal a full run's.
  for (uint32_t frame = 0; frame < options_.first_frame; ++frame) {
    const double time = static_cast<double>(frame) / options_.fps;
    const View view = camera_view(world_->scene_camera(time), extent);
    for (Renderer* river : river_renderers_) SIVIFLOW_TRY(river->simulate(view, time));
    SIVIFLOW_TRY(step_floats(frame, nullptr));
  }

  // One colour and depth target for every slot (12 bytes a pixel together, 100 MB at 3840x2160):
  // a frame's readback copy hands the colour on at the transfer stage, so the next frame,
  // whichever slot, waits on it in the queue, not on the fence of its own slot's frame; the depth
  // is handed on at the fragment tests, which a depth copy is chained into. Only the readback
  // buffers, read on the CPU after that fence, are the slots' own.
  HostTargets targets;
  const ImageState copied{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_NONE,
                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  SIVIFLOW_TRY(
      create_host_targets(*context_, kOutputFormat, kDepthFormat, extent, copied, &targets));
  std::vector<SlotTargets> slots(kFramesInFlight);
  for (SlotTargets& slot : slots) {
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      const auto kind = static_cast<ReadbackImage>(i);
      if ((info.readback_images & readback_bit(kind)) == 0) continue;
      SIVIFLOW_TRY(context_->create_readback_buffer(renderer_->readback_bytes(kind), &slot.readback[i]));
    }
  }

  uint32_t rendered = 0;
  SIVIFLOW_TRY(FrameWriter::start_encoding_threads());
  started_ = std::chrono::steady_clock::now();
  FrameWriter writer(options_, flow_texture_layout(*renderer_),
                     [this](uint32_t written) { report_progress(written); });
  for (uint32_t frame = options_.first_frame; frame < options_.end_frame; ++frame) {
    const double time = static_cast<double>(frame) / options_.fps;
    if (!render[frame - options_.first_frame]) {  // complete already: only its simulation
      const View view = camera_view(world_->scene_camera(time), extent);
      for (Renderer* river : river_renderers_) SIVIFLOW_TRY(river->simulate(view, time));
      SIVIFLOW_TRY(step_floats(frame, nullptr));
      continue;
    }
    const uint32_t index = rendered++ % kFramesInFlight;
    SlotTargets& slot = slots[index];
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    SIVIFLOW_TRY(context_->begin_slot(index, &cmd));  // waits for this slot's previous frame
    // Pipelined readback: the slot's previous frame is copied out, this frame is submitted, and
    // only then is the previous frame encoded and written, while the GPU renders.
    const bool have_finished = slot.pending;
    FinishedFrame finished;
    if (have_finished) {
      finished = writer.spare_frame();
      copy_out(slot, &finished);
    }
    for (Renderer* river : river_renderers_) SIVIFLOW_TRY(river->begin_frame(index));
    slot.camera = world_->scene_camera(time);
    if (options_.motion_aov) SIVIFLOW_TRY(record_motion(frame, &slot));
    const View view = camera_view(slot.camera, extent);
    for (Renderer* river : river_renderers_) SIVIFLOW_TRY(river->update(view, time));
    SIVIFLOW_TRY(step_floats(frame, &slot));
    const std::span<const Particle> particles = particle_field(*renderer_).particles();
    slot.particles.assign(particles.begin(), particles.end());
    ReadbackTargets readback;
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) readback.buffers[i] = slot.readback[i].buffer;
    SIVIFLOW_TRY(record_world_and_water(cmd, index, *world_, river_renderers_, view, time, readback,
                                        &targets));
    SIVIFLOW_TRY(context_->end_slot_and_submit(index));
    slot.pending = true;
    slot.frame = frame;
    if (have_finished) SIVIFLOW_TRY(writer.push(std::move(finished)));
  }
  // Drain: the last frames, at most one per slot, in submission order.
  for (uint32_t i = rendered > kFramesInFlight ? rendered - kFramesInFlight : 0; i < rendered;
       ++i) {
    SlotTargets& slot = slots[i % kFramesInFlight];
    SIVIFLOW_TRY(context_->wait_slot(i % kFramesInFlight));
    FinishedFrame finished = writer.spare_frame();
    copy_out(slot, &finished);
    SIVIFLOW_TRY(writer.push(std::move(finished)));
    slot.pending = false;
  }
  SIVIFLOW_TRY(writer.finish());
  if (context_->report().validation_enabled && context_->validation_error_count() > 0) {
    return Status::error(std::to_string(context_->validation_error_count()) +
                         " Vulkan validation error(s); the first: " +
                         context_->validation_errors().front());
  }
  return Status::success();
}

Status Capture::record_motion(uint32_t frame, SlotTargets* slot) const {
  const double time = static_cast<double>(frame) / options_.fps;
  const double before = (static_cast<double>(frame) - 1.0) / options_.fps;
  const double after = (static_cast<double>(frame) + 1.0) / options_.fps;
  slot->previous_camera = world_->scene_camera(before);
  slot->next_camera = world_->scene_camera(after);
  slot->bodies.clear();
  for (uint32_t i = 0; i < world_->boulder_count(); ++i) {
    BoulderPose then;
    BoulderPose now;
    BoulderPose later;
    SIVIFLOW_TRY(world_->boulder_at(i, before, &then));
    SIVIFLOW_TRY(world_->boulder_at(i, time, &now));
    SIVIFLOW_TRY(world_->boulder_at(i, after, &later));
    if (!now.shown || (then.centre == now.centre && later.centre == now.centre)) continue;
    slot->bodies.push_back({then.centre, now.centre, later.centre, now.radii});
  }
  return Status::success();
}

Status Capture::step_floats(uint32_t frame, SlotTargets* slot) {
  if (!floats_) return Status::success();
  const std::vector<FloatPose> now(floats_->poses().begin(), floats_->poses().end());
  SIVIFLOW_TRY(floats_->advance(static_cast<double>(frame + 1) / options_.fps));
  const std::span<const FloatPose> next = floats_->poses();
  for (uint32_t i = 0; slot != nullptr && i < now.size(); ++i) {
    if (!now[i].shown) {
      SIVIFLOW_TRY(world_->hide_float(i));
      continue;
    }
    SIVIFLOW_TRY(world_->place_float(i, now[i].centre, now[i].heading));
    if (!options_.motion_aov) continue;
    const bool before_shown = !floats_before_.empty() && floats_before_[i].shown;
    glm::vec3 reach;
    SIVIFLOW_TRY(world_->float_reach(i, &reach));
    slot->bodies.push_back({before_shown ? floats_before_[i].centre : now[i].centre, now[i].centre,
                            next[i].centre, reach, true});
  }
  floats_before_ = now;
  return Status::success();
}

void Capture::copy_out(const SlotTargets& slot, FinishedFrame* finished) const {
  const size_t pixels = size_t{options_.size.width} * options_.size.height;
  finished->frame = slot.frame;
  finished->camera = slot.camera;
  finished->previous_camera = slot.previous_camera;
  finished->next_camera = slot.next_camera;
  finished->bodies = slot.bodies;
  // Each read-back image's bytes; the images not read back are left empty.
  const auto copy = [&slot](ReadbackImage kind, size_t count, auto* out) {
    using T = typename std::remove_reference_t<decltype(*out)>::value_type;
    const auto* data = static_cast<const T*>(slot.readback[index_of(kind)].data);
    if (data == nullptr) return;
    out->assign(data, data + count);
  };
  copy(ReadbackImage::kColor, pixels * 4, &finished->color_halves);
  copy(ReadbackImage::kDepth, pixels, &finished->window_depth);
  copy(ReadbackImage::kWaterMask, pixels, &finished->water_mask);
  copy(ReadbackImage::kFlowTexture, renderer_->readback_bytes(ReadbackImage::kFlowTexture),
       &finished->flow_texture);
  // The layers written as HALF are converted as they are copied: a pass over them saved.
  const auto copy_as_halves = [&slot](ReadbackImage kind, size_t count,
                                      std::vector<uint16_t>* out) {
    const auto* data = static_cast<const float*>(slot.readback[index_of(kind)].data);
    if (data == nullptr) return;
    out->resize(count);
    to_halves({data, count}, *out);
  };
  copy_as_halves(ReadbackImage::kNormal, pixels * 4, &finished->normal);
  copy_as_halves(ReadbackImage::kReflection, pixels * 4, &finished->reflection);
  copy_as_halves(ReadbackImage::kFoam, pixels, &finished->foam);
  finished->particles = slot.particles;
}



void Capture::report_progress(uint32_t done_count) {
  const uint32_t total = frames_to_write_;
  // Frames per second over the frames written so far, and the time the rest take at that pace.
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const double fps = seconds > 0.0 ? done_count / seconds : 0.0;
  const double left = fps > 0.0 ? (total - done_count) / fps : 0.0;
  const long whole = std::lround(left);
  const std::string time_left =
      whole >= 3600 ? text_format("%ld h %02ld min", whole / 3600, whole / 60 % 60)
      : whole >= 60 ? text_format("%ld min %02ld s", whole / 60, whole % 60)
                    : text_format("%ld s", whole);
  if (isatty(STDOUT_FILENO)) {
    constexpr int kBarWidth = 40;
    const int filled = static_cast<int>(kBarWidth * done_count / total);
    std::printf("\r[%s%s] %u/%u %.2f frames/s, %s left   ", std::string(filled, '#').c_str(),
                std::string(kBarWidth - filled, ' ').c_str(), done_count, total, fps,
                time_left.c_str());
    if (done_count == total) std::printf("\n");
    std::fflush(stdout);
  } else if (done_count % 10 == 0 || done_count == total) {
    std::printf("captured %u/%u frames, %.2f frames/s, %s left\n", done_count, total, fps,
                time_left.c_str());
  }
}

}  // namespace

int run_capture(int argc, char** argv) {
  CaptureOptions options;
  bool help = false;
  Status status = parse_options(argc, argv, &options, &help);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  if (help) {
    print_help();
    return cli::kExitOk;
  }
  CapturePlan plan;
  try {
    status = plan_capture(&options, &plan);
  } catch (const std::exception& e) {  // std::bad_alloc loading the scene: stop, with why
    status = Status::error(std::string("capture stopped: ") + e.what());
  }
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const uint32_t range = options.end_frame - options.first_frame;
  const auto to_render =
      static_cast<uint32_t>(std::count(plan.render.begin(), plan.render.end(), true));
  if (options.dry_run) {
    std::printf("would render frames %u..%u of %s at %ux%u to %s/frame_NNNNN.exr",
                options.first_frame, options.end_frame - 1,
                options.scene_path.empty() ? "the default scene" : options.scene_path.c_str(),
                options.size.width, options.size.height, options.out_dir.c_str());
    if (options.resume) std::printf("; %u are complete and kept", range - to_render);
    std::printf("\n");
    return cli::kExitOk;
  }
  Capture capture(options, std::move(plan));
  try {
    status = capture.run();
  } catch (const std::exception& e) {  // std::bad_alloc copying a frame out: stop, with why
    status = Status::error(std::string("capture stopped: ") + e.what());
  }
  if (!status.ok()) return cli::fail(kCommand, status.message());
  std::printf("wrote %u of frames %u..%u to %s/frame_NNNNN.exr%s", capture.frames_written(),
              options.first_frame, options.end_frame - 1, options.out_dir.c_str(),
              options.preview ? " (+ .png)" : "");
  if (options.resume) std::printf("; %u were complete", range - capture.frames_written());
  std::printf("\n");
  return cli::kExitOk;
}

}  // namespace siviflow
