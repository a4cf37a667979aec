// `siviflow bench`: GPU time per pass (timestamp queries) and CPU time per stage of a scene file's
// or the default scene's frames, with the flow pass's floor measured in the same run, over one
// or more lifetimes of the world and renderer (runs) whose spread it reports.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_run.h"
#include "cli.h"
#include "commands.h"
#include "siviflow/headless_context.h"
#include "siviflow/scene_file.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "bench";

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

// Every frame of every run, one after the other.
std::vector<double> pooled(const std::vector<BenchRun>& runs,
                           std::vector<double> BenchRun::*member) {
  std::vector<double> all;
  for (const BenchRun& run : runs) {
    all.insert(all.end(), (run.*member).begin(), (run.*member).end());
  }
  return all;
}

std::map<std::string, std::vector<double>> pooled_passes(const std::vector<BenchRun>& runs) {
  std::map<std::string, std::vector<double>> all;
  for (const BenchRun& run : runs) {
    for (const auto& [name, values] : run.pass_ms) {
      all[name].insert(all[name].end(), values.begin(), values.end());
    }
  }
  return all;
}

// Each run's median frame (without the floor), and their spread: (max - min) / median.
struct RunSpread {
  std::vector<double> medians;
  Stats stats;
  double spread = 0.0;
};

RunSpread spread_of(const std::vector<BenchRun>& runs) {
  RunSpread out;
  for (const BenchRun& run : runs) out.medians.push_back(stats_of(run.frame_without_floor_ms).median);
  out.stats = stats_of(out.medians);
  out.spread = out.stats.median > 0.0 ? (out.stats.max - out.stats.min) / out.stats.median : 0.0;
  return out;
}

void print_help() {
  std::printf(
      "usage: siviflow bench [SCENE.json] [--size WxH] [--frames N] [--warmup W] [--runs R]\n"
      "                      [--json] [--second-view] [--motion]\n"
      "  Renders the scene file (at its render size unless --size says otherwise) or the\n"
      "  default scene (1280x720): R times (default 1) a world and renderer are created, render\n"
      "  W warm-up frames (default 10), then N measured frames (default 60), one at a time, and\n"
      "  are destroyed. Reports per pass the median, min and max GPU time (timestamps) over all\n"
      "  measured frames: the world's pass (\"world\") and the water's; the whole frame (wall time,\n"
      "  submit to fence), with and without the flow pass's floor (a pass over the water's\n"
      "  pixels making the same texture reads and writes with next to no arithmetic, an\n"
      "  instrument no user's frame holds); each run's median frame and their spread; the\n"
      "  triangles the world drew in its view and its reflection and the water's; and the CPU\n"
      "  stages' medians. \"flow\" is the water's tile table and material together (also shown\n"
      "  apart as \"flow tiles\" and \"flow material\"); \"water\" is the water's span, from its\n"
      "  first pass's start to its last's end. --json prints one JSON object.\n"
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
    } else if (arg == "--runs") {
      SIVIFLOW_TRY(args.value(arg, &value));
      SIVIFLOW_TRY(cli::parse_uint(arg, value, &options->runs));
      if (options->runs == 0) return Status::error("--runs: must be at least 1");
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

void print_json(const BenchOptions& options, const std::vector<BenchRun>& runs) {
  const BenchRun& last = runs.back();
  nlohmann::json out;
  out["size"] = {options.size.width, options.size.height};
  out["frames"] = options.frames;
  out["runs"] = options.runs;
  out["frame_ms"] = stats_of(pooled(runs, &BenchRun::frame_ms)).median;
  out["frame_without_floor_ms"] = stats_of(pooled(runs, &BenchRun::frame_without_floor_ms)).median;
  const RunSpread spread = spread_of(runs);
  out["run_frame_ms"] = spread.medians;
  out["run_spread"] = spread.spread;
  const auto passes = pooled_passes(runs);
  out["floor_ms"] = passes.count(bench_pass::kFloor) ? stats_of(passes.at(bench_pass::kFloor)).median : 0.0;
  for (const auto& [name, values] : passes) {
    if (name == bench_pass::kFloor) continue;
    const Stats s = stats_of(values);
    out["passes"][name] = {{"median_ms", s.median}, {"min_ms", s.min}, {"max_ms", s.max}};
  }
  out["triangles"] = {{"world", last.world_triangles},
                      {"world_reflection", last.reflection_world_triangles},
                      {"water", last.water_triangles}};
  out["cpu"] = {{"update_ms", stats_of(pooled(runs, &BenchRun::update_ms)).median},
                {"record_ms", stats_of(pooled(runs, &BenchRun::record_ms)).median}};
  out["create_ms"] = last.create_ms;
  if (options.second_view) {
    out["second_view"] = {{"create_ms", last.second_create_ms},
                          {"update_ms", stats_of(pooled(runs, &BenchRun::second_update_ms)).median},
                          {"water_ms", stats_of(pooled(runs, &BenchRun::second_water_ms)).median}};
  }
  std::printf("%s\n", out.dump(2).c_str());
}

void print_table(const BenchOptions& options, const std::vector<BenchRun>& runs) {
  const BenchRun& last = runs.back();
  const auto passes = pooled_passes(runs);
  std::printf("%ux%u, %u run(s) of %u frames after %u warm-up (GPU timestamps, lavapipe or not)\n",
              options.size.width, options.size.height, options.runs, options.frames,
              options.warmup);
  std::printf("%-14s %10s %10s %10s\n", "pass", "median ms", "min ms", "max ms");
  for (const auto& [name, values] : passes) {
    const Stats s = stats_of(values);
    std::printf("%-14s %10.3f %10.3f %10.3f\n", name.c_str(), s.median, s.min, s.max);
  }
  const Stats frame = stats_of(pooled(runs, &BenchRun::frame_ms));
  const Stats without = stats_of(pooled(runs, &BenchRun::frame_without_floor_ms));
  std::printf("frame (wall)   %10.3f %10.3f %10.3f   world + water + floor, submit to fence\n",
              frame.median, frame.min, frame.max);
  std::printf("frame - floor  %10.3f %10.3f %10.3f   what a user's frame costs\n", without.median,
              without.min, without.max);
  const double floor =
      passes.count(bench_pass::kFloor) ? stats_of(passes.at(bench_pass::kFloor)).median : 0.0;
  const double flow = stats_of(passes.at(bench_pass::kFlow)).median;
  std::printf("flow / floor: %.2f\n", floor > 0.0 ? flow / floor : 0.0);
  const RunSpread spread = spread_of(runs);
  std::printf("runs' median frames (less floor):");
  for (double ms : spread.medians) std::printf(" %.2f", ms);
  std::printf(" ms; median %.2f, spread %.1f %% ((max - min) / median)\n", spread.stats.median,
              100.0 * spread.spread);
  std::printf("triangles: world %u, its reflection %u, water %u (last frame)\n",
              last.world_triangles, last.reflection_world_triangles, last.water_triangles);
  std::printf("cpu update (particles + packing) %.3f ms, record %.3f ms (medians)\n",
              stats_of(pooled(runs, &BenchRun::update_ms)).median,
              stats_of(pooled(runs, &BenchRun::record_ms)).median);
  std::printf("create %.1f ms (the flow solve, static data and occluders included)\n",
              last.create_ms);
  if (options.second_view) {
    std::printf("second view: create %.1f ms, cpu update %.3f ms, water %.3f ms (medians; the "
                "first view: %.1f, %.3f, %.3f)\n",
                last.second_create_ms, stats_of(pooled(runs, &BenchRun::second_update_ms)).median,
                stats_of(pooled(runs, &BenchRun::second_water_ms)).median, last.create_ms,
                stats_of(pooled(runs, &BenchRun::update_ms)).median,
                stats_of(passes.at(bench_pass::kWater)).median);
  }
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
  std::vector<BenchRun> runs(options.runs);
  for (BenchRun& run : runs) {
    status = run_bench_once(*context, options, scene.has_value() ? &*scene : nullptr, fps, &run);
    if (!status.ok()) return cli::fail(kCommand, status.message());
  }
  if (options.json) {
    print_json(options, runs);
  } else {
    print_table(options, runs);
  }
  return cli::kExitOk;
}

}  // namespace siviflow
