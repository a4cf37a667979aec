// What `siviflow capture` checks before it asks for a device: one check for the real run and for
// --dry-run, so that a dry run refuses all that the real run would refuse before rendering.
#pragma once

#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "capture_options.h"
#include "siviflow/scene_file.h"
#include "siviflow/scene_river.h"
#include "siviflow/status.h"

namespace siviflow {

// The capture's frames: how many are in flight, and the formats of the host's images.
inline constexpr uint32_t kCaptureFramesInFlight = 2;
inline constexpr VkFormat kCaptureColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kCaptureDepthFormat = VK_FORMAT_D32_SFLOAT;

// What the check found to render, loaded once for the real run.
struct CapturePlan {
  std::optional<SceneFile> scene;      // absent: the built-in default scene
  std::vector<SceneRiverData> rivers;  // each river of the scene, as the renderers take it
  std::vector<bool> render;            // per frame of the range; false: complete, kept (--resume)
};

// The ReadbackImage bits of the colour and of the AOVs `options` asks for.
uint32_t capture_readback_images(const CaptureOptions& options);

// In this order: the output folder (exists, writable); the scene file, whose render settings
// fill what no flag gave; the AOVs against its rivers (those of one river refused for several);
// the memory budget of the size and AOVs; each river loaded as the renderers take it (glTF files
// read and their surfaces built, procedural ones generated, obstacle objects placed); the
// objects loaded and their textures decoded as the world does; the scene's content digest (into
// `options`); and the frames already in the folder: a frame of another capture in the range, or
// the folder's first frame outside it, is refused naming it unless --force; with --resume the
// range's complete frames are kept. `out` is left alone on failure.
Status plan_capture(CaptureOptions* options, CapturePlan* out);

}  // namespace siviflow
