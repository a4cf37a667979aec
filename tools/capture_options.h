// What `siviflow capture` was asked for: shared by the capture loop and the frame writer.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include "cli.h"

namespace siviflow {

struct CaptureOptions {
  std::string scene_path;  // empty: the built-in default scene
  bool size_given = false;  // flags win over the scene file's render settings
  bool fps_given = false;
  bool seed_given = false;
  uint32_t first_frame = 0;
  uint32_t end_frame = 1;
  cli::Size size{1280, 720};
  std::string out_dir;
  uint32_t seed = 1;
  float fps = 30.0f;
  bool preview = false;
  bool validation = false;
  bool dry_run = false;  // check everything that needs no device, say what would be rendered
  bool resume = false;  // render only the frames of the range not already complete
  bool force = false;   // render over (or beside) frames of another capture instead of refusing
  bool depth_aov = false;
  bool flow_aov = false;       // flow.X/Y/Z and water.A
  bool particles_aov = false;  // particle.I and frame_NNNNN.particles.csv
  bool normal_aov = false;     // normal.X/Y/Z
  bool reflection_aov = false; // reflection.R/G/B
  bool foam_aov = false;       // foam.Y
  bool motion_aov = false;     // motion.X/Y/Z/W
  std::string scene_digest;    // scene_content_digest, set by plan_capture
};

// The AOVs asked for, comma-separated in the order --help lists them ("" for the beauty alone):
// what frames record and captures compare.
inline std::string aov_names(const CaptureOptions& options) {
  const std::pair<bool, const char*> aovs[] = {
      {options.depth_aov, "depth"},           {options.flow_aov, "flow"},
      {options.particles_aov, "particles"},   {options.normal_aov, "normal"},
      {options.reflection_aov, "reflection"}, {options.foam_aov, "foam"},
      {options.motion_aov, "motion"}};
  std::string names;
  for (const auto& [asked, name] : aovs) {
    if (asked) names += (names.empty() ? "" : ",") + std::string(name);
  }
  return names;
}

// Whether the frame has water layers, and with them the water mask they are zero outside of.
inline bool water_layers(const CaptureOptions& options) {
  return options.flow_aov || options.particles_aov || options.normal_aov ||
         options.reflection_aov || options.foam_aov;
}

// The particle layer's id where no particle's texel covers visible water (ids start at 1).
inline constexpr uint32_t kNoParticleId = 0;

// The EXR channels of the AOVs (docs/output.md's table says what each holds). Every channel is
// LAYER.C with a one-letter C: Blender's reader drops a layer with a longer one.
inline constexpr const char* kDepthChannel = "depth.Z";
inline constexpr const char* kWaterMaskChannel = "water.A";
inline constexpr const char* kParticleIdChannel = "particle.I";  // UINT; 0: no particle
inline constexpr const char* kFoamChannel = "foam.Y";
inline constexpr const char* kFlowChannels[3] = {"flow.X", "flow.Y", "flow.Z"};
inline constexpr const char* kNormalChannels[3] = {"normal.X", "normal.Y", "normal.Z"};
inline constexpr const char* kReflectionChannels[3] = {"reflection.R", "reflection.G",
                                                       "reflection.B"};
// Blender's Vector pass layout (tools/motion_vectors.h).
inline constexpr const char* kMotionChannels[4] = {"motion.X", "motion.Y", "motion.Z",
                                                   "motion.W"};

}  // namespace siviflow
