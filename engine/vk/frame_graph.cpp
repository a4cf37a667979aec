#include "vk/frame_graph.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>

#include "vk/device_table.h"
#include "vk/vk_text.h"

namespace siviflow {
namespace {

bool kind_allows(PassKind kind, Access access) {
  switch (access) {
    case Access::ColorAttachmentWrite:
    case Access::DepthAttachmentWrite:
    case Access::DepthAttachmentRead:
    case Access::SampledVertex:
    case Access::SampledFragment:
    case Access::StorageReadGraphics:
    case Access::VertexBufferRead:
    case Access::IndexBufferRead: return kind == PassKind::Graphics;
    case Access::SampledCompute:
    case Access::StorageReadCompute:
    case Access::StorageWriteCompute: return kind == PassKind::Compute;
    case Access::TransferRead:
    case Access::TransferWrite: return kind != PassKind::Graphics;  // not inside rendering
    case Access::UniformRead: return kind != PassKind::Transfer;
    default: return false;  // None and Host* only describe states at the graph's boundary
  }
}

const char* load_name(VkAttachmentLoadOp op) {
  switch (op) {
    case VK_ATTACHMENT_LOAD_OP_CLEAR: return "CLEAR";
    case VK_ATTACHMENT_LOAD_OP_LOAD: return "LOAD";
    default: return "DONT_CARE";
  }
}

const char* store_name(VkAttachmentStoreOp op) {
  switch (op) {
    case VK_ATTACHMENT_STORE_OP_STORE: return "STORE";
    case VK_ATTACHMENT_STORE_OP_NONE: return "NONE";
    default: return "DONT_CARE";
  }
}

VkAttachmentLoadOp vk_load_op(LoadOp load) {
  switch (load) {
    case LoadOp::Clear: return VK_ATTACHMENT_LOAD_OP_CLEAR;
    case LoadOp::DontCare: return VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    default: return VK_ATTACHMENT_LOAD_OP_LOAD;
  }
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string extent_text(VkExtent2D extent) {
  return std::to_string(extent.width) + "x" + std::to_string(extent.height);
}

}  // namespace

const char* pass_kind_name(PassKind kind) {
  switch (kind) {
    case PassKind::Transfer: return "transfer";
    case PassKind::Graphics: return "graphics";
    default: return "compute";
  }
}

// ---------------------------------------------------------------------------------------------
// Barrier bookkeeping

FrameGraph::Track FrameGraph::start_track(const ResourceState& incoming) {
  Track track;
  track.layout = incoming.layout;
  if (has_write_access(incoming.access)) {
    track.write_stage = incoming.stage;
    track.write_access = write_bits(incoming.access);
  } else {
    track.read_stages = incoming.stage;  // a read needs no barrier before another read
  }
  return track;
}

// Moves the track to `use`; returns true and fills *src when a barrier is needed first.
bool FrameGraph::advance(Track& track, const ResourceState& use, bool image, ResourceState* src) {
  const bool write = has_write_access(use.access);
  const bool relayout = image && use.layout != track.layout;
  bool needed = relayout;
  if (!relayout && write) needed = (track.write_stage | track.read_stages) != 0;
  if (!relayout && !write) {
    needed = track.write_stage != 0 && ((use.stage & ~track.visible_stages) != 0 ||
                                        (use.access & ~track.visible_access) != 0);
  }
  if (needed) {
    // Reads only need waiting on when the barrier writes (new data or a layout transition).
    src->stage = track.write_stage | ((write || relayout) ? track.read_stages : 0);
    src->access = track.write_access;
    src->layout = image ? track.layout : VK_IMAGE_LAYOUT_UNDEFINED;
  }
  if (write) {
    track.write_stage = use.stage;
    track.write_access = write_bits(use.access);
    track.read_stages = 0;
    track.visible_stages = 0;
    track.visible_access = 0;
  } else if (relayout) {
    // The transition is a write that later uses reach by chaining through this use's stage.
    track.write_stage = use.stage;
    track.write_access = 0;
    track.read_stages = use.stage;
    track.visible_stages = use.stage;
    track.visible_access = use.access;
  } else {
    track.read_stages |= use.stage;
    if (needed) {
      track.visible_stages |= use.stage;
      track.visible_access |= use.access;
    }
  }
  if (image) track.layout = use.layout;
  return needed;
}

// The hand-over to an outgoing state: whoever comes next only waits on out.stage, so every
// read not already in those stages must be chained into them, even when advance() needs no wait.
bool FrameGraph::finish(const Track& track, const ResourceState& out, bool image,
                        ResourceState* src) {
  Track next = track;
  bool needed = advance(next, out, image, src);
  if (out.stage != 0 && (track.read_stages & ~out.stage) != 0) needed = true;
  if (needed) {
    src->stage = track.write_stage | track.read_stages;
    src->access = track.write_access;
    src->layout = image ? track.layout : VK_IMAGE_LAYOUT_UNDEFINED;
  }
  return needed;
}

// ---------------------------------------------------------------------------------------------
// FrameBindings and PassContext

FrameBindings::Bound& FrameBindings::slot(uint32_t id) {
  if (id >= bound_.size()) bound_.resize(static_cast<size_t>(id) + 1);
  return bound_[id];
}

void FrameBindings::bind_image(ImageHandle image, VkImage vk_image, VkImageView view) {
  if (!image.valid()) return;
  slot(image.id).image = vk_image;
  slot(image.id).view = view;
}

void FrameBindings::bind_buffer(BufferHandle buffer, VkBuffer vk_buffer, VkDeviceSize offset) {
  if (!buffer.valid()) return;
  slot(buffer.id).buffer = vk_buffer;
  slot(buffer.id).offset = offset;
}

void FrameBindings::set_incoming(ImageHandle image, ResourceState state) {
  if (image.valid()) slot(image.id).incoming = state;
}
void FrameBindings::set_incoming(BufferHandle buffer, ResourceState state) {
  if (buffer.valid()) slot(buffer.id).incoming = state;
}
void FrameBindings::set_outgoing(ImageHandle image, ResourceState state) {
  if (image.valid()) slot(image.id).outgoing = state;
}
void FrameBindings::set_clear(ImageHandle image, VkClearValue clear) {
  if (image.valid()) slot(image.id).clear = clear;
}
void FrameBindings::set_render_area(ImageHandle image, VkRect2D area) {
  if (image.valid()) slot(image.id).render_area = area;
}
void FrameBindings::set_outgoing(BufferHandle buffer, ResourceState state) {
  if (buffer.valid()) slot(buffer.id).outgoing = state;
}

VkImage PassContext::image(ImageHandle image) const {
  const FrameBindings::Bound* bound = bindings_->find(image.id);
  return bound != nullptr ? bound->image : VK_NULL_HANDLE;
}
VkImageView PassContext::view(ImageHandle image) const {
  const FrameBindings::Bound* bound = bindings_->find(image.id);
  return bound != nullptr ? bound->view : VK_NULL_HANDLE;
}
VkExtent2D PassContext::extent(ImageHandle image) const {
  const ImageDesc* desc = graph_->image_desc(image);
  return desc != nullptr ? desc->extent : VkExtent2D{};
}
VkFormat PassContext::format(ImageHandle image) const {
  const ImageDesc* desc = graph_->image_desc(image);
  return desc != nullptr ? desc->format : VK_FORMAT_UNDEFINED;
}
VkImageLayout PassContext::layout(ImageHandle image) const {
  const FrameGraph::Use* use = graph_->find_use(pass_, image.id);
  return use != nullptr ? use->state.layout : VK_IMAGE_LAYOUT_UNDEFINED;
}
VkBuffer PassContext::buffer(BufferHandle buffer) const {
  const FrameBindings::Bound* bound = bindings_->find(buffer.id);
  return bound != nullptr ? bound->buffer : VK_NULL_HANDLE;
}
VkDeviceSize PassContext::offset(BufferHandle buffer) const {
  const FrameBindings::Bound* bound = bindings_->find(buffer.id);
  return bound != nullptr ? bound->offset : 0;
}
VkDeviceSize PassContext::size(BufferHandle buffer) const {
  const auto& resources = graph_->resources_;
  const bool known = buffer.id < resources.size() && !resources[buffer.id].is_image;
  return known ? resources[buffer.id].size : 0;
}

// ---------------------------------------------------------------------------------------------
// Declaration

// Each verb is one Access row; the row also says whether the use is an attachment.
template <typename Handle>
Handle PassBuilder::use(Handle handle, Access access, LoadOp load) {
  constexpr bool kImage = std::is_same_v<Handle, ImageHandle>;
  return {handle.id, graph_->add_use(pass_, handle.id, handle.version, kImage, access, load)};
}

ImageHandle PassBuilder::color_write(ImageHandle image, LoadOp load) {
  return use(image, Access::ColorAttachmentWrite, load);
}
ImageHandle PassBuilder::depth_write(ImageHandle image, LoadOp load) {
  return use(image, Access::DepthAttachmentWrite, load);
}
void PassBuilder::depth_read(ImageHandle image) { use(image, Access::DepthAttachmentRead); }
void PassBuilder::vertex_read(BufferHandle buffer) { use(buffer, Access::VertexBufferRead); }
void PassBuilder::index_read(BufferHandle buffer) { use(buffer, Access::IndexBufferRead); }
void PassBuilder::sampled(ImageHandle image, ShaderStage stage) {
  use(image, stage == ShaderStage::Vertex     ? Access::SampledVertex
             : stage == ShaderStage::Fragment ? Access::SampledFragment
                                              : Access::SampledCompute);
}
void PassBuilder::uniform_read(BufferHandle buffer) { use(buffer, Access::UniformRead); }
void PassBuilder::storage_read(ImageHandle image, ShaderStage stage) {
  use(image, stage == ShaderStage::Compute ? Access::StorageReadCompute
                                           : Access::StorageReadGraphics);
}
void PassBuilder::storage_read(BufferHandle buffer, ShaderStage stage) {
  use(buffer, stage == ShaderStage::Compute ? Access::StorageReadCompute
                                            : Access::StorageReadGraphics);
}
ImageHandle PassBuilder::storage_write(ImageHandle image) {
  return use(image, Access::StorageWriteCompute);
}
BufferHandle PassBuilder::storage_write(BufferHandle buffer) {
  return use(buffer, Access::StorageWriteCompute);
}
ImageHandle PassBuilder::transfer_write(ImageHandle image) {
  return use(image, Access::TransferWrite);
}
BufferHandle PassBuilder::transfer_write(BufferHandle buffer) {
  return use(buffer, Access::TransferWrite);
}
void PassBuilder::transfer_read(ImageHandle image) { use(image, Access::TransferRead); }
void PassBuilder::transfer_read(BufferHandle buffer) { use(buffer, Access::TransferRead); }
PassBuilder& PassBuilder::side_effect() {
  graph_->compiled_ = false;
  graph_->passes_[pass_].side_effect = true;
  return *this;
}
PassBuilder& PassBuilder::record(RecordFn fn) {
  graph_->passes_[pass_].record = std::move(fn);
  return *this;
}

uint32_t FrameGraph::add_resource(std::string name, bool is_image, Origin origin,
                                  ResourceState incoming, std::optional<ResourceState> outgoing) {
  compiled_ = false;
  Resource r;
  r.name = std::move(name);
  r.is_image = is_image;
  r.origin = origin;
  r.incoming = incoming;
  r.outgoing = outgoing;
  resources_.push_back(std::move(r));
  return static_cast<uint32_t>(resources_.size() - 1);
}

ImageHandle FrameGraph::add_image(ImageDesc desc, Origin origin, ResourceState incoming,
                                  std::optional<ResourceState> outgoing) {
  const uint32_t id = add_resource(desc.name, true, origin, incoming, outgoing);
  resources_[id].image = std::move(desc);
  return {id, 0};
}

BufferHandle FrameGraph::add_buffer(BufferDesc desc, Origin origin, ResourceState incoming,
                                    std::optional<ResourceState> outgoing) {
  const uint32_t id = add_resource(std::move(desc.name), false, origin, incoming, outgoing);
  resources_[id].size = desc.size;
  return {id, 0};
}

ImageHandle FrameGraph::create_image(ImageDesc desc) {
  return add_image(std::move(desc), Origin::Transient, {}, std::nullopt);
}
ImageHandle FrameGraph::create_persistent_image(ImageDesc desc) {
  return add_image(std::move(desc), Origin::Persistent, {}, std::nullopt);
}
ImageHandle FrameGraph::import_image(ImageDesc desc, ResourceState incoming,
                                     std::optional<ResourceState> outgoing) {
  return add_image(std::move(desc), Origin::Imported, incoming, outgoing);
}
BufferHandle FrameGraph::create_buffer(BufferDesc desc) {
  return add_buffer(std::move(desc), Origin::Transient, {}, std::nullopt);
}
BufferHandle FrameGraph::import_buffer(BufferDesc desc, ResourceState incoming,
                                       std::optional<ResourceState> outgoing) {
  return add_buffer(std::move(desc), Origin::Imported, incoming, outgoing);
}

PassBuilder FrameGraph::add_pass(std::string name, PassKind kind) {
  compiled_ = false;
  Pass pass;
  pass.name = std::move(name);
  pass.kind = kind;
  passes_.push_back(std::move(pass));
  return PassBuilder(this, static_cast<uint32_t>(passes_.size() - 1));
}

void FrameGraph::fail(std::string message) {
  if (error_.empty()) error_ = std::move(message);
}

const FrameGraph::Use* FrameGraph::find_use(uint32_t pass, uint32_t id) const {
  if (pass >= passes_.size()) return nullptr;
  for (const Use& use : passes_[pass].uses) {
    if (use.resource == id) return &use;
  }
  return nullptr;
}

// Records one verb; returns the version the caller's handle holds afterwards.
uint32_t FrameGraph::add_use(uint32_t p, uint32_t id, uint32_t version, bool image, Access access,
                             LoadOp load) {
  compiled_ = false;
  Pass& pass = passes_[p];
  const AccessInfo& info = access_info(access);
  const std::string where = "frame graph: pass '" + pass.name + "'";
  if (id >= resources_.size() || resources_[id].is_image != image) {
    fail(where + ": " + info.name + " of an invalid handle");
    return version;
  }
  Resource& r = resources_[id];
  const Role role = access == Access::ColorAttachmentWrite ? Role::Color
                    : access == Access::DepthAttachmentWrite || access == Access::DepthAttachmentRead
                        ? Role::Depth
                        : Role::Plain;
  if (!kind_allows(pass.kind, access)) {
    fail(where + " (" + pass_kind_name(pass.kind) + ") cannot use '" + r.name + "' as " +
         info.name);
    return version;
  }
  const uint32_t current = static_cast<uint32_t>(r.writers.size() - 1);
  if (version > current) {
    fail(where + ": '" + r.name + "' has no version " + std::to_string(version));
    return version;
  }
  if (role != Role::Plain) {
    const bool depth_format = (aspect_of(r.image.format) & VK_IMAGE_ASPECT_COLOR_BIT) == 0;
    if (depth_format != (role == Role::Depth)) {
      fail(where + ": the format of '" + r.name + "' (" + format_name(r.image.format) +
           ") does not fit " + info.name);
      return version;
    }
  }
  const VkImageLayout layout =
      image ? image_layout(access, r.image.format) : VK_IMAGE_LAYOUT_UNDEFINED;
  const bool writes = has_write_access(info.access);
  bool reads = !writes;  // plain writes (transfer, storage) overwrite what they touch
  if (role != Role::Plain && writes) {
    if (load == LoadOp::Auto) {
      load = (version == 0 && r.origin == Origin::Transient) ? LoadOp::Clear : LoadOp::Load;
    }
    reads = load == LoadOp::Load;
  }

  // A second verb on the same resource in the same pass joins the first use.
  for (Use& use : pass.uses) {
    if (use.resource != id) {
      if (role == Role::Depth && use.role == Role::Depth) {
        fail(where + " has two depth attachments");
        return version;
      }
      continue;
    }
    if (image && use.state.layout != layout) {
      fail(where + " uses '" + r.name + "' as " + use.verbs + " and " + info.name +
           ", which need different layouts (" + layout_text(use.state.layout) + " and " +
           layout_text(layout) + ")");
      return version;
    }
    if (use.version != version || (writes && use.writes)) {
      fail(where + " writes '" + r.name + "' twice or uses two of its versions");
      return version;
    }
    use.state.stage |= info.stage;
    use.state.access |= info.access;
    use.image_usage |= info.image_usage;
    use.buffer_usage |= info.buffer_usage;
    use.reads = use.reads || reads;
    use.verbs += std::string("+") + info.name;
    if (role != Role::Plain) {
      use.role = role;
      use.load = load;
    }
    if (!writes) return version;
    use.writes = true;
    r.writers.push_back(p);
    return version + 1;
  }

  // Versions make ordering explicit: only the newest version may be read or written.
  if (version < current) {
    const std::string& newer = passes_[r.writers[version + 1]].name;
    const std::string v = std::to_string(version);
    if (writes) {
      fail("frame graph: passes '" + newer + "' and '" + pass.name + "' both write version " + v +
           " of '" + r.name + "' (two writers in an undefined order); '" + pass.name +
           "' must use the handle '" + newer + "' returned");
    } else {
      fail(where + " reads version " + v + " of '" + r.name + "' after pass '" + newer +
           "' wrote version " + std::to_string(version + 1) +
           "; read the newer handle or declare '" + pass.name + "' first");
    }
    return version;
  }

  Use use;
  use.resource = id;
  use.version = version;
  use.reads = reads;
  use.writes = writes;
  use.role = role;
  use.load = load;
  use.state = {info.stage, info.access, layout};
  use.image_usage = info.image_usage;
  use.buffer_usage = info.buffer_usage;
  use.verbs = info.name;
  pass.uses.push_back(std::move(use));
  if (!writes) return version;
  r.writers.push_back(p);
  return version + 1;
}

// ---------------------------------------------------------------------------------------------
// Compile

Status FrameGraph::compile() {
  compiled_ = false;
  cached_valid_ = false;
  steps_.clear();
  starts_.clear();
  barriers_ = Barriers{};

  // 1. Validate: declaration errors first (they name both passes), then whole-graph rules.
  if (!error_.empty()) return Status::error(error_);
  for (uint32_t i = 0; i < resources_.size(); ++i) {
    if (resources_[i].outgoing) SIVIFLOW_TRY(check_outgoing(i, *resources_[i].outgoing));
  }
  for (const Pass& pass : passes_) {
    const std::string where = "frame graph: pass '" + pass.name + "'";
    for (const Use& use : pass.uses) {
      const Resource& r = resources_[use.resource];
      if (use.reads && use.version == 0 && r.origin == Origin::Transient) {
        return Status::error(where + " reads '" + r.name + "' (" + use.verbs +
                             "), which no earlier pass writes and which is not imported");
      }
    }
    if (pass.kind != PassKind::Graphics) continue;
    const Resource* first = nullptr;
    for (const Use& use : pass.uses) {
      if (use.role == Role::Plain) continue;
      const Resource& r = resources_[use.resource];
      if (first == nullptr) {
        first = &r;
      } else if (r.image.extent.width != first->image.extent.width ||
                 r.image.extent.height != first->image.extent.height) {
        return Status::error(where + ": attachments '" + first->name + "' (" +
                             extent_text(first->image.extent) + ") and '" + r.name + "' (" +
                             extent_text(r.image.extent) + ") differ in extent");
      }
    }
    if (first == nullptr) return Status::error(where + " is graphics but has no attachment");
  }

  // 2. Cull: keep side effects and the last writers of outputs, then walk back through reads.
  //    Declaration order is topological, so one backward sweep reaches every producer.
  for (Pass& pass : passes_) pass.alive = pass.side_effect;
  for (const Resource& r : resources_) {
    const bool output = r.outgoing.has_value() || r.origin == Origin::Persistent;
    if (output && r.writers.back() != kNoPass) passes_[r.writers.back()].alive = true;
  }
  for (size_t p = passes_.size(); p-- > 0;) {
    if (!passes_[p].alive) continue;
    for (const Use& use : passes_[p].uses) {
      const uint32_t writer = resources_[use.resource].writers[use.version];
      if (use.reads && writer != kNoPass) passes_[writer].alive = true;
    }
  }

  // 3. Order: declaration order, which the versioning rules already made a valid topological
  //    order (a pass can only name versions earlier passes produced). Nothing is reordered.

  // 4. Usage flags and liveness, from the surviving passes only.
  std::vector<std::vector<bool>> read_later(resources_.size());
  for (size_t i = 0; i < resources_.size(); ++i) {
    resources_[i].image_usage = 0;
    resources_[i].buffer_usage = 0;
    resources_[i].live = false;
    read_later[i].assign(resources_[i].writers.size(), false);
  }
  for (const Pass& pass : passes_) {
    if (!pass.alive) continue;
    for (const Use& use : pass.uses) {
      Resource& r = resources_[use.resource];
      r.image_usage |= use.image_usage;
      r.buffer_usage |= use.buffer_usage;
      r.live = true;
      if (use.reads) read_later[use.resource][use.version] = true;
    }
  }

  // 5. Attachments: load ops as declared (or resolved from Auto); store only what someone
  //    reads later, or what outlives the frame (imported and persistent images).
  for (uint32_t p = 0; p < passes_.size(); ++p) {
    if (!passes_[p].alive) continue;
    Step step;
    step.pass = p;
    for (const Use& use : passes_[p].uses) {
      if (use.role == Role::Plain) continue;
      const Resource& r = resources_[use.resource];
      Attachment attachment;
      attachment.resource = use.resource;
      attachment.load = vk_load_op(use.load);
      attachment.layout = use.state.layout;
      if (!use.writes) {
        attachment.store = VK_ATTACHMENT_STORE_OP_NONE;
      } else if (!read_later[use.resource][use.version + 1] && r.origin == Origin::Transient) {
        attachment.store = VK_ATTACHMENT_STORE_OP_DONT_CARE;
      }
      step.extent = r.image.extent;
      if (use.role == Role::Color) {
        step.colors.push_back(attachment);
      } else {
        step.depth = attachment;
      }
    }
    steps_.push_back(std::move(step));
  }

  // 6. Barriers. Imports start where the host said; graph-owned resources where the previous
  //    frame left them (transients in undefined layout), found by running frames until the
  //    carried state repeats (within three runs: only the first use depends on the start).
  starts_.resize(resources_.size());
  for (size_t i = 0; i < resources_.size(); ++i) {
    const Resource& r = resources_[i];
    starts_[i] = r.origin == Origin::Imported ? start_track(r.incoming) : Track{};
  }
  std::vector<Track> ends;
  constexpr int kMaxRuns = 8;
  for (int run = 0;; ++run) {
    derive_barriers(starts_, {}, barriers_, &ends);
    bool settled = true;
    for (size_t i = 0; i < resources_.size(); ++i) {
      const Resource& r = resources_[i];
      if (r.origin == Origin::Imported) continue;
      Track carried = ends[i];
      if (r.origin == Origin::Transient) carried.layout = VK_IMAGE_LAYOUT_UNDEFINED;
      if (carried == starts_[i]) continue;
      starts_[i] = carried;
      settled = false;
    }
    if (settled) break;
    if (run + 1 == kMaxRuns) {
      barriers_ = Barriers{};
      return Status::error("frame graph: internal error: the state carried between frames does "
                           "not settle");
    }
  }
  compiled_ = true;
  return Status();
}

Status FrameGraph::check_outgoing(uint32_t resource, const ResourceState& outgoing) const {
  const Resource& r = resources_[resource];
  if (!r.is_image || (outgoing.layout != VK_IMAGE_LAYOUT_UNDEFINED &&
                      outgoing.layout != VK_IMAGE_LAYOUT_PREINITIALIZED)) {
    return Status();
  }
  // VUID-VkImageMemoryBarrier2-newLayout-01198: a barrier cannot transition to these layouts.
  return Status::error("frame graph: the outgoing state of '" + r.name + "' has layout " +
                       layout_text(outgoing.layout) +
                       ", which no barrier may transition to; state the layout its next user "
                       "needs");
}

void FrameGraph::derive_barriers(const std::vector<Track>& starts,
                                 const std::vector<Override>& overrides, Barriers& out,
                                 std::vector<Track>* ends) const {
  std::vector<Track> tracks = starts;
  for (size_t i = 0; i < overrides.size(); ++i) {
    if (overrides[i].incoming) tracks[i] = start_track(*overrides[i].incoming);
  }
  out.steps.resize(steps_.size());
  for (size_t s = 0; s < steps_.size(); ++s) {
    std::vector<Barrier>& barriers = out.steps[s];
    barriers.clear();
    for (const Use& use : passes_[steps_[s].pass].uses) {
      Barrier barrier{use.resource, {}, use.state};
      if (advance(tracks[use.resource], use.state, resources_[use.resource].is_image,
                  &barrier.src)) {
        barriers.push_back(barrier);
      }
    }
  }
  out.final.clear();
  for (uint32_t i = 0; i < resources_.size(); ++i) {
    const std::optional<ResourceState>& outgoing =
        i < overrides.size() && overrides[i].outgoing ? overrides[i].outgoing
                                                      : resources_[i].outgoing;
    if (!outgoing) continue;
    const bool image = resources_[i].is_image;
    Barrier barrier{i, {}, *outgoing};
    if (!image) barrier.dst.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (finish(tracks[i], barrier.dst, image, &barrier.src)) out.final.push_back(barrier);
  }
  if (ends != nullptr) *ends = std::move(tracks);
}

// ---------------------------------------------------------------------------------------------
// Execute

void FrameGraph::emit_barriers(const DeviceTable& table, VkCommandBuffer cmd,
                               const FrameBindings& bindings,
                               const std::vector<Barrier>& barriers) const {
  std::vector<VkImageMemoryBarrier2>& images = image_scratch_;
  std::vector<VkBufferMemoryBarrier2>& buffers = buffer_scratch_;
  images.clear();
  buffers.clear();
  for (const Barrier& b : barriers) {
    const Resource& r = resources_[b.resource];
    const FrameBindings::Bound* bound = bindings.find(b.resource);  // checked by execute()
    if (r.is_image) {
      VkImageMemoryBarrier2 m{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
      m.srcStageMask = b.src.stage;
      m.srcAccessMask = b.src.access;
      m.dstStageMask = b.dst.stage;
      m.dstAccessMask = b.dst.access;
      m.oldLayout = b.src.layout;
      m.newLayout = b.dst.layout;
      m.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.image = bound->image;
      m.subresourceRange = {aspect_of(r.image.format), 0, VK_REMAINING_MIP_LEVELS, 0,
                            VK_REMAINING_ARRAY_LAYERS};
      images.push_back(m);
    } else {
      VkBufferMemoryBarrier2 m{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
      m.srcStageMask = b.src.stage;
      m.srcAccessMask = b.src.access;
      m.dstStageMask = b.dst.stage;
      m.dstAccessMask = b.dst.access;
      m.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      m.buffer = bound->buffer;
      m.offset = bound->offset;
      m.size = r.size != 0 ? r.size : VK_WHOLE_SIZE;
      buffers.push_back(m);
    }
  }
  if (images.empty() && buffers.empty()) return;
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.bufferMemoryBarrierCount = static_cast<uint32_t>(buffers.size());
  dependency.pBufferMemoryBarriers = buffers.data();
  dependency.imageMemoryBarrierCount = static_cast<uint32_t>(images.size());
  dependency.pImageMemoryBarriers = images.data();
  table.vkCmdPipelineBarrier2(cmd, &dependency);
}

Status FrameGraph::execute(const DeviceTable& table, VkCommandBuffer cmd,
                           const FrameBindings& bindings, const Timestamps* timestamps) const {
  if (!compiled_) return Status::error("frame graph: execute() needs a successful compile()");
  if (cmd == VK_NULL_HANDLE || table.vkCmdPipelineBarrier2 == nullptr ||
      table.vkCmdBeginRendering == nullptr || table.vkCmdEndRendering == nullptr) {
    return Status::error("frame graph: execute() needs a command buffer and a loaded table");
  }

  Status state_status;
  const Barriers* barriers = barriers_for(bindings, &state_status);
  if (barriers == nullptr) return state_status;

  for (uint32_t id = 0; id < data_names_.size(); ++id) {
    if (bindings.find_data(id) == nullptr) {
      return Status::error("frame graph: the frame's '" + data_names_[id] + "' is not bound");
    }
  }
  // Every handle is checked before the first command, so a binding error records nothing.
  auto check_bound = [&](uint32_t id, const Pass* pass, bool need_view) -> Status {
    const Resource& r = resources_[id];
    const FrameBindings::Bound* bound = bindings.find(id);
    const bool ok = bound != nullptr &&
                    (r.is_image ? bound->image != VK_NULL_HANDLE &&
                                      (!need_view || bound->view != VK_NULL_HANDLE)
                                : bound->buffer != VK_NULL_HANDLE);
    if (ok) return Status();
    const std::string what = pass != nullptr
                                 ? "pass '" + pass->name + "' uses '" + r.name + "', which"
                                 : "'" + r.name + "' (transitioned to its outgoing state)";
    return Status::error("frame graph: " + what + " is not bound" +
                         (need_view ? " (an attachment needs a VkImageView)" : ""));
  };
  for (const Step& step : steps_) {
    const Pass& pass = passes_[step.pass];
    for (const Use& use : pass.uses) {
      SIVIFLOW_TRY(check_bound(use.resource, &pass, use.role != Role::Plain));
    }
  }
  for (const Barrier& barrier : barriers->final) {
    SIVIFLOW_TRY(check_bound(barrier.resource, nullptr, false));
  }

  const bool labels = table.has_debug_labels() && table.vkCmdEndDebugUtilsLabelEXT != nullptr;
  for (size_t s = 0; s < steps_.size(); ++s) {
    const Step& step = steps_[s];
    const Pass& pass = passes_[step.pass];
    if (labels) {
      VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
      label.pLabelName = pass.name.c_str();
      table.vkCmdBeginDebugUtilsLabelEXT(cmd, &label);
    }
    emit_barriers(table, cmd, bindings, barriers->steps[s]);
    // After the pass's barriers, so the time is the pass's own, not its wait for earlier ones.
    if (timestamps != nullptr) {
      table.vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps->pool,
                                 timestamps->first_query + 2 * static_cast<uint32_t>(s));
    }
    if (pass.kind == PassKind::Graphics) {
      auto attachment_info = [&](const Attachment& a) {
        VkRenderingAttachmentInfo info{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        info.imageView = bindings.find(a.resource)->view;
        info.imageLayout = a.layout;
        info.loadOp = a.load;
        info.storeOp = a.store;
        const FrameBindings::Bound* bound = bindings.find(a.resource);
        info.clearValue = bound != nullptr && bound->clear ? *bound->clear
                                                           : resources_[a.resource].image.clear;
        return info;
      };
      std::vector<VkRenderingAttachmentInfo>& colors = color_scratch_;
      colors.clear();
      for (const Attachment& a : step.colors) colors.push_back(attachment_info(a));
      VkRenderingAttachmentInfo depth{};
      if (step.depth) depth = attachment_info(*step.depth);
      VkRect2D area{{0, 0}, step.extent};
      const auto take_area = [&](const Attachment& a) {
        const FrameBindings::Bound* bound = bindings.find(a.resource);
        if (bound != nullptr && bound->render_area) area = *bound->render_area;
      };
      if (step.depth) take_area(*step.depth);  // a depth-only pass has no colour to take it from
      for (const Attachment& a : step.colors) take_area(a);
      // An image of the graph's own lies at the origin, its declared size: the area stays on it.
      const auto clip_area = [&](const Attachment& a) {
        const Resource& r = resources_[a.resource];
        if (r.origin == Origin::Imported) return;
        const int64_t right = std::min<int64_t>(int64_t{area.offset.x} + area.extent.width,
                                                r.image.extent.width);
        const int64_t bottom = std::min<int64_t>(int64_t{area.offset.y} + area.extent.height,
                                                 r.image.extent.height);
        area.extent = {static_cast<uint32_t>(std::max<int64_t>(right - area.offset.x, 0)),
                       static_cast<uint32_t>(std::max<int64_t>(bottom - area.offset.y, 0))};
      };
      if (step.depth) clip_area(*step.depth);
      for (const Attachment& a : step.colors) clip_area(a);
      VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
      rendering.renderArea = area;
      rendering.layerCount = 1;
      rendering.colorAttachmentCount = static_cast<uint32_t>(colors.size());
      rendering.pColorAttachments = colors.data();
      rendering.pDepthAttachment = step.depth ? &depth : nullptr;
      table.vkCmdBeginRendering(cmd, &rendering);
    }
    const Status status =
        pass.record ? pass.record(PassContext(*this, bindings, table, cmd, step.pass)) : Status();
    if (pass.kind == PassKind::Graphics) table.vkCmdEndRendering(cmd);
    if (timestamps != nullptr) {
      table.vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timestamps->pool,
                                 timestamps->first_query + 2 * static_cast<uint32_t>(s) + 1);
    }
    if (labels) table.vkCmdEndDebugUtilsLabelEXT(cmd);
    if (!status.ok()) {
      return Status::error("frame graph: pass '" + pass.name + "': " + status.message(),
                           status.code());
    }
  }
  emit_barriers(table, cmd, bindings, barriers->final);
  return Status();
}

// The declared states' barriers when nothing is overridden; otherwise those of the override set,
// derived again only when it differs from the previous execute's. Null (and *status) on error.
const FrameGraph::Barriers* FrameGraph::barriers_for(const FrameBindings& bindings,
                                                     Status* status) const {
  bool any = false;
  bool same = cached_valid_;
  for (uint32_t i = 0; i < resources_.size(); ++i) {
    const Resource& r = resources_[i];
    const FrameBindings::Bound* bound = bindings.find(i);
    const bool in = bound != nullptr && bound->incoming.has_value();
    const bool out = bound != nullptr && bound->outgoing.has_value();
    if ((in && r.origin == Origin::Transient) || (out && r.origin != Origin::Imported)) {
      *status = Status::error("frame graph: '" + r.name +
                              "' takes no per-execute state (only imports, and persistent images "
                              "for their incoming state)");
      return nullptr;
    }
    if (out) {
      *status = check_outgoing(i, *bound->outgoing);
      if (!status->ok()) return nullptr;
    }
    any = any || in || out;
    if (same) {
      same = bound != nullptr ? cached_key_[i] == Override{bound->incoming, bound->outgoing}
                              : cached_key_[i] == Override{};
    }
  }
  if (!any) return &barriers_;
  if (same) return &cached_;
  cached_key_.assign(resources_.size(), Override{});
  for (uint32_t i = 0; i < resources_.size(); ++i) {
    const FrameBindings::Bound* bound = bindings.find(i);
    if (bound != nullptr) cached_key_[i] = {bound->incoming, bound->outgoing};
  }
  derive_barriers(starts_, cached_key_, cached_, nullptr);
  cached_valid_ = true;
  return &cached_;
}

// ---------------------------------------------------------------------------------------------
// Queries and dumps

VkImageUsageFlags FrameGraph::image_usage(ImageHandle image) const {
  const ImageDesc* desc = image_desc(image);
  return desc != nullptr ? resources_[image.id].image_usage : 0;
}

VkBufferUsageFlags FrameGraph::buffer_usage(BufferHandle buffer) const {
  const bool known = buffer.id < resources_.size() && !resources_[buffer.id].is_image;
  return known ? resources_[buffer.id].buffer_usage : 0;
}

const ImageDesc* FrameGraph::image_desc(ImageHandle image) const {
  const bool known = image.id < resources_.size() && resources_[image.id].is_image;
  return known ? &resources_[image.id].image : nullptr;
}

std::vector<std::string> FrameGraph::pass_order() const {
  std::vector<std::string> order;
  for (const Step& step : steps_) order.push_back(passes_[step.pass].name);
  return order;
}

bool FrameGraph::culled(const std::string& pass) const {
  for (const Pass& each : passes_) {
    if (each.name == pass) return compiled_ && !each.alive;
  }
  return false;
}

std::string FrameGraph::barrier_line(const Barrier& b) const {
  const Resource& r = resources_[b.resource];
  std::string line = "barrier " + r.name + ": ";
  if (r.is_image) line += layout_name(b.src.layout) + " -> " + layout_name(b.dst.layout) + ", ";
  return line + stage_flags_name(b.src.stage) + ":" + access_flags_name(b.src.access) + " -> " +
         stage_flags_name(b.dst.stage) + ":" + access_flags_name(b.dst.access);
}

std::string FrameGraph::dump_text() const {
  if (!compiled_) return "not compiled\n";
  std::string out;
  size_t next = 0;  // steps_ holds the surviving passes in declaration order
  for (const Pass& pass : passes_) {
    const std::string kind = pass_kind_name(pass.kind);
    if (!pass.alive) {
      out += "culled " + pass.name + " (" + kind + ")\n";
      continue;
    }
    const std::vector<Barrier>& barriers = barriers_.steps[next];
    const Step& step = steps_[next++];
    out += "pass " + pass.name + " (" + kind + ")\n";
    for (const Barrier& barrier : barriers) out += "  " + barrier_line(barrier) + "\n";
    auto attachment_line = [&](const char* what, const Attachment& a) {
      out += std::string("  ") + what + " " + resources_[a.resource].name + ": load " +
             load_name(a.load) + ", store " + store_name(a.store) + "\n";
    };
    for (const Attachment& a : step.colors) attachment_line("color", a);
    if (step.depth) attachment_line("depth", *step.depth);
  }
  out += "final\n";
  for (const Barrier& barrier : barriers_.final) out += "  " + barrier_line(barrier) + "\n";
  return out;
}

std::string FrameGraph::dump_graphviz() const {
  std::string out = "digraph frame_graph {\n  rankdir=LR;\n";
  for (uint32_t i = 0; i < resources_.size(); ++i) {
    const Resource& r = resources_[i];
    // Version 0 of a transient holds nothing, so it is not drawn.
    for (uint32_t v = r.origin == Origin::Transient ? 1 : 0; v < r.writers.size(); ++v) {
      out += "  r" + std::to_string(i) + "v" + std::to_string(v) + " [shape=ellipse" +
             (r.origin == Origin::Imported ? ", peripheries=2" : "") +
             ", label=" + quoted(r.name + " v" + std::to_string(v)) + "];\n";
    }
  }
  for (uint32_t p = 0; p < passes_.size(); ++p) {
    const Pass& pass = passes_[p];
    const bool culled_pass = compiled_ && !pass.alive;
    const std::string node = "p" + std::to_string(p);
    out += "  " + node + " [shape=box" + (culled_pass ? ", style=dashed" : "") + ", label=" +
           quoted(pass.name + " (" + pass_kind_name(pass.kind) + (culled_pass ? ", culled)" : ")")) +
           "];\n";
    for (const Use& use : pass.uses) {
      const std::string r = "r" + std::to_string(use.resource) + "v";
      if (use.reads) {
        out += "  " + r + std::to_string(use.version) + " -> " + node +
               " [label=" + quoted(use.verbs) + "];\n";
      }
      if (use.writes) {
        out += "  " + node + " -> " + r + std::to_string(use.version + 1) +
               " [label=" + quoted(use.verbs) + "];\n";
      }
    }
  }
  return out + "}\n";
}

}  // namespace siviflow
