// The viewer's Dear ImGui panel: frame rate, GPU time per pass and CPU time per stage, the
// particle count, the camera and time controls, the water's look live, "save look", and the
// water's debug views.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "siviflow/renderer.h"
#include "siviflow/water_look.h"

namespace siviflow::view {

struct PanelStats {
  double fps = 0.0;
  std::vector<std::pair<std::string, double>> gpu_ms;  // per pass, the last finished frame
  std::vector<std::pair<std::string, double>> cpu_ms;  // per stage, this frame
  size_t particles = 0;
  size_t obstacles = 0;
  std::string cursor_water;  // the water under the cursor (Renderer::query_water), or why none
  const char* present_mode = "";
  unsigned width = 0;
  unsigned height = 0;
};

struct PanelState {
  bool follow_path = false;
  bool paused = false;
  float time_scale = 1.0f;
  double time_seconds = 0.0;
  float camera_speed = 0.0f;
  WaterLook look;
  DebugView debug_view = DebugView::kNone;
  char save_path[512] = {};
  std::string message;  // the last action's outcome or error
};

struct PanelActions {
  bool look_changed = false;
  bool save_look = false;
  bool debug_view_changed = false;
};

// Builds the panel for this frame (between ImGui::NewFrame and ImGui::Render).
PanelActions draw_panel(const PanelStats& stats, PanelState* state);

}  // namespace siviflow::view
