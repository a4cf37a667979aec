// One lifetime of `siviflow bench`'s world and renderers: created, warmed up, then timed frame
// by frame (GPU timestamps per pass, wall time per frame, CPU time per stage).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cli.h"
#include "siviflow/headless_context.h"
#include "siviflow/scene_file.h"
#include "siviflow/status.h"

namespace siviflow {

struct BenchOptions {
  std::string scene_path;  // empty: the built-in default scene
  cli::Size size{1280, 720};
  bool size_given = false;  // a flag wins over the scene file's render size
  uint32_t frames = 60;
  uint32_t warmup = 10;
  uint32_t runs = 1;
  bool json = false;
  bool second_view = false;  // also a second view of the same river (a probe 4 s ahead)
  bool motion = false;       // the water writes motion vectors and a reactive mask too
};

// The bench's names beside the renderer's and the world's own passes.
namespace bench_pass {
constexpr const char* kFloor = "flow floor";  // the flow pass's floor, an instrument
// The flow pass is its tile table (compute) then its material: "flow" reports both together,
// so flow / floor counts all the work the water costs beyond its texture reads.
constexpr const char* kFlow = "flow";
constexpr const char* kTiles = "flow tiles";
constexpr const char* kMaterial = "flow material";
constexpr const char* kWater = "water";  // the water's span: first start to last end, floor aside
}  // namespace bench_pass

// What one run measured, per measured frame.
struct BenchRun {
  std::map<std::string, std::vector<double>> pass_ms;  // GPU time per pass (and the sums above)
  std::vector<double> frame_ms;  // wall time, submit to fence, with the floor
  std::vector<double> frame_without_floor_ms;  // the same less the floor pass's GPU time
  std::vector<double> update_ms;
  std::vector<double> record_ms;
  std::vector<double> second_update_ms;
  std::vector<double> second_water_ms;
  double create_ms = 0.0;
  double second_create_ms = 0.0;  // 0 without --second-view
  // Triangles of the last frame: the world's main view and reflection, the water surface.
  uint32_t world_triangles = 0;
  uint32_t reflection_world_triangles = 0;
  uint32_t water_triangles = 0;
};

// Creates the world and renderer(s) of `scene` (null: the default scene), renders the warm-up
// and measured frames, and destroys them.
Status run_bench_once(HeadlessContext& context, const BenchOptions& options,
                      const SceneFile* scene, double fps, BenchRun* out);

}  // namespace siviflow
