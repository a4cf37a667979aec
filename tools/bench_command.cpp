// `siviflow bench`: GPU time per pass (timestamp queries) and CPU time per stage of a scene file's
// or the default scene's frames, with the flow pass's floor measured in the same run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "commands.h"
#include "siviflow/headless_context.h"
#include "siviflow/host_frame.h"
#include "siviflow/renderer.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "bench";
constexpr const char* kFloorPass = "flow floor";
// The flow pass is its tile table (compute) then its material: "flow" reports both together,
// so flow / floor counts all the work the water costs beyond its texture reads.
constexpr const char* kTilePass = "flow tiles";
constexpr const char* kMaterialPass = "flow material";
constexpr VkFormat kOutputFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct BenchOptions {
  std::string scene_path;  // empty: the built-in default scene
  cli::Size size{1280, 720};
  bool size_given = false;  // a flag wins over the scene file's render size
  uint32_t frames = 60;
  uint32_t warmup = 10;
  bool json = false;
  bool second_view = false;  // also a second view of the same river (a probe 4 s ahead)
  bool motion = false;       // the water writes motion vectors and a reactive mask too
};

constexpr double kSecondViewAhead = 4.0;  // seconds ahead on the camera path

struct Stats {
  double median = 0.0;
  double min = 0.0;
  double max = 0.0;
};

Stats stats_of(std::vector<double> values) {
  if (values.empty()) return {};
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  const double median = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return {median, values.front(), values.back()};
}

void print_help() {
  std::printf(
      "usage: siviflow bench [SCENE.json] [--size WxH] [--frames N] [--warmup W] [--json]\n"
      "                      [--second-view] [--motion]\n"
      "  Renders the scene file (at its render size unless --size says otherwise) or the\n"
      "  default scene (1280x720): W warm-up frames (default 10), then N measured frames\n"
      "  (default 60), one at a time. Reports per pass the median, min and max GPU time\n"
      "  (timestamps), the whole frame, the flow pass's floor (a pass over the water's pixels\n"
      "  making the same texture reads and writes with next to no arithmetic), and the CPU\n"
      "  stages' medians. \"flow\" is the water's tile table and material together (also shown\n"
      "  apart as \"flow tiles\" and \"flow material\"). --json prints one JSON object.\n"
      "  --second-view also renders a second view of the same river (CreateInfo::\n"
      "  share_river_with; the camera 4 s further on) into images of its own, and reports its\n"
      "  creation, CPU update and water span beside the first view's. --motion has the water\n"
      "  write motion vectors (R16G16_SFLOAT) and a reactive mask (R8_UNORM) for a temporal\n"
      "  filter as well, under a Halton(2,3) jitter. The first river of a scene file is\n"
      "  benchmarked.\n");
}

Status parse_options(int argc, char** argv, BenchOptions* options, bool* help) {
  cli::ArgReader args(argc, argv, 2);
  std::string_view value;
  while (!args.done()) {
    const std::string_view arg = args.next();
    if (arg == "--help" || arg == "-h") {
      *help = true;
    } else if (arg == "--size") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_size(arg, value, &options->size));
      options->size_given = true;
    } else if (arg == "--frames") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &options->frames));
      if (options->frames == 0) return Status::error("--frames: must be at least 1");
    } else if (arg == "--warmup") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &options->warmup));
    } else if (arg == "--json") {
      options->json = true;
    } else if (arg == "--second-view") {
      options->second_view = true;
    } else if (arg == "--motion") {
      options->motion = true;
    } else if (!arg.empty() && arg[0] != '-' && options->scene_path.empty()) {
      options->scene_path = std::string(arg);
    } else {
      return cli::unexpected_argument(arg);
    }
  }
  return Status::success();
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The water's span in a frame: its passes from the first start to the last end, floor left out.
double water_span(const std::vector<PassTime>& times) {
  double water = 0.0;
  for (const PassTime& pass : times) {
    if (pass.name != kFloorPass) water = std::max(water, pass.begin_ms + pass.milliseconds);
  }
  return water;
}

}  // namespace

int run_bench(int argc, char** argv) {
  BenchOptions options;
  bool help = false;
  Status status = parse_options(argc, argv, &options, &help);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  if (help) {
    print_help();
    return cli::kExitOk;
  }
  std::optional<SceneFile> scene;
  double fps = 30.0;
  if (!options.scene_path.empty()) {
    scene.emplace();
    status = load_scene_file(options.scene_path, &*scene);
    if (!status.ok()) return cli::fail(kCommand, status.message());
    if (!options.size_given) options.size = {scene->render.width, scene->render.height};
    fps = scene->render.fps;
  }
  std::unique_ptr<HeadlessContext> context;
  status = HeadlessContext::create(HeadlessContextOptions{}, &context);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const VkExtent2D extent{options.size.width, options.size.height};
  CreateInfo info = context->renderer_create_info(extent, kOutputFormat);
  info.frames_in_flight = 1;
  info.enable_timing = true;
  info.measure_flow_floor = true;
  if (options.motion) {
    info.motion_format = VK_FORMAT_R16G16_SFLOAT;
    info.reactive_format = VK_FORMAT_R8_UNORM;
  }
  const SceneFile* scene_file = scene.has_value() ? &*scene : nullptr;
  SceneRiverData river;  // the scene's first river
  status = scene_river_data(scene_file, 0, &river);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const WaterRiver water = river.river();
  info.river = &water;
  info.look = scene_file != nullptr ? &scene_file->look : nullptr;
  info.depth_format = kDepthFormat;
  WorldCreateInfo world_info = context->world_create_info(kOutputFormat, kDepthFormat);
  world_info.frames_in_flight = 1;
  world_info.scene = scene_file;
  std::unique_ptr<World> world;
  status = World::create(world_info, &world);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  info.reflection = &World::draw_reflection;
  info.reflection_user = world.get();
  std::unique_ptr<Renderer> renderer;
  auto create_start = std::chrono::steady_clock::now();
  status = Renderer::create(info, &renderer);
  if (status.ok()) status = renderer->set_occluders(world->occluders());
  const double create_ms = ms_since(create_start);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const ImageState shown{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  HostTargets targets;
  status = create_host_targets(*context, kOutputFormat, kDepthFormat, extent, shown, &targets);
  if (status.ok()) {
    status = create_temporal_targets(*context, info.motion_format, info.reactive_format, extent,
                                     &targets);
  }
  if (!status.ok()) return cli::fail(kCommand, status.message());
  // The second view: the same river (no second solve), its own particles, passes and images.
  std::unique_ptr<Renderer> second;
  HostTargets second_targets;
  double second_create_ms = 0.0;
  if (options.second_view) {
    info.share_river_with = renderer.get();
    create_start = std::chrono::steady_clock::now();
    status = Renderer::create(info, &second);
    second_create_ms = ms_since(create_start);
    if (status.ok()) {
      status = create_host_targets(*context, kOutputFormat, kDepthFormat, extent, shown,
                                   &second_targets);
    }
    if (status.ok()) {
      status = create_temporal_targets(*context, info.motion_format, info.reactive_format, extent,
                                       &second_targets);
    }
    if (!status.ok()) return cli::fail(kCommand, status.message());
  }

  std::map<std::string, std::vector<double>> pass_ms;
  std::vector<double> frame_ms;
  std::vector<double> update_ms;
  std::vector<double> record_ms;
  std::vector<double> second_update_ms;
  std::vector<double> second_water_ms;
  std::vector<PassTime> times;
  for (uint32_t frame = 0; frame < options.warmup + options.frames; ++frame) {
    const double time = frame / fps;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    status = context->begin_slot(0, &cmd);
    if (status.ok()) status = renderer->begin_frame(0);
    View view = camera_view(world->scene_camera(time), extent);
    if (options.motion) view = with_taa_jitter(view, frame, extent);
    const auto update_start = std::chrono::steady_clock::now();
    if (status.ok()) status = renderer->update(view, time);
    const double update = ms_since(update_start);
    const View second_view = camera_view(world->scene_camera(time + kSecondViewAhead), extent);
    double second_update = 0.0;
    if (second != nullptr) {
      if (status.ok()) status = second->begin_frame(0);
      const auto second_start = std::chrono::steady_clock::now();
      if (status.ok()) status = second->update(second_view, time);
      second_update = ms_since(second_start);
    }
    const auto record_start = std::chrono::steady_clock::now();
    if (status.ok()) status = world->begin_frame(0);
    Renderer* const first_river[] = {renderer.get()};
    if (status.ok()) {
      status = record_view(cmd, *world, first_river, view, time, ReadbackTargets{}, &targets);
    }
    const double record = ms_since(record_start);
    Renderer* const second_river[] = {second.get()};
    if (status.ok() && second != nullptr) {
      status = record_view(cmd, *world, second_river, second_view, time, ReadbackTargets{},
                           &second_targets);
    }
    const auto submit_start = std::chrono::steady_clock::now();
    if (status.ok()) status = context->end_slot_and_submit(0);
    if (status.ok()) status = context->wait_slot(0);
    const double gpu_wall = ms_since(submit_start);
    double second_water = 0.0;
    if (status.ok() && second != nullptr) status = second->pass_times(0, &times);
    if (status.ok()) second_water = water_span(times);
    if (status.ok()) status = renderer->pass_times(0, &times);
    if (!status.ok()) return cli::fail(kCommand, status.message());
    if (frame < options.warmup) continue;
    update_ms.push_back(update);
    record_ms.push_back(record);
    second_update_ms.push_back(second_update);
    second_water_ms.push_back(second_water);
    double flow = 0.0;
    for (const PassTime& pass : times) {
      if (pass.name == "flow" || pass.name == kTilePass) flow += pass.milliseconds;
      pass_ms[pass.name == "flow" ? kMaterialPass : pass.name].push_back(pass.milliseconds);
    }
    pass_ms["flow"].push_back(flow);
    pass_ms["water"].push_back(water_span(times));
    frame_ms.push_back(gpu_wall);
  }

  const Stats frame = stats_of(frame_ms);
  const Stats floor = stats_of(pass_ms[kFloorPass]);
  const Stats flow = stats_of(pass_ms["flow"]);
  const Stats update = stats_of(update_ms);
  const Stats record = stats_of(record_ms);
  if (options.json) {
    nlohmann::json out;
    out["size"] = {options.size.width, options.size.height};
    out["frames"] = options.frames;
    out["frame_ms"] = frame.median;
    out["floor_ms"] = floor.median;
    for (const auto& [name, values] : pass_ms) {
      if (name == kFloorPass) continue;
      const Stats s = stats_of(values);
      out["passes"][name] = {{"median_ms", s.median}, {"min_ms", s.min}, {"max_ms", s.max}};
    }
    out["cpu"] = {{"update_ms", update.median}, {"record_ms", record.median}};
    out["create_ms"] = create_ms;
    if (second != nullptr) {
      out["second_view"] = {{"create_ms", second_create_ms},
                            {"update_ms", stats_of(second_update_ms).median},
                            {"water_ms", stats_of(second_water_ms).median}};
    }
    std::printf("%s\n", out.dump(2).c_str());
    return cli::kExitOk;
  }
  std::printf("%ux%u, %u frames after %u warm-up (GPU timestamps, lavapipe or not)\n",
              options.size.width, options.size.height, options.frames, options.warmup);
  std::printf("%-12s %10s %10s %10s\n", "pass", "median ms", "min ms", "max ms");
  for (const auto& [name, values] : pass_ms) {
    const Stats s = stats_of(values);
    std::printf("%-12s %10.3f %10.3f %10.3f\n", name.c_str(), s.median, s.min, s.max);
  }
  // The world has no timestamps of its own: it is what the frame's wall time adds to the water.
  std::printf("frame (wall) %10.3f %10.3f %10.3f   world + water, submit to fence\n", frame.median,
              frame.min, frame.max);
  std::printf("flow / floor: %.2f\n", floor.median > 0.0 ? flow.median / floor.median : 0.0);
  std::printf("cpu update (particles + packing) %.3f ms, record %.3f ms (medians)\n", update.median,
              record.median);
  std::printf("create %.1f ms (the flow solve, static data and occluders included)\n", create_ms);
  if (second != nullptr) {
    std::printf("second view: create %.1f ms, cpu update %.3f ms, water %.3f ms (medians; the "
                "first view: %.1f, %.3f, %.3f)\n",
                second_create_ms, stats_of(second_update_ms).median,
                stats_of(second_water_ms).median, create_ms, update.median,
                stats_of(pass_ms["water"]).median);
  }
  return cli::kExitOk;
}

}  // namespace siviflow
