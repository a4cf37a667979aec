#include "bench_run.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "renderer_inspect.h"
#include "siviflow/host_frame.h"
#include "siviflow/renderer.h"
#include "siviflow/scene_river.h"
#include "siviflow/world.h"

namespace siviflow {
namespace {

constexpr VkFormat kOutputFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr double kSecondViewAhead = 4.0;  // seconds ahead on the camera path

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The water's span in a frame: its passes from the first start to the last end, floor left out.
double water_span(const std::vector<PassTime>& times) {
  double water = 0.0;
  for (const PassTime& pass : times) {
    if (pass.name != bench_pass::kFloor) water = std::max(water, pass.begin_ms + pass.milliseconds);
  }
  return water;
}

}  // namespace

Status run_bench_once(HeadlessContext& context, const BenchOptions& options,
                      const SceneFile* scene, double fps, BenchRun* out) {
  const VkExtent2D extent{options.size.width, options.size.height};
  CreateInfo info = context.renderer_create_info(extent, kOutputFormat);
  info.frames_in_flight = 1;
  info.enable_timing = true;
  info.measure_flow_floor = true;
  if (options.motion) {
    info.motion_format = VK_FORMAT_R16G16_SFLOAT;
    info.reactive_format = VK_FORMAT_R8_UNORM;
  }
  SceneRiverData river;  // the scene's first river
  SIVIFLOW_TRY(scene_river_data(scene, 0, &river));
  const WaterRiver water = river.river();
  info.river = &water;
  info.river_copied = &SceneRiverData::release_arrays;  // the renderer holds its copy
  info.river_copied_user = &river;
  info.look = scene != nullptr ? &scene->look : nullptr;
  info.depth_format = kDepthFormat;
  WorldCreateInfo world_info = context.world_create_info(kOutputFormat, kDepthFormat);
  world_info.frames_in_flight = 1;
  world_info.scene = scene;
  world_info.enable_timing = true;
  std::unique_ptr<World> world;
  SIVIFLOW_TRY(World::create(world_info, &world));
  info.reflection = &World::draw_reflection;
  info.reflection_user = world.get();
  std::unique_ptr<Renderer> renderer;
  auto create_start = std::chrono::steady_clock::now();
  Status status = Renderer::create(info, &renderer);
  info.river = nullptr;  // freed by river_copied; a second view shares the first's river
  if (status.ok()) status = renderer->set_occluders(world->occluders());
  out->create_ms = ms_since(create_start);
  SIVIFLOW_TRY(status);
  const ImageState shown{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  HostTargets targets;
  SIVIFLOW_TRY(create_host_targets(context, kOutputFormat, kDepthFormat, extent, shown, &targets));
  SIVIFLOW_TRY(create_temporal_targets(context, info.motion_format, info.reactive_format, extent,
                                       &targets));
  // The second view: the same river (no second solve), its own particles, passes and images.
  std::unique_ptr<Renderer> second;
  HostTargets second_targets;
  if (options.second_view) {
    info.share_river_with = renderer.get();
    create_start = std::chrono::steady_clock::now();
    status = Renderer::create(info, &second);
    out->second_create_ms = ms_since(create_start);
    SIVIFLOW_TRY(status);
    SIVIFLOW_TRY(create_host_targets(context, kOutputFormat, kDepthFormat, extent, shown,
                                     &second_targets));
    SIVIFLOW_TRY(create_temporal_targets(context, info.motion_format, info.reactive_format,
                                         extent, &second_targets));
  }

  std::vector<PassTime> times;
  std::vector<PassTime> world_times;
  for (uint32_t frame = 0; frame < options.warmup + options.frames; ++frame) {
    const double time = frame / fps;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    SIVIFLOW_TRY(context.begin_slot(0, &cmd));
    SIVIFLOW_TRY(renderer->begin_frame(0));
    View view = camera_view(world->scene_camera(time), extent);
    if (options.motion) view = with_taa_jitter(view, frame, extent);
    const auto update_start = std::chrono::steady_clock::now();
    SIVIFLOW_TRY(renderer->update(view, time));
    const double update = ms_since(update_start);
    const View second_view = camera_view(world->scene_camera(time + kSecondViewAhead), extent);
    double second_update = 0.0;
    if (second != nullptr) {
      SIVIFLOW_TRY(second->begin_frame(0));
      const auto second_start = std::chrono::steady_clock::now();
      SIVIFLOW_TRY(second->update(second_view, time));
      second_update = ms_since(second_start);
    }
    const auto record_start = std::chrono::steady_clock::now();
    SIVIFLOW_TRY(world->begin_frame(0));
    Renderer* const first_river[] = {renderer.get()};
    SIVIFLOW_TRY(record_view(cmd, *world, first_river, view, time, ReadbackTargets{}, &targets));
    const double record = ms_since(record_start);
    Renderer* const second_river[] = {second.get()};
    if (second != nullptr) {
      SIVIFLOW_TRY(record_view(cmd, *world, second_river, second_view, time, ReadbackTargets{},
                               &second_targets));
    }
    const auto submit_start = std::chrono::steady_clock::now();
    SIVIFLOW_TRY(context.end_slot_and_submit(0));
    SIVIFLOW_TRY(context.wait_slot(0));
    const double gpu_wall = ms_since(submit_start);
    double second_water = 0.0;
    if (second != nullptr) {
      SIVIFLOW_TRY(second->pass_times(0, &times));
      second_water = water_span(times);
    }
    SIVIFLOW_TRY(world->pass_times(0, &world_times));
    SIVIFLOW_TRY(renderer->pass_times(0, &times));
    if (frame < options.warmup) continue;
    out->update_ms.push_back(update);
    out->record_ms.push_back(record);
    out->second_update_ms.push_back(second_update);
    out->second_water_ms.push_back(second_water);
    double flow = 0.0;
    double floor = 0.0;
    for (const PassTime& pass : times) {
      if (pass.name == "flow" || pass.name == bench_pass::kTiles) flow += pass.milliseconds;
      if (pass.name == bench_pass::kFloor) floor = pass.milliseconds;
      out->pass_ms[pass.name == "flow" ? bench_pass::kMaterial : pass.name].push_back(
          pass.milliseconds);
    }
    for (const PassTime& pass : world_times) out->pass_ms[pass.name].push_back(pass.milliseconds);
    out->pass_ms[bench_pass::kFlow].push_back(flow);
    out->pass_ms[bench_pass::kWater].push_back(water_span(times));
    out->frame_ms.push_back(gpu_wall);
    out->frame_without_floor_ms.push_back(gpu_wall - floor);
  }
  const WorldDrawStats drawn = world->draw_stats();
  out->world_triangles = drawn.main_triangles;
  out->reflection_world_triangles = drawn.reflection_triangles;
  out->water_triangles = drawn_water_triangles(*renderer);
  return Status::success();
}

}  // namespace siviflow
