// `siviflow flow SCENE.json [--out FILE.csv] [--describe] [--time T] [--river N]`: the solved
// flow field of one of a scene's rivers, and what the river surface generator found in it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>

#include "cli.h"
#include "commands.h"
#include "siviflow/atomic_file.h"
#include "siviflow/scene_river.h"
#include "siviflow/text_format.h"

namespace siviflow {
namespace {

constexpr const char* kCommand = "flow";

void print_help() {
  std::printf(
      "usage: siviflow flow SCENE.json [--out FILE.csv] [--describe] [--time T] [--river N]\n"
      "  Solves the stream-function flow of the scene's river N (default 0, the first), with\n"
      "  its obstacles placed at time T (seconds, default 0).\n"
      "  --out FILE.csv  writes one CSV row per river vertex in the file's accessor order:\n"
      "                  vertex,x,y,z,section,bank,width,d_left,d_right,psi,vx,vy,vz,wet\n"
      "  --describe      prints what the river's mesh was found to be: a strip or a network,\n"
      "                  its ends, banks, tongues, arms and islands, and the discharge each\n"
      "                  end and arm carries\n"
      "  At least one of the two is required.\n");
}

// The river's ends, banks, arms (the water between two borders) and islands, with the
// discharge of each.
std::string describe(const StreamFunction& flow) {
  const RiverSurface& s = flow.surface();
  const auto sections = s.sections();
  const size_t tongues = s.network() ? s.banks().size() - 2 : 0;
  const auto name = [&](BorderId b) {
    if (b == kLeftBankBorder) return std::string("the left bank");
    if (b == kRightBankBorder) return std::string("the right bank");
    if (s.is_island_border(b)) return text_format("island %d", int(b - island_border(0)));
    return text_format("tongue %d", int(b - island_border(s.islands().size())));
  };
  std::set<std::pair<BorderId, BorderId>> arms;
  for (uint32_t n = 0; n < s.node_count(); ++n) {
    if (s.node_bank()[n] == Bank::kNone && !s.on_island(n) && !s.on_tongue(n)) {
      arms.insert({s.node_left_border(n), s.node_right_border(n)});
    }
  }
  std::string out = text_format("a %s of %zu sections, %.1f m along its middle, %zu vertices (%zu triangles)\n",
                                s.network() ? "network" : "strip", sections.size(),
                                double(sections.back().along), s.vertex_count(), s.triangle_count());
  for (size_t e = 0; e < s.ends().size(); ++e) {
    const RiverEnd& end = s.ends()[e];
    const char* kind = end.inflow ? "inflow" : "outflow";
    const std::string where =
        s.network() ? text_format("end %zu, %s", e, kind)
                    : text_format("1 %s end (%s)", kind, end.inflow ? "upstream" : "downstream");
    out += text_format("%s: section %u, %u vertices (vertex %u first), %.2f m wide, %.9g m^2/s\n",
                       where.c_str(), end.section, end.node_count,
                       s.vertex_of_node(s.end_nodes(e)[0]), double(end.width), flow.end_discharge(e));
  }
  if (s.network()) {
    for (const RiverBank& bank : s.banks()) {
      out += text_format("%s: psi %.9g m^2/s\n", name(bank.border).c_str(), flow.border_psi(bank.border));
    }
  } else {
    out += text_format("2 banks: psi %.9g m^2/s on the left, 0 on the right\n",
                       flow.border_psi(kLeftBankBorder));
  }
  out += text_format("%zu island%s, %zu arms, %zu junction%s\n", s.islands().size(),
                     s.islands().size() == 1 ? "" : "s", arms.size(), tongues, tongues == 1 ? "" : "s");
  for (size_t i = 0; i < s.islands().size(); ++i) {
    uint32_t first = UINT32_MAX, last = 0;
    for (const uint32_t n : s.island_nodes(i)) {
      first = std::min(first, s.node_section()[n]);
      last = std::max(last, s.node_section()[n]);
    }
    out += text_format(
        "island %zu: %zu shore vertices (vertex %u first), sections %u to %u (%.1f m), psi %.9g\n",
        i, s.island_nodes(i).size(), s.vertex_of_node(s.island_nodes(i)[0]), first, last,
        double(sections[last].along - sections[first].along), flow.island_psi(i));
  }
  for (const auto& [left, right] : arms) {
    out += text_format("arm from %s to %s: %.9g m^2/s\n", name(left).c_str(), name(right).c_str(),
                       flow.border_psi(left) - flow.border_psi(right));
  }
  return out;
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
  bool describe_river = false;
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
    } else if (arg == "--describe") {
      describe_river = true;
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
  if (out_path.empty() && !describe_river) {
    return cli::fail(kCommand, "--out FILE.csv or --describe is required");
  }
  Status status = out_path.empty() ? Status::success() : check_output_path(out_path);
  if (!status.ok()) return cli::fail(kCommand, status.message());

  SceneFile scene;
  status = load_scene_file(scene_path, &scene);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  SceneRiverFlow river;
  status = build_scene_river_flow(scene, river_index, time, &river);
  if (!status.ok()) return cli::fail(kCommand, status.message());
  if (describe_river) std::printf("%s", describe(river.flow).c_str());
  if (out_path.empty()) return cli::kExitOk;
  const std::string csv = flow_field_csv(river);
  status = write_file_atomically(out_path, csv.data(), csv.size());
  if (!status.ok()) return cli::fail(kCommand, status.message());
  std::printf("wrote %zu vertices to %s\n", river.positions.size(), out_path.c_str());
  return cli::kExitOk;
}

}  // namespace siviflow
