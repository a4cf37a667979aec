// `siviflow flow SCENE.json --out FILE.csv [--time T] [--river N]`: the solved flow field of one
// of a scene's rivers.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cli.h"
#include "commands.h"
#include "siviflow/atomic_file.h"
#include "siviflow/scene_river.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "flow";

void print_help() {
  std::printf(
      "usage: siviflow flow SCENE.json --out FILE.csv [--time T] [--river N]\n"
      "  Solves the stream-function flow of the scene's river N (default 0, the first), with\n"
      "  its obstacles placed at time T (seconds, default 0), and writes one CSV row per river\n"
      "  vertex in the file's accessor order:\n"
      "  vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet\n");
}

Status parse_time(std::string_view text, double* out) {
  const std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size() || !std::isfinite(value)) {
    return Status::error("--time: invalid value '" + copy + "' (expected seconds)");
  }
  *out = value;
  return Status::success();
}

}  // namespace

int run_flow(int argc, char** argv) {
  cli::ArgReader args(argc, argv, 2);
  std::string scene_path;
  std::string out_path;
  double time = 0.0;
  uint32_t river_index = 0;
  std::string_view value;
  while (!args.done()) {
    const std::string_view arg = args.next();
    Status status;
    if (arg == "--help" || arg == "-h") {
      print_help();
      return cli::kExitOk;
    } else if (arg == "--out") {
      status = args.value(arg, &value);
      out_path = std::string(value);
    } else if (arg == "--time") {
      status = args.value(arg, &value);
      if (status.ok()) status = parse_time(value, &time);
    } else if (arg == "--river") {
      status = args.value(arg, &value);
      if (status.ok()) status = cli::parse_uint(arg, value, &river_index);
    } else if (!arg.empty() && arg[0] == '-') {
      status = Status::error("unknown option '" + std::string(arg) + "' (see --help)");
    } else if (scene_path.empty()) {
      scene_path = std::string(arg);
    } else {
      status = Status::error("unexpected argument '" + std::string(arg) + "': one scene file only");
    }
    if (!status.ok()) return cli::fail(kCommand, status.message());
  }
  if (scene_path.empty()) return cli::fail(kCommand, "a scene file is required (see --help)");
  if (out_path.empty()) return cli::fail(kCommand, "--out FILE.csv is required");
  Status status = check_output_path(out_path);
  if (!status.ok()) return cli::fail(kCommand, status.message());

  SceneFile scene;
  status = load_scene_file(scene_path, &scene);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  SceneRiverFlow river;
  status = build_scene_river_flow(scene, river_index, time, &river);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  const std::string csv = flow_field_csv(river);
  status = write_file_atomically(out_path, csv.data(), csv.size());
  if (!status.ok()) return cli::fail(kCommand, status.message());
  std::printf("wrote %zu vertices to %s\n", river.positions.size(), out_path.c_str());
  return cli::kExitOk;
}

}  // namespace siviflow
