// SiViFlow renderer: the embedding interface.
//
// The host owns the instance (Vulkan 1.3: VkApplicationInfo::apiVersion 1.3 or later), the
// device, the queue and the command buffers. It fills one CreateInfo (zero-initialised fields
// take the documented defaults; color_format, extent and the handles are required), enables
// required_device_features() when it creates its device, and per frame:
//   1. waits on its own fence for the frame slot it is about to reuse, then begin_frame(slot);
//   2. update(view, time)     — CPU only: the host's view matrices, simulation and packing into
//                               the slot's staging block;
//   3. (the host draws its world into its colour and depth images)
//   4. record(cmd, inputs)    — records upload, reflection and water passes into the host's
//                               command buffer, outside any host render pass: the river is blended
//                               over the host's colour and depth-tested against its depth, and
//                               every host image is left in the state the host asked for.
//   5. (the host submits the command buffer with the slot's fence)
// An updated frame is recorded or dropped (abandon_frame) before the next begin_frame.
// Host images (FrameInputs): colour COLOR_ATTACHMENT + TRANSFER_SRC usage; depth
// DEPTH_STENCIL_ATTACHMENT + SAMPLED, stored by the host's pass (storeOp STORE); motion and
// reactive COLOR_ATTACHMENT. Each is stated with its state on entry and the state wanted on exit.
// Space: river space is +Y up, in metres (the river's mesh, obstacles, the look's sun);
// CreateInfo::world_from_river places it in the host's world (identity: the host's world is
// river space); views, occluders and river_bounds() are in the host's world.
// The renderer draws only the water: no sky, terrain or objects (the built-in world of our tools
// is a host component of its own, siviflow/world.h).
// The renderer never submits, never waits idle and never owns a swapchain. It calls Vulkan only
// through a private function table loaded from the host's vkGet*ProcAddr.
// Destroy it only when the GPU has finished every frame it recorded.
// Every call that can fail returns a Status: no exception leaves the library (a failed
// allocation is VK_ERROR_OUT_OF_HOST_MEMORY), errors in the caller's arguments carry no Vulkan
// result (Status::kGenericError), and every error message starts with "siviflow::Renderer: "
// and also reaches CreateInfo::log.
// Threads: the library holds no global state and takes no locks. Calls on one renderer must not
// overlap; a host may make them from different threads in turn when it orders them itself (a
// mutex, a queue hand-off), say begin_frame and update on a simulation thread and record on the
// render thread. Renderers that share a river (CreateInfo::share_river_with) share its flow,
// obstacles and occluders, so their calls must not overlap either; renderers of different
// rivers are independent. The one exception: query_water only reads, so it may run on any
// thread (a physics thread) at the same time as record() and as other query_water calls, of
// this renderer or of those sharing its river, but not with a call that changes the flow
// (begin_frame, update and simulate, which move keyed obstacles; add_, move_ and
// remove_obstacle; set_look; resize; destroying the renderer). The log callback runs on the thread of the
// call that logs.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

#include "siviflow/sim/water_sample.h"
#include "siviflow/water_look.h"
#include "siviflow/water_river.h"
#include "siviflow/status.h"
#include "siviflow/version.h"

namespace siviflow {

enum class LogLevel { kInfo, kWarning, kError };
class Renderer;

// What the water shows in place of its look, to see what the material reads (set_debug_view):
// the flow as a colour per direction with an arrow per ripple tile, each particle's pixels in a
// colour of its own, or the look with the ripple tiles outlined.
enum class DebugView : uint32_t { kNone, kFlowDirection, kParticles, kTileGrid };
inline constexpr uint32_t kDebugViewCount = 4;
// "none", "flow", "particles", "tiles"; "" for a value out of range.
const char* debug_view_name(DebugView view);

// What a host's own reflection drawing needs: the scene mirrored about the water plane, seen from
// the real camera, and the plane to clip below (keep dot(plane.xyz, p) + plane.w >= 0).
struct ReflectionView {
  float view_proj[16];   // column-major, Vulkan clip space (depth 0..1, +Y down), mirror included
  float clip_plane[4];   // world space
  float camera_position[3];  // the mirrored camera, for view-dependent shading
  VkExtent2D extent;     // of the reflection target
  bool reverse_z;        // the host's projection maps near to 1 and far to 0 (depth cleared to 0)
  VkFormat format;       // of the reflection target: reflection_format(CreateInfo::color_format)
  // The part of the target the water samples this frame (the water on screen, widened by how far
  // its ripples bend a sample); the scissor is set to it. Empty when no water is in view.
  VkRect2D area;
};
// Records the host's world into the reflection target. Called inside the reflection pass, with
// dynamic rendering begun (colour: ReflectionView::format, cleared to transparent black;
// depth: VK_FORMAT_D32_SFLOAT, cleared to the far value of the view's depth convention) and
// viewport (the whole target) and scissor (ReflectionView::area) set; the host binds its own
// pipelines (with that rendering format and gl_ClipDistance against clip_plane) and must not
// end the rendering. Where the host leaves the colour's alpha at 0, the water reflects the sky
// along the reflected ray.
using ReflectionCallback = void (*)(VkCommandBuffer cmd, const ReflectionView& view, void* user);
using LogCallback = void (*)(LogLevel level, const char* message, void* user);

struct CreateInfo {
  VkInstance instance = VK_NULL_HANDLE;                    // host's instance (Vulkan >= 1.3)
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;       // the device's physical device
  VkDevice device = VK_NULL_HANDLE;                        // created with required_device_features()
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;  // required: loads our private table
  PFN_vkGetDeviceProcAddr get_device_proc_addr = nullptr;  // optional: else from the instance
  // The feature chain the device was created with (what VkDeviceCreateInfo::pNext held). Required:
  // create() checks it enables every feature of required_device_features() and names any missing.
  const VkPhysicalDeviceFeatures2* enabled_features = nullptr;
  uint32_t queue_family_index = 0;     // family of the queue that will run what we record (graphics)
  uint32_t frames_in_flight = 0;       // ring slots; 0 means 2
  // Host colour image format; required. Any colour format with red, green and blue that the
  // device can blend into as a colour attachment, sample and copy (optimal tiling):
  // B10G11R11_UFLOAT_PACK32, A2B10G10R10_UNORM_PACK32, R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT,
  // R8G8B8A8 and B8G8R8A8 in UNORM and SRGB, ... create() names a missing format feature.
  VkFormat color_format = VK_FORMAT_UNDEFINED;
  // Host depth image format: D32_SFLOAT (0 means this), D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT.
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent = {0, 0};          // the view's size in pixels (its viewport); required
  // Outputs for the host's temporal filters (TAA, FSR 2/3, DLSS, XeSS), written where the water
  // is the nearest surface and kept elsewhere; VK_FORMAT_UNDEFINED: none, and FrameInputs::motion
  // / ::reactive are not read. Motion: a two-channel float format (R16G16_SFLOAT,
  // R32G32_SFLOAT); reactive: a colour format with red (R8_UNORM, R16_SFLOAT, ...).
  VkFormat motion_format = VK_FORMAT_UNDEFINED;
  VkFormat reactive_format = VK_FORMAT_UNDEFINED;
  // The water writes its surface's depth into FrameInputs::depth once it has drawn (for the
  // host's fog, depth of field and later transparent passes); its own reads of what lies behind
  // it still see the host's depth. Off: the host's depth is only tested, never written.
  bool write_depth = false;
  // Places the river (its mesh, obstacles and their keys, the look's sun direction, all in river
  // space: +Y up, metres) in the host's world. Meant for a rotation and a translation; any
  // finite invertible affine matrix is taken, but the water's look measures river metres, so a
  // scale or shear stretches its ripples and depths with it. Views, occluders and river_bounds()
  // are in the host's world. A Z-up engine puts its rotation here instead of rotating its views.
  glm::mat4 world_from_river{1.0f};
  // The images to copy into host buffers each frame (ReadbackImage bits, readback_bit()); 0,
  // the shipping path: no copies and no AOV attachments.
  uint32_t readback_images = 0;
  uint64_t seed = 0;                   // seed of the river particles' random choices
  // The river to render (siviflow/water_river.h); null: the built-in default river with its two
  // boulders. Read by create() only: the renderer copies what it needs.
  const WaterRiver* river = nullptr;
  // Optional: called once by create(), as soon as the renderer holds its own copy of everything
  // `river` points at (the surface's nodes and triangles made, before it finds their sections),
  // and before it solves the flow and makes its buffers. The host may free the river's arrays
  // there, so a long river is not held twice at the peak of creation (a 100 km river's mesh is
  // about 60 MB). Not called for the built-in river, with share_river_with, or
  // when create() fails before the copy is made; a create() that fails after it may have called
  // it, so a host that frees there cannot retry with the same arrays.
  void (*river_copied)(void* user) = nullptr;
  void* river_copied_user = nullptr;
  // The water's starting look; null: WaterLook's defaults. Read by create() only; set_look()
  // changes it.
  const WaterLook* look = nullptr;
  // Another view of the same river: a renderer on the same device whose river this one shares
  // (its surface, flow, obstacles, occluders and static GPU data: no second flow solve), with
  // particles, flow textures, tile table and reflection of its own; `river` is then not read.
  // Obstacles added and occluders set through either renderer reach both. Null: a river of its
  // own.
  const Renderer* share_river_with = nullptr;
  bool enable_timing = false;          // GPU timestamps around every pass (see pass_times())
  // With enable_timing: also the flow pass's floor (a pass over the water's pixels making the
  // same texture reads and writes with next to no arithmetic), for benchmarks; it costs GPU time.
  bool measure_flow_floor = false;
  VkDeviceSize staging_bytes_per_slot = 0;  // per-slot staging block; 0 means 8 MiB
  bool debug_utils = false;            // the host enabled VK_EXT_debug_utils: label passes, name objects
  // Optional. Used by create() and by a record() that first draws with another material or a
  // debug view: keep it until the renderer is destroyed, and if it was created
  // VK_PIPELINE_CACHE_CREATE_EXTERNALLY_SYNCHRONIZED_BIT, use it nowhere else during record().
  VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
  const VkAllocationCallbacks* allocation_callbacks = nullptr;  // optional
  ReflectionCallback reflection = nullptr;  // optional: the host draws the reflection instead
  void* reflection_user = nullptr;
  LogCallback log = nullptr;           // optional; warnings and errors with context
  void* log_user = nullptr;
};

// Features the host must enable on its device (Vulkan 1.3 core). Fill the host's chain with
// them; create() reports each one that is missing by name.
struct RequiredDeviceFeatures {
  VkPhysicalDeviceFeatures2 features2{};
  VkPhysicalDeviceVulkan13Features vulkan13{};
  // Links vulkan13 into features2.pNext; call after copying the struct.
  void link() { features2.pNext = &vulkan13; }
};
RequiredDeviceFeatures required_device_features();
// Their names, as used in error messages: "shaderClipDistance", "dynamicRendering", ...
std::vector<std::string> required_device_feature_names();
// Names of required features a chain (enabled or supported features) does not hold.
std::vector<std::string> missing_device_features(const VkPhysicalDeviceFeatures2* features);

// Triangles in world space, as Renderer::set_occluders takes them.
struct OccluderMesh {
  std::span<const glm::vec3> positions;
  std::span<const uint32_t> indices;  // 3 per triangle; empty: every 3 positions are one
};

// A host's view of the river: its matrices and where it lies in the host's images.
struct View {
  glm::mat4 view{1.0f};  // world -> view space (right-handed, looking down -Z)
  // view -> Vulkan clip space (x right, y down, depth 0..1), a perspective projection: standard
  // or reverse-Z, finite or infinite far plane, off-centre, with this frame's jitter in it. The
  // renderer derives the depth convention from it every frame.
  glm::mat4 projection{1.0f};
  // The sub-pixel offset `projection` carries this frame (pixels, x right, y down; a TAA or
  // upscaler jitter, e.g. Halton(2,3) - 0.5): a point the unjittered projection puts at pixel p
  // lands at p + jitter. The water is drawn jittered, as the host's world is; its particles,
  // motion vectors and (unless jitter_reflection) reflection use the unjittered projection, so
  // jitter neither churns particles nor shows in motion. |jitter| <= 64 px.
  glm::vec2 jitter{0.0f};
  bool jitter_reflection = false;  // draw the reflection with the jittered projection too
  // No previous frame to move from (a cut, a teleport): this frame's motion vectors are zero.
  // The first frame after create() and resize() is one too.
  bool camera_cut = false;
  // The pixels of the host's images the view covers; its extent must equal CreateInfo::extent.
  // An extent of 0x0 means {offset, CreateInfo::extent}.
  VkRect2D viewport{};
  // The water draws only inside this rectangle (host image pixels), which must lie inside the
  // viewport; 0x0: the whole viewport. Two views sharing pixels (picture in picture) keep apart.
  VkRect2D scissor{};
};

// A convenience for hosts without matrices of their own: a position, a target, +Y up.
struct Camera {
  glm::vec3 position{0.0f, 10.0f, -30.0f};
  glm::vec3 target{0.0f, 0.0f, 0.0f};
  float fov_y_deg = 50.0f;
  float near_plane = 0.1f;
  float far_plane = 1000.0f;
};
// The standard-depth view of `camera` over a viewport of `extent` at the images' origin.
View camera_view(const Camera& camera, VkExtent2D extent);

// An image's synchronisation state: what last touched it and its layout.
struct ImageState {
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

// A host image we use. `current` is its state when our commands start; `final` the state the
// host wants when they end, which must name a real layout (not UNDEFINED). The format, extent
// and usage are the host's word for what the image is, checked against what we need.
struct ExternalImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // depth: covering the depth aspect (and stencil, if any)
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent = {0, 0};
  ImageState current;
  ImageState final;
  // The usage it was created with. Colour: COLOR_ATTACHMENT and TRANSFER_SRC (the water copies
  // what it sees through); depth: DEPTH_STENCIL_ATTACHMENT and SAMPLED, and TRANSFER_SRC when
  // CreateInfo::readback_images copies it.
  VkImageUsageFlags usage = 0;
};

// What CreateInfo::readback_images can copy each frame into host-visible buffers, tightly packed
// rows, top-left origin of the view's viewport:
enum class ReadbackImage : uint32_t {
  kColor,        // the host's colour with the water, in its format's texels
  kDepth,        // the host's depth (with the water's under write_depth), 4-byte depth texels
  kWaterMask,    // 32-bit float, 1 where the river surface is the nearest thing seen, else 0
  kFlowTexture,  // the flow texture as uploaded (layout in shaders/shared.h)
  kParticleAux,  // the particles' auxiliary data as uploaded (shaders/shared.h)
  kNormal,       // RGBA32F: the final water normal in river space (xyz) on water, 0 elsewhere
  kReflection,   // RGBA32F: the reflection sample of the water material before blending
  kTileTable,    // RGBA32UI: the water's tile table (shaders/shared.h), tile_table_layout()
  kFoam,         // 32-bit float: how much of the water foam covers, 0 none to 1 full, 0 off water
};
inline constexpr uint32_t kReadbackImageCount = 9;
constexpr uint32_t readback_bit(ReadbackImage image) { return 1u << static_cast<uint32_t>(image); }
inline constexpr uint32_t kAllReadbackImages = (1u << kReadbackImageCount) - 1;
// The water mask, normal, reflection sample and foam come from extra attachments of the water
// pass, added only when one of them is read back.
inline constexpr uint32_t kAovReadbackImages = readback_bit(ReadbackImage::kWaterMask) |
                                               readback_bit(ReadbackImage::kNormal) |
                                               readback_bit(ReadbackImage::kReflection) |
                                               readback_bit(ReadbackImage::kFoam);

// The tile table of the water material (shaders/shared.h): its size and which lattice points
// the last updated frame put in it (the corner moves with the camera on rivers larger than the
// table: decode a read-back table before updating the next frame). Texel (x, y) holds lattice
// point corner + ((x, y) - corner) mod size, the river point (i, j) * tile_size_m / 2 in x, z.
struct TileTableLayout {
  uint32_t width = 0;  // texels, a power of two
  uint32_t height = 0;
  int32_t corner_x = 0;  // lattice point of the window's corner
  int32_t corner_z = 0;
  float tile_size_m = 0.0f;
};
const char* readback_image_name(ReadbackImage image);

struct ReadbackTargets {
  VkBuffer buffers[kReadbackImageCount] = {};  // indexed by ReadbackImage; those read back only
  VkBuffer& operator[](ReadbackImage image) { return buffers[static_cast<uint32_t>(image)]; }
};

struct FrameInputs {
  // The host's colour image, with its world drawn: the water is drawn over it, and sees
  // through to a copy of it taken first (colour attachment and transfer source usages).
  ExternalImage color;
  // The host's depth image of the same frame: the water is depth-tested against it and reads it
  // for the depth of water behind each pixel (depth attachment and sampled usages; transfer
  // source with readback). Written only with CreateInfo::write_depth. The host's render pass
  // must store it (storeOp STORE): a tiled GPU otherwise hands the water garbage to test against.
  ExternalImage depth;
  // With CreateInfo::motion_format: the host's motion vectors, the view's pixels of it (colour
  // attachment usage). Where the water is the nearest surface it writes the screen motion of its
  // surface point, uv_previous - uv_current in viewport UV units (x right, y down, 1 = the
  // viewport's width or height), jitter excluded: FSR 2/3's and DLSS's default convention
  // (DLSS: scale by the viewport's size in pixels). Elsewhere the host's values stay.
  ExternalImage motion;
  // With CreateInfo::reactive_format: the host's reactive mask (colour attachment usage). Where
  // the water is the nearest surface it writes how much a temporal filter should distrust its
  // history there, 0..1 in the red channel: WaterLook::reactive_strength x the water's opacity
  // x min(1, the ripple strength the shore lets through + the Fresnel reflection share + the
  // foam cover).
  // Elsewhere the host's values stay.
  ExternalImage reactive;
  ReadbackTargets readback;
};

// The format of the reflection target a renderer of `color_format` draws into (and a host's
// ReflectionCallback draws with): the colour format itself when it has an alpha channel, whose
// 0 marks "nothing reflected, the sky shows"; R16G16B16A16_SFLOAT for one without
// (B10G11R11_UFLOAT_PACK32, ...) and for R32G32B32A32_SFLOAT (a half-size, filtered reflection
// gains nothing from 32-bit floats, which not every device filters). VK_FORMAT_UNDEFINED for a
// format create() does not take.
VkFormat reflection_format(VkFormat color_format);

// The device memory a view of `info` (its extent, formats, frames in flight, readback images,
// timing) takes, for a host's budget before create(); no device needed. Upper bounds where the
// river decides (the particles' slots, the tile table). It refuses exactly what create() refuses
// of `info`'s sizes and formats without asking a device (create() also asks the device's
// features of the formats), with the same messages.
struct ViewMemory {
  // The renderer's own: the reflection and its depth, the refraction copy, the AOV attachments
  // and the flow floor when asked for, the flow texture, particle aux data and tile table, and a
  // staging block per frame in flight. Not the river's static data (by the river's size, shared
  // by its views).
  VkDeviceSize renderer_bytes = 0;
  // The host's readback buffers of one frame in flight for CreateInfo::readback_images.
  VkDeviceSize readback_bytes = 0;
};
// An extent of 0 or a colour format the renderer does not take is an error naming it.
Status view_memory(const CreateInfo& info, ViewMemory* out);

struct PassTime {
  std::string name;     // the frame graph's pass name: "upload", "reflection", "scene", "flow", ...
  double begin_ms;      // when the pass started, from the start of the frame's first pass
  double milliseconds;  // GPU time between the timestamps around the pass
};

class Renderer {
 public:
  static Status create(const CreateInfo& info, std::unique_ptr<Renderer>* out);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // The host has waited until the GPU finished the commands last recorded for this slot. A frame
  // updated but not recorded is an error: record it, or abandon_frame() it first.
  Status begin_frame(uint32_t slot);
  // Drops the frame begun and not yet recorded (the host's own recording failed, or it decided
  // not to draw the water): its particles keep their step, nothing of it reaches the GPU, the next
  // frame's motion is measured from the last frame recorded, and begin_frame starts the next.
  // A command buffer that record() filled successfully must be submitted: it uploads the river's
  // static data once.
  Status abandon_frame();
  // CPU only: the host's view and simulation time for the frame being prepared: advances the
  // river's particles one frame (frame next_frame()) and packs the flow textures into the slot's
  // staging block. The particles carry state from frame to frame: to start at frame N and get
  // the same pixels as a run from frame 0, simulate() frames 0..N-1 first.
  Status update(const View& view, double time_seconds);
  // CPU only, outside begin_frame/record: advances the particles one frame without rendering,
  // so that a capture starting at frame N gets the same frame N as one starting at 0.
  Status simulate(const View& view, double time_seconds);
  // Records the frame into `cmd` (in the recording state, outside any render pass), after the
  // host's own drawing of colour and depth. On failure what it recorded is incomplete: the host
  // resets `cmd` instead of submitting it; the next begin_frame/update/record renders normally.
  Status record(VkCommandBuffer cmd, const FrameInputs& inputs);

  // Runtime obstacles. Each call re-solves the flow only around the old and new footprints
  // (the result equals a fresh solve) and the next update() carries the new flow. Call outside
  // begin_frame/record. An obstacle with a non-finite or degenerate footprint, or an unknown id,
  // is an error naming the field or id, and nothing changes. An added obstacle's keys move it
  // as update()'s time goes.
  Status add_obstacle(const WaterObstacle& obstacle, uint32_t* id);
  // Moves obstacle `id` to `centre`, its polygon turned to `rotation_rad`.
  Status move_obstacle(uint32_t id, const glm::vec3& centre, float rotation_rad = 0.0f);
  Status remove_obstacle(uint32_t id);

  // Gameplay's view of the water: for each point of the host's world, whether it lies over the
  // river surface and outside every obstacle's footprint, the surface point above or below it
  // (along the river's up axis) and its macro normal, the flow there (m/s), the depth to the bed,
  // the foam the material shows (this renderer's WaterLook::foam_amount in), and the obstacle
  // whose footprint holds it (siviflow/sim/water_sample.h), all in the host's world. CPU only,
  // from the solved flow as it stands (runtime obstacles count from the call that placed them,
  // keyed ones from the last update), not from the GPU; a walk down the surface's bounding volume
  // hierarchy a point (O(log n), well under a microsecond); deterministic. `out` holds at
  // least as many samples as `points`. A point that is not finite, or a short `out`, is an error
  // naming it, and nothing is written. Threads: see the top of this file.
  Status query_water(std::span<const glm::vec3> points, std::span<WaterSample> out) const;

  // The host's geometry that can stand between a camera and the water (ground, buildings,
  // props; not the obstacles, which the renderer knows): particles are made only on water a
  // view sees, so no hidden water feeds the flow the visible water shows. World space, static
  // until the next call; copied, and its ray-cast structure built (O(n log n) in the triangles).
  // Shared by every view of the river from their next update() or simulate() on; an empty mesh
  // clears it. Call outside begin_frame/record. A bad mesh (a count not a multiple of 3, an index
  // out of range, a position not finite) is an error naming the field and index, and nothing
  // changes.
  Status set_occluders(const OccluderMesh& mesh);

  // The water's look from the next update() on. A field out of its range (water_look.h) is an
  // error naming it and its value, and the look stays as it was. A material no frame drew with
  // yet has its pipeline compiled by the next record() (create() compiles the starting one's);
  // if that fails, record() fails before recording anything, and the next record() tries again.
  Status set_look(const WaterLook& look);
  const WaterLook& look() const;
  // The debug view from the next update() on; a value out of the enum is an error. The first
  // frame with a debug view compiles its pipeline in record(), as set_look says.
  Status set_debug_view(DebugView view);
  DebugView debug_view() const;

  // New view size. Call between frames (not between begin_frame and record); images that
  // frames in flight still use are freed once every slot has come round again. When it fails
  // (a size the particles cannot cover fails before anything changed; a failed allocation after
  // the old images were let go), begin_frame refuses to render until a resize succeeds.
  Status resize(VkExtent2D extent);

  // With CreateInfo::enable_timing: the GPU time of each pass of the frame last recorded in
  // `slot`. Call only after the host waited for that slot's frame.
  Status pass_times(uint32_t slot, std::vector<PassTime>* out) const;

  // The water surface's box in the host's world (CreateInfo::world_from_river applied), metres:
  // every point of the surface lies inside; for framing or culling the river.
  struct Bounds {
    glm::vec3 min{0.0f};
    glm::vec3 max{0.0f};
  };
  Bounds river_bounds() const;

  const TileTableLayout& tile_table_layout() const;
  // The index of the next frame update() or simulate() will advance to.
  uint64_t next_frame() const;
  // Full solves of this renderer's river flow so far (one at its creation; the renderers that
  // share the river share the count). Runtime obstacles re-solve incrementally, not fully.
  uint64_t flow_solves() const;

  // Byte size of the readback buffer of that image at the configured extent.
  VkDeviceSize readback_bytes(ReadbackImage image) const;
  // The frame graph of the current configuration, as text and as Graphviz.
  std::string dump_frame_graph() const;
  std::string dump_frame_graph_graphviz() const;

 private:
  struct Impl;
  friend class RendererInspector;  // what our tools and tests read of the simulation
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace siviflow
