// `siviflow view`: a live window that embeds the water as an engine would. The viewer owns the
// Vulkan device, the swapchain, its frames in flight and its own render pass (the panel); it
// draws the built-in world, records the water through the public API into the same command
// buffer, copies the frame to the swapchain image, draws the panel over it and presents.
#pragma once

#include <cstdint>
#include <string>

#include "siviflow/renderer.h"
#include "siviflow/status.h"

namespace siviflow::view {

struct ViewOptions {
  std::string scene_path;      // empty: the built-in default scene
  uint32_t width = 1280;
  uint32_t height = 720;
  uint32_t frames = 0;         // close after this many presented frames; 0: until closed
  bool no_vsync = false;
  bool validation = false;
  std::string screenshot;      // the last presented image as PNG
  std::string input_script;    // scripted input (input_script.h)
  std::string flow_report;     // CSV of the obstacles and the particles' flow at exit
  DebugView debug_view = DebugView::kNone;  // the water's debug view at the start
};

struct ViewResult {
  uint32_t frames_presented = 0;
  double seconds = 0.0;              // wall time of the presented frames
  uint32_t validation_errors = 0;
};

// Runs the viewer until the window closes, Esc, or `frames` presented frames. Errors: no
// display, no device that can present, bad scene or script, a Vulkan failure.
Status run_viewer(const ViewOptions& options, ViewResult* result);

}  // namespace siviflow::view
