// The passes of the SiViFlow frame graph. Each pass knows the frame graph and its own shaders,
// not the other passes; the renderer wires their handles together.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <vulkan/vulkan.h>

#include "index_range.h"
#include "shared.h"
#include "siviflow/renderer.h"
#include "siviflow/status.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"
#include "vk/pipeline.h"

namespace siviflow {

// ---- upload: staging block -> device buffers and images (always a real copy) ----

// One copy from the frame slot's staging block, recorded by the upload pass. Destinations are
// graph handles, so the copy and the graph's barriers always name the same resource.
struct BufferUpload {
  VkDeviceSize staging_offset = 0;
  BufferHandle destination;
  VkDeviceSize size = 0;
};
struct ImageUpload {
  VkDeviceSize staging_offset = 0;
  ImageHandle destination;
  VkExtent2D extent{};  // of this mip level
  uint32_t mip_level = 0;
};

// What the upload pass copies; filled on the CPU before the pass records.
struct UploadList {
  std::vector<BufferUpload> buffers;
  std::vector<ImageUpload> images;
  void clear() {
    buffers.clear();
    images.clear();
  }
};

// Declares the pass: it writes every destination of `list` (their handles are replaced by the
// written versions; the levels of one image must be listed one after another) from the
// imported staging buffer. Each execute binds the frame's list (those destinations, this frame's
// staging offsets) to the returned handle.
DataHandle<UploadList> add_upload_pass(FrameGraph& graph, BufferHandle staging, UploadList* list);

// ---- reflection: the host's world mirrored about the water plane ----

// Declares the reflection target's pass: colour cleared to transparent ("nothing reflected"),
// depth cleared to the far value the frame sets (FrameBindings::set_clear), then `callback` (if
// any) draws the host's world as each execute's bound ReflectionView says (its extent filled in).
DataHandle<ReflectionView> add_reflection_pass(FrameGraph& graph, ImageHandle* color,
                                               ImageHandle* depth, ReflectionCallback callback,
                                               void* user);

// ---- refraction copy: what the host drew, before the water, for the water to see through ----

// What a frame's refraction copy takes: the viewport's offset in the host's image, and the part
// of the view (its own pixels) the water samples; nothing is copied when that part is empty.
struct RefractionCopy {
  VkOffset2D viewport_offset{0, 0};
  VkRect2D area{};
};
// Declares the copy of the view's viewport of the host's `color` into `copy` (the view's size,
// the colour's format; its handle is replaced by the written version), which the water samples
// where it refracts: an image cannot be sampled while it is drawn to. Each execute binds the
// frame's RefractionCopy to the returned handle; the rest of `copy` is never sampled.
DataHandle<RefractionCopy> add_refraction_copy_pass(FrameGraph& graph, ImageHandle color,
                                                    ImageHandle* copy);

// ---- flow: the water material of Algorithm 3, drawn over the scene ----

// Draws the river surface: first (compute) the tile table, the flow at every Tiled Directional
// Flow tile centre near the camera; then per fragment the particle (flow texture, aux data by
// slot), the Tiled Directional Flow normal from the table, the reflection sampled with that
// normal, what lies under the water (the refraction copy) sampled with it and absorbed per
// colour channel, depth colour and shore fade, over the scene's colour. It also writes, unblended,
// where configured: the motion vectors and reactive mask into the host's images, and the water
// mask, the normal, the reflection sample and the foam coverage (AOVs). A pass after it can write
// the surface's depth into the host's depth.
class FlowPass {
 public:
  static constexpr VkFormat kMaskFormat = VK_FORMAT_R32_SFLOAT;
  static constexpr VkFormat kNormalFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  static constexpr VkFormat kReflectionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  static constexpr VkFormat kFoamFormat = VK_FORMAT_R32_SFLOAT;
  static constexpr uint32_t kAovAttachmentCount = 4;  // mask, normal, reflection, foam

  static constexpr VkFormat kTileTableFormat = VK_FORMAT_R32G32B32A32_UINT;  // shaders/shared.h
  static constexpr VkFormat kWaterHeightsFormat = VK_FORMAT_R32_SFLOAT;

  struct Config {
    VkFormat color_format = VK_FORMAT_UNDEFINED;
    VkFormat depth_format = VK_FORMAT_UNDEFINED;
    VkFormat motion_format = VK_FORMAT_UNDEFINED;    // UNDEFINED: no motion output
    VkFormat reactive_format = VK_FORMAT_UNDEFINED;  // UNDEFINED: no reactive output
    uint32_t slot_count = 1;
    bool with_aovs = false;
    bool with_floor = false;  // the bench's floor pipeline (declare_floor)
    bool with_depth = false;  // the surface's depth pipeline (declare_depth)
    // The material whose pipeline is compiled at create; the others, and the debug views', when
    // a frame first draws with them (prepare_pipeline).
    WaterMaterial material = WaterMaterial::kTiledDirectionalFlow;
  };
  // One material descriptor set per frame slot (the host's depth changes per frame).
  Status create(const GpuContext& gpu, VkPipelineCache cache, const Config& config);
  void destroy(const GpuContext& gpu);

  struct Textures {
    VkImageView flow = VK_NULL_HANDLE;        // R16G16B16A16_UINT, shaders/shared.h
    VkImageView aux = VK_NULL_HANDLE;         // R32G32B32A32_SFLOAT, shaders/shared.h
    VkImageView reflection = VK_NULL_HANDLE;  // the mirrored scene
    VkImageLayout reflection_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    VkImageView normal_map = VK_NULL_HANDLE;  // tileable, mipmapped
    VkImageView tile_table = VK_NULL_HANDLE;  // kTileTableFormat
    VkImageView water_heights = VK_NULL_HANDLE;  // kWaterHeightsFormat, sim/water_heights.h
    VkImageView refraction = VK_NULL_HANDLE;  // the host's colour before the water, view-sized
  };
  // Points a fresh descriptor set at the textures of this configuration. The previous pool is
  // handed to `retire`, to be destroyed once no frame in flight uses it.
  Status bind_textures(const GpuContext& gpu, const Textures& textures,
                       const std::function<void(VkDescriptorPool)>& retire);

  // What a frame draws with: the frame slot (whose previous frame the host has waited for), a
  // view of the host depth's depth aspect, the depth convention, the viewport in the host's
  // images, the water's look and the passes' push constants.
  struct Frame {
    uint32_t slot = 0;
    VkImageView host_depth = VK_NULL_HANDLE;
    bool reverse_z = false;
    VkRect2D viewport{};
    VkRect2D scissor{};  // inside the viewport
    gpu::WaterLookConstants look{};
    WaterMaterial material = WaterMaterial::kTiledDirectionalFlow;  // which pipeline draws
    DebugView debug_view = DebugView::kNone;
    gpu::FlowConstants flow{};
    gpu::FlowTileConstants tiles{};
    // The runs of the river's indices the view can see: the water, depth and floor draw them.
    const std::vector<IndexRange>* draws = nullptr;
  };
  // Before anything of a frame is recorded: compiles the pipeline of its material and debug view
  // if no frame drew with them yet (a failure leaves none, and the next frame tries again).
  Status prepare_pipeline(const GpuContext& gpu, const Frame& frame);
  // Before recording a frame: points the slot's descriptor set at the frame's host depth and
  // writes its look block.
  void prepare_frame(const GpuContext& gpu, const Frame& frame);
  // Where the declared passes read the frame when the graph executes (bind it every execute).
  DataHandle<Frame> frame_data() const { return frame_data_; }

  struct Handles {
    ImageHandle color;       // the host's colour: loaded, blended over
    ImageHandle depth;       // the host's depth: tested and sampled, not written
    ImageHandle flow;
    ImageHandle aux;
    ImageHandle reflection;
    ImageHandle normal_map;
    ImageHandle tile_table;     // written by declare_tiles (compute), read by the material
    ImageHandle water_heights;  // read by declare_tiles
    ImageHandle refraction;     // the host's colour before the water (add_refraction_copy_pass)
    BufferHandle vertices;   // river surface positions (vec3)
    BufferHandle indices;
    ImageHandle motion;      // the host's, written where configured; loaded and kept elsewhere
    ImageHandle reactive;
    ImageHandle mask;        // AOVs, written when created with_aovs
    ImageHandle normal;
    ImageHandle reflection_sample;
    ImageHandle foam;
  };
  // The tile table of this frame (shaders/flow_tiles.comp), before declare; the new version of
  // handles->tile_table goes back into `handles`.
  void declare_tiles(FrameGraph& graph, Handles* handles);
  void declare(FrameGraph& graph, Handles* handles);
  // After declare: the surface's depth into the host's depth where the water is in front (the
  // new version of handles->depth goes back into `handles`).
  void declare_depth(FrameGraph& graph, Handles* handles);
  // The floor of the flow pass for benchmarks: the same pixels (river mesh, depth test) making
  // the same texture reads with next to no arithmetic, blended into `target` (of the colour
  // format); kept although nothing reads it.
  void declare_floor(FrameGraph& graph, const Handles& inputs, ImageHandle target);

 private:
  void draw_river(const PassContext& ctx, VkPipeline pipeline, const Handles& h) const;
  Status ensure_material_pipeline(const GpuContext& gpu, WaterMaterial material, bool debug_views);

  Config config_;
  DataHandle<Frame> frame_data_;  // declared by declare_tiles, in the graph of the passes
  VkPipeline floor_pipeline_ = VK_NULL_HANDLE;
  VkPipeline depth_pipeline_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  // The material's pipelines: per WaterMaterial, without and with the debug views (null until
  // a frame needs one), and what they are made from.
  VkPipeline pipelines_[kWaterMaterialCount][2] = {};
  GraphicsPipelineDesc material_desc_;
  VkPipelineCache cache_ = VK_NULL_HANDLE;
  VkPipeline tiles_pipeline_ = VK_NULL_HANDLE;  // compute, with a layout and set of its own
  VkDescriptorSetLayout tiles_set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout tiles_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool tiles_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet tiles_set_ = VK_NULL_HANDLE;
  VkSampler nearest_ = VK_NULL_HANDLE;  // flow and aux: texelFetch only, integer formats
  VkSampler linear_clamp_ = VK_NULL_HANDLE;
  VkSampler linear_repeat_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_;  // per frame slot
  Buffer look_buffer_;                 // host-visible, one WaterLookConstants block per slot
};

// ---- readback: images -> host buffers (tools and tests only) ----

struct ReadbackCopy {
  ImageHandle image;    // copied tightly packed (depth formats: the depth aspect)
  BufferHandle buffer;  // imported, handed back in the HostRead state; replaced by the written version
  VkRect2D region{};    // the part copied, read when the pass records; 0x0: the whole image
};
// Declares the copies (their buffers replaced by the written versions); each execute binds the
// frame's copies (the same, with this frame's regions) to the returned handle.
DataHandle<std::vector<ReadbackCopy>> add_readback_pass(FrameGraph& graph,
                                                        std::vector<ReadbackCopy>* copies);

}  // namespace siviflow
