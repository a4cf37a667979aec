// The built-in world of SiViFlow's tools: sky, terrain, riverbed, a scene file's glTF objects,
// a boulder at each obstacle, and the floating logs and leaves the host drifts. It is a host of
// the water renderer like any engine's world: it draws into the host's colour and depth (every
// pixel of the view's) before the water is recorded, and draws itself mirrored into the
// renderer's reflection through the reflection callback.
//
// Per frame, on the host's command buffer, with the host having waited for the slot:
//   world->begin_frame(slot);
//   world->record(cmd, view, time, color, depth);  // colour and depth of the world (per view)
//   renderer->record(cmd, inputs);                 // the water over them
// with CreateInfo::reflection = World::draw_reflection and reflection_user = the world. Several
// views in one frame (split screen) record the world once per view, each over its viewport.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include <vulkan/vulkan.h>

#include "siviflow/renderer.h"
#include "siviflow/scene_file.h"
#include "siviflow/status.h"

namespace siviflow {

struct WorldCreateInfo {
  VkInstance instance = VK_NULL_HANDLE;               // the host's, as for the renderer
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;  // required
  PFN_vkGetDeviceProcAddr get_device_proc_addr = nullptr;      // optional
  uint32_t frames_in_flight = 0;   // the host's slots; 0 means 2
  VkFormat color_format = VK_FORMAT_UNDEFINED;  // host colour and reflection target; 0: RGBA16F
  VkFormat depth_format = VK_FORMAT_UNDEFINED;  // host depth; 0: D32_SFLOAT
  // The scene whose world to draw (its river's valley or bed, objects, obstacles, camera path);
  // null: the built-in default scene. Read by create() only.
  const SceneFile* scene = nullptr;
  VkPipelineCache pipeline_cache = VK_NULL_HANDLE;              // optional
  const VkAllocationCallbacks* allocation_callbacks = nullptr;  // optional
  bool debug_utils = false;  // the host enabled VK_EXT_debug_utils: label the pass
  // Boulders for obstacles a host adds at runtime (Renderer::add_obstacle), hidden until placed
  // with place_boulder(); each `spare_boulder_radius` metres round.
  uint32_t spare_boulders = 0;
  float spare_boulder_radius = 1.5f;
  // Floats: one for each of the scene's `floats` (its mesh and radius), then these spares for a
  // host to drop (logs, then leaves, of the scene file's default radii); all hidden until placed
  // with place_float().
  uint32_t spare_logs = 0;
  uint32_t spare_leaves = 0;
  bool enable_timing = false;        // GPU timestamps around the world's pass (pass_times())
  uint32_t queue_family_index = 0;   // with enable_timing: the family of the queue that runs it
};

// A boulder at a time: whether it is drawn, where (its obstacle's keys, or where place_boulder()
// stood it), and the radii of the ellipsoid its bumped surface stays within 15 % of.
struct BoulderPose {
  bool shown = false;
  glm::vec3 centre{0.0f};
  glm::vec3 radii{0.0f};
};

// What the world drew in its last main view (record()) and reflection (draw_reflection()):
// the pieces its views see, at their levels of detail, and the boulders.
struct WorldDrawStats {
  uint32_t main_triangles = 0;
  uint32_t reflection_triangles = 0;
};

class World {
 public:
  static Status create(const WorldCreateInfo& info, std::unique_ptr<World>* out);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // The camera of the scene's own path at that time (the default scene glides downstream; a
  // glTF river without keys is seen from above its upstream end).
  Camera scene_camera(double time_seconds) const;

  // The ground, riverbeds and objects as triangles in world space, for Renderer::set_occluders
  // (the boulders are left out: they stand for the renderer's own obstacles). Valid as long as
  // the world.
  OccluderMesh occluders() const;

  // The boulders: one per obstacle of the scene (its `obstacles`, in order), then the spares.
  uint32_t boulder_count() const;
  // Stands boulder `index` at `centre` from the next record() on (its keys no longer move it):
  // a host that moves or adds an obstacle in the water renderer moves its boulder with it.
  Status place_boulder(uint32_t index, const glm::vec3& centre);
  // Draws boulder `index` no more until it is placed again (its obstacle was removed).
  Status hide_boulder(uint32_t index);
  // Boulder `index` as record() would draw it at `time_seconds` (a capture's motion vectors).
  Status boulder_at(uint32_t index, double time_seconds, BoulderPose* out) const;

  // The floats: the scene's `floats` in order, then the spare logs and leaves.
  uint32_t float_count() const;
  // Draws float `index` from the next record() on with its centre at `centre` (on the water
  // surface: the host drifts it, e.g. with siviflow/drift.h), its length turned from +x by
  // `heading` radians towards +z (along (cos, 0, sin)).
  Status place_float(uint32_t index, const glm::vec3& centre, float heading);
  Status hide_float(uint32_t index);
  // How far float `index`'s mesh reaches from its centre: x (and z) along its length, y up. The
  // upright cylinder of radius x and half height y holds it at any heading (motion vectors).
  Status float_reach(uint32_t index, glm::vec3* out) const;

  // The host has waited until the GPU finished the commands last recorded for this slot.
  Status begin_frame(uint32_t slot);
  // Records the world seen through `view` at `time_seconds` (obstacles where their keys put
  // them) into `color` and `depth`, writing every pixel of the view's viewport (depth cleared
  // first, the sky where nothing else is), and leaves them in their final states. The depth
  // convention (standard or reverse-Z) is the projection's.
  Status record(VkCommandBuffer cmd, const View& view, double time_seconds,
                const ExternalImage& color, const ExternalImage& depth);

  // The world's passes ("world") of the frame last recorded in `slot`, once the host waited for
  // it; needs WorldCreateInfo::enable_timing.
  Status pass_times(uint32_t slot, std::vector<PassTime>* out) const;
  WorldDrawStats draw_stats() const;

  // A siviflow::ReflectionCallback (user: this World): draws the world as of the last record(),
  // mirrored and clipped as `view` says.
  static void draw_reflection(VkCommandBuffer cmd, const ReflectionView& view, void* world);

 private:
  struct Impl;
  explicit World(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace siviflow
