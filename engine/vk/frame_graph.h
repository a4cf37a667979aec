// The frame graph: declare once per configuration, compile once on the CPU, execute every frame.
//
//   FrameGraph graph;
//   ImageHandle color = graph.create_image({"color", VK_FORMAT_R8G8B8A8_UNORM, {w, h}, clear});
//   PassBuilder scene = graph.add_pass("scene", PassKind::Graphics);
//   color = scene.color_write(color);             // a write returns the next version
//   scene.record([=](const PassContext& ctx) { ...; return Status(); });
//   Status s = graph.compile();                   // pure CPU: validate, cull, order, barriers
//   ...each frame: bind handles, graph.execute(table, cmd, bindings)
//
// What the caller must know:
// - Declaration order is execution order. A pass can only name versions that earlier passes
//   produced, so that order is always a valid topological order; nothing is reordered.
// - Each use is one verb of PassBuilder, which maps to one row of the Access table
//   (vk/access.h). A write verb returns the next version of the handle; keep using that one.
//   Reading a version after another pass wrote a newer one, or writing a version twice (two
//   writers in an undefined order), is an error reported by compile() naming both passes.
// - Declaration errors are kept and reported by compile(); the verbs themselves never fail.
// - The graph never allocates: after compile() the owner creates each transient or persistent
//   image with image_usage(handle) (0 means "unused by every surviving pass: don't create it")
//   and binds VkImage/VkImageView/VkBuffer handles per execute (they may change per frame slot).
// - Passes that reach no output are culled. Outputs are imported resources with an outgoing
//   state, persistent images, and passes marked side_effect() (e.g. a readback).
// - Transient images lose their contents between frames; their first barrier in a frame
//   waits on every use of the previous frame not yet ordered by a barrier (the last write and
//   all reads since), so one image may serve every frame slot.
//   Persistent images keep their contents: the graph assumes they start each frame in the
//   state the previous frame left them (the same steady state every frame); on the first
//   execute after creating one, the owner must call
//   FrameBindings::set_incoming(handle, ResourceState{}) (undefined layout).
// - Imported images and buffers start in the incoming state given at import (or overridden
//   per execute) and are handed back in their outgoing state after the last pass: the final
//   transition makes every access of the frame (reads included) happen before the outgoing
//   stage. An image's outgoing layout must not be UNDEFINED or PREINITIALIZED (a barrier cannot
//   transition to them); compile() and execute() reject that, naming the resource.
// - Images with a depth/stencil format are sampled in DEPTH_STENCIL_READ_ONLY_OPTIMAL, so a
//   pass may both depth_read() and sample one image. Descriptors must take their layout from
//   PassContext::layout().
// - execute() derives barriers again only when the per-execute states differ from the previous
//   execute's; with the same states every frame (or none), it neither derives nor allocates.
// - execute() records into the caller's command buffer, outside any render pass; it never
//   submits or waits. If it returns an error after recording started, discard the buffer.
// - Per-frame data a callback reads (push constants, the host's view, this frame's copies) is
//   declared like a resource (declare_data) and bound per execute (FrameBindings::bind_data):
//   callbacks read it through PassContext::data, never through pointers captured at declaration.
//   execute() refuses to record when a declared datum is not bound, naming it.
// - Not thread-safe; handles and PassBuilders must not outlive (or be moved away from) their
//   graph. Record callbacks run inside execute() and should capture handles by value.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "siviflow/status.h"
#include "vk/access.h"

namespace siviflow {

struct DeviceTable;

enum class PassKind : uint8_t { Transfer, Graphics, Compute };
const char* pass_kind_name(PassKind kind);

// Attachment load op. Auto: clear a transient image on its first write, load otherwise.
enum class LoadOp : uint8_t { Auto, Clear, Load, DontCare };

enum class ShaderStage : uint8_t { Vertex, Fragment, Compute };

inline constexpr uint32_t kNoResource = UINT32_MAX;

// Versioned handles: id names the resource, version the contents after `version` writes.
struct ImageHandle {
  uint32_t id = kNoResource;
  uint32_t version = 0;
  bool valid() const { return id != kNoResource; }
  bool operator==(const ImageHandle&) const = default;
};
struct BufferHandle {
  uint32_t id = kNoResource;
  uint32_t version = 0;
  bool valid() const { return id != kNoResource; }
  bool operator==(const BufferHandle&) const = default;
};

// Per-frame data of type T that passes read when they record.
template <typename T>
struct DataHandle {
  uint32_t id = kNoResource;
  bool valid() const { return id != kNoResource; }
};

struct ImageDesc {
  std::string name;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};
  VkClearValue clear{};  // used when an attachment's load op resolves to clear
};

struct BufferDesc {
  std::string name;
  VkDeviceSize size = 0;  // bytes covered by barriers; 0 means VK_WHOLE_SIZE
};

// Concrete handles and per-execute state overrides. Build one per frame (or per frame slot and
// rebind): an override stays until the object is reset.
class FrameBindings {
 public:
  void bind_image(ImageHandle image, VkImage vk_image, VkImageView view = VK_NULL_HANDLE);
  void bind_buffer(BufferHandle buffer, VkBuffer vk_buffer, VkDeviceSize offset = 0);
  // Replaces the import's declared (or a persistent image's assumed) state for this execute.
  void set_incoming(ImageHandle image, ResourceState state);
  void set_incoming(BufferHandle buffer, ResourceState state);
  void set_outgoing(ImageHandle image, ResourceState state);
  void set_outgoing(BufferHandle buffer, ResourceState state);
  // Replaces the declared clear value of an attachment for this execute (a depth convention
  // chosen per frame).
  void set_clear(ImageHandle image, VkClearValue clear);
  // The part of an imported image that passes drawing into it render (and clear) this execute,
  // when it is not the declared extent: one view in a host's image that holds several.
  void set_render_area(ImageHandle image, VkRect2D area);
  // This execute's value of a declared datum (it must outlive the execute).
  template <typename T>
  void bind_data(DataHandle<T> handle, const T* data) {
    if (handle.id >= data_.size()) data_.resize(handle.id + 1, nullptr);
    data_[handle.id] = data;
  }
  void reset() {
    bound_.clear();
    data_.clear();
  }

 private:
  friend class FrameGraph;
  friend class PassContext;
  struct Bound {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    std::optional<ResourceState> incoming;
    std::optional<ResourceState> outgoing;
    std::optional<VkClearValue> clear;
    std::optional<VkRect2D> render_area;
  };
  Bound& slot(uint32_t id);
  const Bound* find(uint32_t id) const { return id < bound_.size() ? &bound_[id] : nullptr; }
  const void* find_data(uint32_t id) const { return id < data_.size() ? data_[id] : nullptr; }
  std::vector<Bound> bound_;
  std::vector<const void*> data_;  // by DataHandle id
};

class FrameGraph;

// What a record callback sees. Lookups of unknown handles return null handles / zero extents.
class PassContext {
 public:
  VkCommandBuffer cmd() const { return cmd_; }
  const DeviceTable& table() const { return *table_; }
  VkImage image(ImageHandle image) const;
  VkImageView view(ImageHandle image) const;
  VkExtent2D extent(ImageHandle image) const;
  VkFormat format(ImageHandle image) const;
  VkImageLayout layout(ImageHandle image) const;  // the layout this pass uses it in
  VkBuffer buffer(BufferHandle buffer) const;
  VkDeviceSize offset(BufferHandle buffer) const;
  VkDeviceSize size(BufferHandle buffer) const;
  // This execute's value of a declared datum (execute() checked that it is bound).
  template <typename T>
  const T& data(DataHandle<T> handle) const {
    return *static_cast<const T*>(bindings_->find_data(handle.id));
  }

 private:
  friend class FrameGraph;
  PassContext(const FrameGraph& graph, const FrameBindings& bindings, const DeviceTable& table,
              VkCommandBuffer cmd, uint32_t pass)
      : graph_(&graph), bindings_(&bindings), table_(&table), cmd_(cmd), pass_(pass) {}
  const FrameGraph* graph_;
  const FrameBindings* bindings_;
  const DeviceTable* table_;
  VkCommandBuffer cmd_;
  uint32_t pass_;
};

// A graphics pass's callback runs inside vkCmdBeginRendering; others run outside any rendering.
// A failed status aborts execute() and is returned to its caller, prefixed with the pass name.
using RecordFn = std::function<Status(const PassContext&)>;

// States the uses of one pass. Each verb is one Access row; write verbs return the next version.
class PassBuilder {
 public:
  // Graphics. Colour attachments are numbered in call order; at most one depth attachment.
  ImageHandle color_write(ImageHandle image, LoadOp load = LoadOp::Auto);
  ImageHandle depth_write(ImageHandle image, LoadOp load = LoadOp::Auto);
  void depth_read(ImageHandle image);  // depth test without depth writes
  void vertex_read(BufferHandle buffer);
  void index_read(BufferHandle buffer);
  // Graphics or compute (the stage must match the pass kind).
  void sampled(ImageHandle image, ShaderStage stage);
  void sampled_fragment(ImageHandle image) { sampled(image, ShaderStage::Fragment); }
  void uniform_read(BufferHandle buffer);
  void storage_read(ImageHandle image, ShaderStage stage);
  void storage_read(BufferHandle buffer, ShaderStage stage);
  // Compute only. The previous contents are not kept unless the pass also storage_read()s them.
  ImageHandle storage_write(ImageHandle image);
  BufferHandle storage_write(BufferHandle buffer);
  // Transfer or compute. A transfer write is assumed to overwrite what the pass touches.
  ImageHandle transfer_write(ImageHandle image);
  BufferHandle transfer_write(BufferHandle buffer);
  void transfer_read(ImageHandle image);
  void transfer_read(BufferHandle buffer);

  // Keeps the pass even if nothing in the graph reads what it writes (readback, debug dumps).
  PassBuilder& side_effect();
  PassBuilder& record(RecordFn fn);

 private:
  friend class FrameGraph;
  PassBuilder(FrameGraph* graph, uint32_t pass) : graph_(graph), pass_(pass) {}
  template <typename Handle>
  Handle use(Handle handle, Access access, LoadOp load = LoadOp::Auto);
  FrameGraph* graph_;
  uint32_t pass_;
};

class FrameGraph {
 public:
  // Resources. Names appear in errors and dumps; keep them unique.
  ImageHandle create_image(ImageDesc desc);  // transient
  ImageHandle create_persistent_image(ImageDesc desc);
  ImageHandle import_image(ImageDesc desc, ResourceState incoming,
                           std::optional<ResourceState> outgoing = std::nullopt);
  BufferHandle create_buffer(BufferDesc desc);  // transient
  BufferHandle import_buffer(BufferDesc desc, ResourceState incoming,
                             std::optional<ResourceState> outgoing = std::nullopt);

  PassBuilder add_pass(std::string name, PassKind kind);
  // Per-frame data, bound per execute by FrameBindings::bind_data.
  template <typename T>
  DataHandle<T> declare_data(std::string name) {
    data_names_.push_back(std::move(name));
    return {static_cast<uint32_t>(data_names_.size() - 1)};
  }

  // Pure CPU, no device. Steps: validate, cull, order, usage flags, attachments, barriers.
  Status compile();
  bool compiled() const { return compiled_; }

  // Records every surviving pass into cmd, then the transitions to the outgoing states. Every
  // resource a surviving pass uses must be bound (attachments with a view); checked first.
  // Const for callers, but it keeps caches (barriers per override set, scratch arrays).
  // With `timestamps`, a timestamp is written before and after each surviving pass, at queries
  // first_query + 2i and + 2i + 1 (pass i of pass_order()); the caller resets them beforehand.
  struct Timestamps {
    VkQueryPool pool = VK_NULL_HANDLE;
    uint32_t first_query = 0;
  };
  Status execute(const DeviceTable& table, VkCommandBuffer cmd, const FrameBindings& bindings,
                 const Timestamps* timestamps = nullptr) const;

  // Valid after compile(). Usage is the union over surviving passes.
  VkImageUsageFlags image_usage(ImageHandle image) const;
  VkBufferUsageFlags buffer_usage(BufferHandle buffer) const;
  const ImageDesc* image_desc(ImageHandle image) const;
  std::vector<std::string> pass_order() const;  // surviving passes, in execution order
  bool culled(const std::string& pass) const;

  // Stable, line per barrier: the order, culled passes, barriers, load/store ops, final
  // transitions. Meant for test expectations.
  std::string dump_text() const;
  std::string dump_graphviz() const;

 private:
  std::vector<std::string> data_names_;  // by DataHandle id
  friend class PassBuilder;
  friend class PassContext;
  enum class Origin : uint8_t { Transient, Persistent, Imported };
  enum class Role : uint8_t { Plain, Color, Depth };
  static constexpr uint32_t kNoPass = UINT32_MAX;

  struct Resource {
    std::string name;
    bool is_image = true;
    Origin origin = Origin::Transient;
    ImageDesc image;
    VkDeviceSize size = 0;
    ResourceState incoming;  // imports: declared; others: derived in compile
    std::optional<ResourceState> outgoing;
    std::vector<uint32_t> writers{kNoPass};  // writers[v]: the pass that produced version v
    VkImageUsageFlags image_usage = 0;
    VkBufferUsageFlags buffer_usage = 0;
    bool live = false;  // used by a surviving pass
  };
  struct Use {
    uint32_t resource = kNoResource;
    uint32_t version = 0;  // the version this pass reads or overwrites
    bool reads = false;    // needs the contents of `version`
    bool writes = false;   // produces version + 1
    Role role = Role::Plain;
    LoadOp load = LoadOp::Auto;
    ResourceState state;  // union of the rows of every verb on this resource in this pass
    VkImageUsageFlags image_usage = 0;
    VkBufferUsageFlags buffer_usage = 0;
    std::string verbs;  // Access names, for dumps
  };
  struct Pass {
    std::string name;
    PassKind kind = PassKind::Transfer;
    std::vector<Use> uses;
    RecordFn record;
    bool side_effect = false;
    bool alive = false;
  };
  struct Barrier {
    uint32_t resource = kNoResource;
    ResourceState src;
    ResourceState dst;
  };
  struct Attachment {
    uint32_t resource = kNoResource;
    VkAttachmentLoadOp load = VK_ATTACHMENT_LOAD_OP_LOAD;
    VkAttachmentStoreOp store = VK_ATTACHMENT_STORE_OP_STORE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  };
  struct Step {  // one surviving pass, ready to record
    uint32_t pass = kNoPass;
    std::vector<Attachment> colors;
    std::optional<Attachment> depth;
    VkExtent2D extent{};
  };
  struct Barriers {  // derived from one set of incoming and outgoing states
    std::vector<std::vector<Barrier>> steps;  // before each step, parallel to steps_
    std::vector<Barrier> final;               // to the outgoing states
  };
  // What a resource has been through since its last barrier, so that the next use gets exactly
  // the barrier it needs (Granite's invalidate/flush bookkeeping, per resource).
  struct Track {
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags2 write_stage = 0;  // last write or layout transition: later uses wait
    VkAccessFlags2 write_access = 0;        // its writes, still to be made available
    VkPipelineStageFlags2 read_stages = 0;  // reads since: a later write must wait on them (WAR)
    VkPipelineStageFlags2 visible_stages = 0;  // where the last write is already visible
    VkAccessFlags2 visible_access = 0;
    bool operator==(const Track&) const = default;
  };
  struct Override {  // one resource's per-execute states
    std::optional<ResourceState> incoming;
    std::optional<ResourceState> outgoing;
    bool operator==(const Override&) const = default;
  };

  uint32_t add_resource(std::string name, bool is_image, Origin origin, ResourceState incoming,
                        std::optional<ResourceState> outgoing);
  ImageHandle add_image(ImageDesc desc, Origin origin, ResourceState incoming,
                        std::optional<ResourceState> outgoing);
  BufferHandle add_buffer(BufferDesc desc, Origin origin, ResourceState incoming,
                          std::optional<ResourceState> outgoing);
  uint32_t add_use(uint32_t pass, uint32_t id, uint32_t version, bool image, Access access,
                   LoadOp load);
  void fail(std::string message);
  const Use* find_use(uint32_t pass, uint32_t id) const;
  static Track start_track(const ResourceState& incoming);
  static bool advance(Track& track, const ResourceState& use, bool image, ResourceState* src);
  static bool finish(const Track& track, const ResourceState& out, bool image, ResourceState* src);
  // overrides is empty or has one entry per resource; ends (if given) gets the final tracks.
  void derive_barriers(const std::vector<Track>& starts, const std::vector<Override>& overrides,
                       Barriers& out, std::vector<Track>* ends) const;
  Status check_outgoing(uint32_t resource, const ResourceState& outgoing) const;
  const Barriers* barriers_for(const FrameBindings& bindings, Status* status) const;
  void emit_barriers(const DeviceTable& table, VkCommandBuffer cmd, const FrameBindings& bindings,
                     const std::vector<Barrier>& barriers) const;
  std::string barrier_line(const Barrier& barrier) const;

  std::vector<Resource> resources_;
  std::vector<Pass> passes_;
  std::string error_;  // first declaration error
  bool compiled_ = false;
  std::vector<Step> steps_;
  std::vector<Track> starts_;  // where each resource starts a frame (no overrides)
  Barriers barriers_;          // for the declared states: the listing of dump_text()

  // execute() caches: barriers for the last override set, and scratch arrays reused per call.
  mutable bool cached_valid_ = false;
  mutable std::vector<Override> cached_key_;
  mutable Barriers cached_;
  mutable std::vector<VkImageMemoryBarrier2> image_scratch_;
  mutable std::vector<VkBufferMemoryBarrier2> buffer_scratch_;
  mutable std::vector<VkRenderingAttachmentInfo> color_scratch_;
};

}  // namespace siviflow
