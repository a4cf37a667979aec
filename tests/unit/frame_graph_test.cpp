// Frame graph and Access table, on the CPU: compile results are asserted through the text dump,
// and execute() is run against a fake device table that records the commands it receives.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "vk/access.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"

// Every allocation of the test binary is counted, so a test can assert that a call allocates
// nothing (the replaceable global operator new; the array and nothrow forms call this one).
namespace {
std::atomic<uint64_t> g_allocations{0};
}  // namespace
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
// GCC at -O1 inlines these into callers beside the replaced operator new and takes the pair for
// new and free; both sides are this file's malloc and free.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace siviflow {
namespace {

constexpr VkExtent2D kExtent{64, 32};

struct River {
  ImageHandle flow, color, depth, debug_view;
  BufferHandle staging, readback;
};

// The lead's graph: upload -> scene -> readback, plus a debug pass whose output nobody reads.
River declare_river(FrameGraph& graph, std::vector<std::string>* calls = nullptr) {
  River h;
  h.staging = graph.import_buffer({"staging", 4096}, state_of(Access::None));
  h.readback = graph.import_buffer({"readback", 8192}, state_of(Access::None),
                                   state_of(Access::HostRead));
  h.flow = graph.create_image({"flow", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  VkClearValue sky{};
  sky.color = {{0.25f, 0.5f, 0.75f, 1.0f}};
  h.color = graph.create_image({"color", VK_FORMAT_R16G16B16A16_SFLOAT, kExtent, sky});
  h.depth = graph.create_image({"depth", VK_FORMAT_D32_SFLOAT, kExtent, {}});
  h.debug_view = graph.create_image({"debug_view", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  auto log = [calls](const char* name) {
    return [calls, name](const PassContext&) {
      if (calls != nullptr) calls->push_back(std::string("record ") + name);
      return Status();
    };
  };

  PassBuilder upload = graph.add_pass("upload", PassKind::Transfer);
  upload.transfer_read(h.staging);
  h.flow = upload.transfer_write(h.flow);
  upload.record(log("upload"));

  PassBuilder scene = graph.add_pass("scene", PassKind::Graphics);
  scene.sampled_fragment(h.flow);
  h.color = scene.color_write(h.color);
  h.depth = scene.depth_write(h.depth);
  scene.record(log("scene"));

  PassBuilder debug = graph.add_pass("debug", PassKind::Graphics);
  debug.sampled_fragment(h.flow);
  h.debug_view = debug.color_write(h.debug_view);
  debug.record(log("debug"));

  PassBuilder readback = graph.add_pass("readback", PassKind::Transfer);
  readback.transfer_read(h.color);
  h.readback = readback.transfer_write(h.readback);
  readback.side_effect().record(log("readback"));
  return h;
}

TEST(AccessTable, RowsMatchTheirEnumAndSync2Values) {
  for (std::size_t i = 0; i < kAccessCount; ++i) {
    const AccessInfo& row = access_info(static_cast<Access>(i));
    EXPECT_EQ(static_cast<std::size_t>(row.id), i);
    EXPECT_NE(std::string(row.name), "");
  }
  const AccessInfo& sampled = access_info(Access::SampledFragment);
  EXPECT_EQ(sampled.stage, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
  EXPECT_EQ(sampled.access, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
  EXPECT_EQ(sampled.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_EQ(sampled.image_usage, VkImageUsageFlags{VK_IMAGE_USAGE_SAMPLED_BIT});
  EXPECT_EQ(access_info(Access::DepthAttachmentRead).layout,
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
  EXPECT_EQ(access_info(Access::VertexBufferRead).buffer_usage,
            VkBufferUsageFlags{VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
  EXPECT_TRUE(is_write(Access::TransferWrite));
  EXPECT_TRUE(is_write(Access::ColorAttachmentWrite));
  EXPECT_FALSE(is_write(Access::TransferRead));
  EXPECT_FALSE(is_write(Access::DepthAttachmentRead));
  EXPECT_EQ(state_of(Access::HostRead),
            (ResourceState{VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT,
                           VK_IMAGE_LAYOUT_UNDEFINED}));
}

TEST(AccessTable, DepthFormatsAreSampledInTheDepthReadOnlyLayout) {
  EXPECT_EQ(image_layout(Access::SampledFragment, VK_FORMAT_D32_SFLOAT),
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
  EXPECT_EQ(image_layout(Access::SampledCompute, VK_FORMAT_D24_UNORM_S8_UINT),
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
  EXPECT_EQ(image_layout(Access::DepthAttachmentRead, VK_FORMAT_D32_SFLOAT),
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
  EXPECT_EQ(image_layout(Access::SampledFragment, VK_FORMAT_R8G8B8A8_UNORM),
            VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  EXPECT_EQ(image_layout(Access::TransferRead, VK_FORMAT_D32_SFLOAT),
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

TEST(AccessTable, NamesAreStable) {
  EXPECT_EQ(access_name(Access::StorageWriteCompute), std::string("StorageWriteCompute"));
  EXPECT_EQ(stage_flags_name(0), "NONE");
  EXPECT_EQ(stage_flags_name(access_info(Access::DepthAttachmentWrite).stage),
            "EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS");
  EXPECT_EQ(stage_flags_name(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT), "TRANSFER");
  EXPECT_EQ(access_flags_name(VK_ACCESS_2_TRANSFER_WRITE_BIT | (1ull << 60)),
            "TRANSFER_WRITE|0x1000000000000000");
  EXPECT_EQ(layout_name(VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL), "TRANSFER_DST_OPTIMAL");
  // The dumps' own order and set of names, not vk_text's ascending full set.
  EXPECT_EQ(stage_flags_name(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT |
                             VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT |
                             VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT),
            "TRANSFER|COMPUTE_SHADER|0x40");
  EXPECT_EQ(access_flags_name(VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT),
            "MEMORY_WRITE|SHADER_READ");
  EXPECT_EQ(layout_name(VK_IMAGE_LAYOUT_PRESENT_SRC_KHR), "PRESENT_SRC_KHR");
  EXPECT_EQ(layout_name(VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL), "LAYOUT_1000241000");
}

TEST(FrameGraphCompile, ExactBarrierListingOfUploadSceneReadback) {
  FrameGraph graph;
  declare_river(graph);
  ASSERT_TRUE(graph.compile().ok());
  const std::string expected =
      "pass upload (transfer)\n"
      "  barrier flow: UNDEFINED -> TRANSFER_DST_OPTIMAL, FRAGMENT_SHADER:NONE -> "
      "TRANSFER:TRANSFER_WRITE\n"
      "pass scene (graphics)\n"
      "  barrier flow: TRANSFER_DST_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL, TRANSFER:TRANSFER_WRITE"
      " -> FRAGMENT_SHADER:SHADER_SAMPLED_READ\n"
      "  barrier color: UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL, TRANSFER:NONE -> "
      "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_READ|COLOR_ATTACHMENT_WRITE\n"
      "  barrier depth: UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL, "
      "EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS:DEPTH_STENCIL_ATTACHMENT_WRITE -> "
      "EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS:"
      "DEPTH_STENCIL_ATTACHMENT_READ|DEPTH_STENCIL_ATTACHMENT_WRITE\n"
      "  color color: load CLEAR, store STORE\n"
      "  depth depth: load CLEAR, store DONT_CARE\n"
      "culled debug (graphics)\n"
      "pass readback (transfer)\n"
      "  barrier color: COLOR_ATTACHMENT_OPTIMAL -> TRANSFER_SRC_OPTIMAL, "
      "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_WRITE -> TRANSFER:TRANSFER_READ\n"
      "final\n"
      "  barrier readback: TRANSFER:TRANSFER_WRITE -> HOST:HOST_READ\n";
  EXPECT_EQ(graph.dump_text(), expected);
  const std::string dot = graph.dump_graphviz();
  EXPECT_NE(dot.find("label=\"debug (graphics, culled)\""), std::string::npos) << dot;
  EXPECT_NE(dot.find("p1 -> r3v1 [label=\"ColorAttachmentWrite\"]"), std::string::npos) << dot;
}

TEST(FrameGraphCompile, KeepsDeclarationOrderAndCullsPassesReachingNoOutput) {
  FrameGraph graph;
  declare_river(graph);
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_EQ(graph.pass_order(), (std::vector<std::string>{"upload", "scene", "readback"}));
  EXPECT_TRUE(graph.culled("debug"));
  EXPECT_FALSE(graph.culled("scene"));
}

TEST(FrameGraphCompile, SideEffectKeepsAPassAndEverythingItReads) {
  FrameGraph graph;
  ImageHandle a = graph.create_image({"a", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  ImageHandle b = graph.create_image({"b", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  PassBuilder make = graph.add_pass("make", PassKind::Graphics);
  a = make.color_write(a);
  PassBuilder unread = graph.add_pass("unread", PassKind::Graphics);
  b = unread.color_write(b);
  PassBuilder probe = graph.add_pass("probe", PassKind::Compute);
  probe.sampled(a, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_TRUE(graph.pass_order().empty());  // no output, no side effect: everything goes

  probe.side_effect();
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_EQ(graph.pass_order(), (std::vector<std::string>{"make", "probe"}));
  EXPECT_TRUE(graph.culled("unread"));
}

TEST(FrameGraphCompile, DerivesUsageFlagsFromTheVerbsOfSurvivingPasses) {
  FrameGraph graph;
  const River h = declare_river(graph);
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_EQ(graph.image_usage(h.flow),
            VkImageUsageFlags{VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT});
  EXPECT_EQ(graph.image_usage(h.color), VkImageUsageFlags{VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  EXPECT_EQ(graph.image_usage(h.depth),
            VkImageUsageFlags{VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
  EXPECT_EQ(graph.image_usage(h.debug_view), 0u);  // only the culled pass uses it
  EXPECT_EQ(graph.buffer_usage(h.staging), VkBufferUsageFlags{VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
  EXPECT_EQ(graph.buffer_usage(h.readback), VkBufferUsageFlags{VK_BUFFER_USAGE_TRANSFER_DST_BIT});
}

TEST(FrameGraphCompile, ImportsAreTransitionedInFromAndOutToTheHostStates) {
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  ImageHandle out = graph.import_image({"host_out", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}},
                                       host_sampled, host_sampled);
  PassBuilder flow = graph.add_pass("flow", PassKind::Graphics);
  out = flow.color_write(out);  // Auto on an import: keep the host's pixels
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_EQ(graph.dump_text(),
            "pass flow (graphics)\n"
            "  barrier host_out: SHADER_READ_ONLY_OPTIMAL -> COLOR_ATTACHMENT_OPTIMAL, "
            "FRAGMENT_SHADER:NONE -> "
            "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_READ|COLOR_ATTACHMENT_WRITE\n"
            "  color host_out: load LOAD, store STORE\n"
            "final\n"
            "  barrier host_out: COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL, "
            "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_WRITE -> "
            "FRAGMENT_SHADER:SHADER_SAMPLED_READ\n");
}

TEST(FrameGraphCompile, NoBarrierForReadAfterReadInTheSameLayout) {
  FrameGraph graph;
  ImageHandle tex = graph.create_image({"tex", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  PassBuilder fill = graph.add_pass("fill", PassKind::Transfer);
  tex = fill.transfer_write(tex);
  const char* names[] = {"read1", "read2"};
  for (const char* name : names) graph.add_pass(name, PassKind::Compute).side_effect().sampled(tex, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());
  const std::string dump = graph.dump_text();
  EXPECT_NE(dump.find("pass read1 (compute)\n  barrier tex: TRANSFER_DST_OPTIMAL -> "
                      "SHADER_READ_ONLY_OPTIMAL"),
            std::string::npos)
      << dump;
  EXPECT_NE(dump.find("pass read2 (compute)\nfinal\n"), std::string::npos) << dump;
}

TEST(FrameGraphErrors, ReadWithoutWriterNamesPassAndResource) {
  FrameGraph graph;
  ImageHandle never = graph.create_image({"never_written", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  graph.add_pass("consumer", PassKind::Compute).side_effect().sampled(never, ShaderStage::Compute);
  const Status status = graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'consumer'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("'never_written'"), std::string::npos) << status.message();
  EXPECT_EQ(graph.dump_text(), "not compiled\n");
}

TEST(FrameGraphErrors, TwoWritersOfOneVersionNameBothPasses) {
  FrameGraph graph;
  const ImageHandle color = graph.create_image({"color", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  graph.add_pass("first", PassKind::Graphics).color_write(color);
  graph.add_pass("second", PassKind::Graphics).color_write(color);  // should use first's handle
  const Status status = graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'first' and 'second'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("'color'"), std::string::npos) << status.message();
}

TEST(FrameGraphErrors, ReadingAnOldVersionNamesTheNewerWriter) {
  FrameGraph graph;
  const ImageHandle v0 = graph.create_image({"color", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  const ImageHandle v1 = graph.add_pass("a", PassKind::Graphics).color_write(v0);
  graph.add_pass("b", PassKind::Graphics).color_write(v1, LoadOp::Load);
  graph.add_pass("late", PassKind::Transfer).side_effect().transfer_read(v1);
  const Status status = graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pass 'late' reads version 1 of 'color' after pass 'b'"),
            std::string::npos)
      << status.message();
}

TEST(FrameGraphErrors, VerbsMustFitThePassKindAndTheFormat) {
  FrameGraph kind_graph;
  const ImageHandle img = kind_graph.create_image({"img", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  kind_graph.add_pass("copy", PassKind::Transfer).color_write(img);
  EXPECT_NE(kind_graph.compile().message().find("pass 'copy' (transfer) cannot use 'img'"),
            std::string::npos);
  FrameGraph format_graph;
  const ImageHandle col = format_graph.create_image({"col", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  format_graph.add_pass("scene", PassKind::Graphics).depth_write(col);
  const Status status = format_graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pass 'scene'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("'col' (VK_FORMAT_R8G8B8A8_UNORM) does not fit"),
            std::string::npos)
      << status.message();
}

TEST(FrameGraphErrors, SamplingTheDepthAttachmentBeingWrittenNamesPassAndResource) {
  FrameGraph graph;
  ImageHandle depth = graph.create_image({"scene_depth", VK_FORMAT_D32_SFLOAT, kExtent, {}});
  PassBuilder pass = graph.add_pass("feedback", PassKind::Graphics);
  pass.sampled_fragment(depth);
  depth = pass.depth_write(depth);  // a feedback loop: two layouts, still an error
  const Status status = graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pass 'feedback'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("'scene_depth'"), std::string::npos) << status.message();
  const std::string layouts =
      "different layouts (VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL and "
      "VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL)";
  EXPECT_NE(status.message().find(layouts), std::string::npos) << status.message();
}

TEST(FrameGraphErrors, ImportWithAnUndefinedOutgoingLayoutNamesTheResource) {
  FrameGraph graph;
  const ImageHandle present = graph.import_image(
      {"present", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}}, ResourceState{}, ResourceState{});
  graph.add_pass("draw", PassKind::Graphics).color_write(present);
  const Status status = graph.compile();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'present'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("has layout VK_IMAGE_LAYOUT_UNDEFINED,"), std::string::npos)
      << status.message();
  EXPECT_EQ(graph.dump_text(), "not compiled\n");

  // Buffers have no layout: an outgoing "no sync needed" state is fine for them.
  FrameGraph buffer_graph;
  const BufferHandle data = buffer_graph.import_buffer({"data", 256}, ResourceState{},
                                                       state_of(Access::None));
  buffer_graph.add_pass("fill", PassKind::Transfer).transfer_write(data);
  const Status buffer_status = buffer_graph.compile();
  EXPECT_TRUE(buffer_status.ok()) << buffer_status.message();
}

TEST(FrameGraphCompile, NextFrameWaitsOnEveryReadSinceTheLastBarrier) {
  // compute read (layout change) -> fragment read (barrier) -> compute read (no barrier): the
  // next frame's overwrite must wait on the fragment read too, not only on the last use.
  FrameGraph graph;
  ImageHandle tex = graph.create_image({"tex", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  const ImageHandle target = graph.create_image({"target", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  tex = graph.add_pass("fill", PassKind::Transfer).transfer_write(tex);
  graph.add_pass("c1", PassKind::Compute).side_effect().sampled(tex, ShaderStage::Compute);
  PassBuilder draw = graph.add_pass("g", PassKind::Graphics);
  draw.side_effect().sampled_fragment(tex);
  draw.color_write(target);
  graph.add_pass("c2", PassKind::Compute).side_effect().sampled(tex, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());
  const std::string dump = graph.dump_text();
  EXPECT_NE(dump.find("pass fill (transfer)\n"
                      "  barrier tex: UNDEFINED -> TRANSFER_DST_OPTIMAL, "
                      "FRAGMENT_SHADER|COMPUTE_SHADER:NONE -> TRANSFER:TRANSFER_WRITE\n"),
            std::string::npos)
      << dump;
  EXPECT_NE(dump.find("  barrier tex: SHADER_READ_ONLY_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL, "
                      "COMPUTE_SHADER:NONE -> FRAGMENT_SHADER:SHADER_SAMPLED_READ\n"),
            std::string::npos)
      << dump;
  EXPECT_NE(dump.find("pass c2 (compute)\nfinal\n"), std::string::npos) << dump;
}

TEST(FrameGraphCompile, OutgoingTransitionWaitsOnEveryUnorderedRead) {
  // The host waits only on the outgoing stages, so the compute read (already made visible, no
  // barrier needed for it) must still be chained into them before the hand-over.
  FrameGraph graph;
  const ResourceState graphics_read = state_of(Access::StorageReadGraphics);
  ImageHandle field = graph.import_image({"field", VK_FORMAT_R32_SFLOAT, kExtent, {}},
                                         ResourceState{}, graphics_read);
  const ImageHandle target = graph.create_image({"target", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  field = graph.add_pass("solve", PassKind::Compute).storage_write(field);
  PassBuilder draw = graph.add_pass("draw", PassKind::Graphics);
  draw.side_effect().storage_read(field, ShaderStage::Fragment);
  draw.color_write(target);
  graph.add_pass("probe", PassKind::Compute).side_effect().storage_read(field, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());
  const std::string dump = graph.dump_text();
  EXPECT_NE(dump.find("final\n"
                      "  barrier field: GENERAL -> GENERAL, "
                      "VERTEX_SHADER|FRAGMENT_SHADER|COMPUTE_SHADER:SHADER_STORAGE_WRITE -> "
                      "VERTEX_SHADER|FRAGMENT_SHADER:SHADER_STORAGE_READ\n"),
            std::string::npos)
      << dump;
}

TEST(FrameGraphCompile, OutgoingReadCoveringEveryReadNeedsNoBarrier) {
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  const ImageHandle tex = graph.import_image({"tex", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}},
                                             host_sampled, host_sampled);
  const ImageHandle target = graph.create_image({"target", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  PassBuilder draw = graph.add_pass("draw", PassKind::Graphics);
  draw.side_effect().sampled_fragment(tex);
  draw.color_write(target);
  ASSERT_TRUE(graph.compile().ok());
  const std::string dump = graph.dump_text();
  EXPECT_EQ(dump.find("barrier tex"), std::string::npos) << dump;

  // A compute read the host does not wait on must be chained into its fragment stage.
  graph.add_pass("probe", PassKind::Compute).side_effect().sampled(tex, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());
  EXPECT_NE(graph.dump_text().find("final\n  barrier tex: SHADER_READ_ONLY_OPTIMAL -> "
                                   "SHADER_READ_ONLY_OPTIMAL, FRAGMENT_SHADER|COMPUTE_SHADER:NONE"
                                   " -> FRAGMENT_SHADER:SHADER_SAMPLED_READ\n"),
            std::string::npos)
      << graph.dump_text();
}

TEST(FrameGraphCompile, OnePassCanSampleAndDepthTestTheSameDepthImage) {
  for (const bool sample_first : {false, true}) {
    SCOPED_TRACE(sample_first ? "sampled then depth_read" : "depth_read then sampled");
    FrameGraph graph;
    ImageHandle color = graph.create_image({"color", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
    ImageHandle depth = graph.create_image({"depth", VK_FORMAT_D32_SFLOAT, kExtent, {}});
    PassBuilder scene = graph.add_pass("scene", PassKind::Graphics);
    color = scene.color_write(color);
    depth = scene.depth_write(depth);
    PassBuilder water = graph.add_pass("water", PassKind::Graphics);
    if (sample_first) water.sampled_fragment(depth);
    water.depth_read(depth);
    if (!sample_first) water.sampled_fragment(depth);
    color = water.color_write(color);
    water.side_effect();
    const Status status = graph.compile();
    ASSERT_TRUE(status.ok()) << status.message();
    const std::string dump = graph.dump_text();
    EXPECT_NE(dump.find("pass water (graphics)\n"
                        "  barrier depth: DEPTH_STENCIL_ATTACHMENT_OPTIMAL -> "
                        "DEPTH_STENCIL_READ_ONLY_OPTIMAL, EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS:"
                        "DEPTH_STENCIL_ATTACHMENT_WRITE -> "
                        "FRAGMENT_SHADER|EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS:"
                        "SHADER_SAMPLED_READ|DEPTH_STENCIL_ATTACHMENT_READ\n"),
              std::string::npos)
        << dump;
    EXPECT_NE(dump.find("  depth depth: load LOAD, store NONE\n"), std::string::npos) << dump;
    EXPECT_NE(dump.find("  depth depth: load CLEAR, store STORE\n"), std::string::npos) << dump;
    EXPECT_EQ(graph.image_usage(depth), VkImageUsageFlags{VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                                          VK_IMAGE_USAGE_SAMPLED_BIT});
  }
}


// --- execute() against a fake device table --------------------------------------------------

std::vector<std::string>* g_calls = nullptr;
VkClearValue g_clear{};

VKAPI_ATTR void VKAPI_CALL fake_barrier(VkCommandBuffer, const VkDependencyInfo* dependency) {
  std::string line = "barrier images=" + std::to_string(dependency->imageMemoryBarrierCount) +
                     " buffers=" + std::to_string(dependency->bufferMemoryBarrierCount);
  for (uint32_t i = 0; i < dependency->imageMemoryBarrierCount; ++i) {
    // Two appends: GCC 12 warns falsely (-Wrestrict) on `" " + std::string` here in Release.
    line += ' ';
    line += layout_name(dependency->pImageMemoryBarriers[i].newLayout);
  }
  g_calls->push_back(line);
}
VKAPI_ATTR void VKAPI_CALL fake_begin_rendering(VkCommandBuffer, const VkRenderingInfo* info) {
  g_calls->push_back("begin_rendering " + std::to_string(info->renderArea.extent.width) + "x" +
                     std::to_string(info->renderArea.extent.height) + " colors=" +
                     std::to_string(info->colorAttachmentCount) +
                     " depth=" + (info->pDepthAttachment != nullptr ? "yes" : "no"));
  g_clear = info->pColorAttachments[0].clearValue;
}
VKAPI_ATTR void VKAPI_CALL fake_end_rendering(VkCommandBuffer) { g_calls->push_back("end_rendering"); }
VKAPI_ATTR void VKAPI_CALL fake_begin_label(VkCommandBuffer, const VkDebugUtilsLabelEXT* label) {
  g_calls->push_back(std::string("label ") + label->pLabelName);
}
VKAPI_ATTR void VKAPI_CALL fake_end_label(VkCommandBuffer) { g_calls->push_back("end_label"); }

DeviceTable fake_table(bool labels) {
  DeviceTable table;
  table.vkCmdPipelineBarrier2 = fake_barrier;
  table.vkCmdBeginRendering = fake_begin_rendering;
  table.vkCmdEndRendering = fake_end_rendering;
  if (labels) {
    table.vkCmdBeginDebugUtilsLabelEXT = fake_begin_label;
    table.vkCmdEndDebugUtilsLabelEXT = fake_end_label;
  }
  return table;
}

template <typename T>
T fake_handle(uintptr_t value) {
  return reinterpret_cast<T>(value);
}

FrameBindings bind_river(const River& h) {
  FrameBindings bindings;
  bindings.bind_buffer(h.staging, fake_handle<VkBuffer>(0x10));
  bindings.bind_buffer(h.readback, fake_handle<VkBuffer>(0x11));
  bindings.bind_image(h.flow, fake_handle<VkImage>(0x20), fake_handle<VkImageView>(0x21));
  bindings.bind_image(h.color, fake_handle<VkImage>(0x30), fake_handle<VkImageView>(0x31));
  bindings.bind_image(h.depth, fake_handle<VkImage>(0x40), fake_handle<VkImageView>(0x41));
  return bindings;
}

TEST(FrameGraphExecute, RecordsBarriersRenderingLabelsAndCallbacksInOrder) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const River h = declare_river(graph, &calls);
  ASSERT_TRUE(graph.compile().ok());
  const Status status =
      graph.execute(fake_table(true), fake_handle<VkCommandBuffer>(0x1), bind_river(h));
  ASSERT_TRUE(status.ok()) << status.message();
  const std::vector<std::string> expected = {
      "label upload",
      "barrier images=1 buffers=0 TRANSFER_DST_OPTIMAL",
      "record upload",
      "end_label",
      "label scene",
      "barrier images=3 buffers=0 SHADER_READ_ONLY_OPTIMAL COLOR_ATTACHMENT_OPTIMAL "
      "DEPTH_STENCIL_ATTACHMENT_OPTIMAL",
      "begin_rendering 64x32 colors=1 depth=yes",
      "record scene",
      "end_rendering",
      "end_label",
      "label readback",
      "barrier images=1 buffers=0 TRANSFER_SRC_OPTIMAL",
      "record readback",
      "end_label",
      "barrier images=0 buffers=1",
  };
  EXPECT_EQ(calls, expected);
  EXPECT_EQ(g_clear.color.float32[2], 0.75f);
}

TEST(FrameGraphExecute, MissingBindingFailsBeforeRecordingAnything) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const River h = declare_river(graph, &calls);
  ASSERT_TRUE(graph.compile().ok());
  FrameBindings bindings = bind_river(h);
  bindings.bind_image(h.depth, fake_handle<VkImage>(0x40));  // no view for an attachment
  const Status status = graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("pass 'scene' uses 'depth'"), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("VkImageView"), std::string::npos) << status.message();
  EXPECT_TRUE(calls.empty());
}

TEST(FrameGraphExecute, PerExecuteStatesOverrideTheImportAndCallbackErrorsPropagate) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  const ImageHandle out = graph.import_image({"host_out", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}},
                                             host_sampled, host_sampled);
  PassBuilder flow = graph.add_pass("flow", PassKind::Graphics);
  flow.color_write(out);
  ASSERT_TRUE(graph.compile().ok());
  FrameBindings bindings;
  bindings.bind_image(out, fake_handle<VkImage>(0x50), fake_handle<VkImageView>(0x51));
  bindings.set_outgoing(out, state_of(Access::TransferRead));  // host copies it this frame
  ASSERT_TRUE(graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  EXPECT_EQ(calls.back(), "barrier images=1 buffers=0 TRANSFER_SRC_OPTIMAL");

  flow.record([](const PassContext&) { return Status::error("no pipeline"); });
  ASSERT_TRUE(graph.compile().ok());
  const Status status =
      graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings);
  EXPECT_EQ(status.message(), "frame graph: pass 'flow': no pipeline");
}

TEST(FrameGraphExecute, CallbacksReadTheFramesDataAndUnboundDataIsRefusedByName) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  const ImageHandle out = graph.import_image({"host_out", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}},
                                             host_sampled, host_sampled);
  const DataHandle<int> level = graph.declare_data<int>("water level");
  PassBuilder flow = graph.add_pass("flow", PassKind::Graphics);
  flow.color_write(out);
  flow.record([level](const PassContext& ctx) {
    g_calls->push_back("level " + std::to_string(ctx.data(level)));
    return Status::success();
  });
  ASSERT_TRUE(graph.compile().ok());
  FrameBindings bindings;
  bindings.bind_image(out, fake_handle<VkImage>(0x50), fake_handle<VkImageView>(0x51));
  const Status unbound = graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings);
  ASSERT_FALSE(unbound.ok());
  EXPECT_EQ(unbound.message(), "frame graph: the frame's 'water level' is not bound");
  EXPECT_TRUE(calls.empty()) << "nothing recorded";
  for (const int frame_level : {3, 7}) {  // each execute reads what it is given
    bindings.bind_data(level, &frame_level);
    ASSERT_TRUE(graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  }
  std::vector<std::string> levels;
  for (const std::string& call : calls) {
    if (call.rfind("level ", 0) == 0) levels.push_back(call);
  }
  EXPECT_EQ(levels, (std::vector<std::string>{"level 3", "level 7"}));
}

// One line per image or buffer barrier, with the image's handle value and the full states.
VKAPI_ATTR void VKAPI_CALL detail_barrier(VkCommandBuffer, const VkDependencyInfo* dependency) {
  for (uint32_t i = 0; i < dependency->imageMemoryBarrierCount; ++i) {
    const VkImageMemoryBarrier2& b = dependency->pImageMemoryBarriers[i];
    g_calls->push_back("image " + std::to_string(reinterpret_cast<uintptr_t>(b.image)) + ": " +
                       layout_name(b.oldLayout) + " -> " + layout_name(b.newLayout) + ", " +
                       stage_flags_name(b.srcStageMask) + ":" + access_flags_name(b.srcAccessMask) +
                       " -> " + stage_flags_name(b.dstStageMask) + ":" +
                       access_flags_name(b.dstAccessMask));
  }
  for (uint32_t i = 0; i < dependency->bufferMemoryBarrierCount; ++i) {
    const VkBufferMemoryBarrier2& b = dependency->pBufferMemoryBarriers[i];
    g_calls->push_back("buffer " + std::to_string(reinterpret_cast<uintptr_t>(b.buffer)) + ": " +
                       stage_flags_name(b.srcStageMask) + ":" + access_flags_name(b.srcAccessMask) +
                       " -> " + stage_flags_name(b.dstStageMask) + ":" +
                       access_flags_name(b.dstAccessMask));
  }
}

DeviceTable detail_table() {
  DeviceTable table = fake_table(false);
  table.vkCmdPipelineBarrier2 = detail_barrier;
  return table;
}

// Records nothing and allocates nothing, so allocations during execute() are the graph's own.
int g_quiet_barriers = 0;
VKAPI_ATTR void VKAPI_CALL quiet_barrier(VkCommandBuffer, const VkDependencyInfo* dependency) {
  g_quiet_barriers += static_cast<int>(dependency->imageMemoryBarrierCount +
                                       dependency->bufferMemoryBarrierCount);
}
VKAPI_ATTR void VKAPI_CALL quiet_begin_rendering(VkCommandBuffer, const VkRenderingInfo*) {}
VKAPI_ATTR void VKAPI_CALL quiet_end_rendering(VkCommandBuffer) {}

DeviceTable quiet_table() {
  DeviceTable table;
  table.vkCmdPipelineBarrier2 = quiet_barrier;
  table.vkCmdBeginRendering = quiet_begin_rendering;
  table.vkCmdEndRendering = quiet_end_rendering;
  return table;
}

// Allocations made by one execute().
uint64_t allocations_of_execute(const FrameGraph& graph, const FrameBindings& bindings,
                                Status* status) {
  const DeviceTable table = quiet_table();
  const uint64_t before = g_allocations.load();
  *status = graph.execute(table, fake_handle<VkCommandBuffer>(0x1), bindings);
  return g_allocations.load() - before;
}

TEST(FrameGraphExecute, SteadyExecuteWithoutOverridesAllocatesNothing) {
  FrameGraph graph;
  const River h = declare_river(graph);
  ASSERT_TRUE(graph.compile().ok());
  const FrameBindings bindings = bind_river(h);
  Status status;
  allocations_of_execute(graph, bindings, &status);  // the first one sizes the scratch arrays
  ASSERT_TRUE(status.ok()) << status.message();
  g_quiet_barriers = 0;
  EXPECT_EQ(allocations_of_execute(graph, bindings, &status), 0u);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(g_quiet_barriers, 6);  // flow; flow, color, depth; color; readback
}

TEST(FrameGraphExecute, SameOverridesReuseTheDerivedBarriersAndNewOnesDeriveAgain) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  const ImageHandle out = graph.import_image({"host_out", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}},
                                             host_sampled, host_sampled);
  graph.add_pass("flow", PassKind::Graphics).color_write(out);
  ASSERT_TRUE(graph.compile().ok());
  const std::string listing = graph.dump_text();
  FrameBindings bindings;
  bindings.bind_image(out, fake_handle<VkImage>(0x50), fake_handle<VkImageView>(0x51));
  bindings.set_incoming(out, state_of(Access::TransferWrite));  // the host copied into it
  bindings.set_outgoing(out, state_of(Access::TransferRead));   // and copies out of it next

  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  const std::vector<std::string> expected = {
      "image 80: TRANSFER_DST_OPTIMAL -> COLOR_ATTACHMENT_OPTIMAL, TRANSFER:TRANSFER_WRITE -> "
      "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_READ|COLOR_ATTACHMENT_WRITE",
      "begin_rendering 64x32 colors=1 depth=no",
      "end_rendering",
      "image 80: COLOR_ATTACHMENT_OPTIMAL -> TRANSFER_SRC_OPTIMAL, "
      "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_WRITE -> TRANSFER:TRANSFER_READ",
  };
  EXPECT_EQ(calls, expected);

  // The same states again: the same barriers, with no derivation and no allocation.
  Status status;
  EXPECT_EQ(allocations_of_execute(graph, bindings, &status), 0u);
  ASSERT_TRUE(status.ok()) << status.message();
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  EXPECT_EQ(calls, expected);

  // A new outgoing state yields the new final barrier.
  bindings.set_outgoing(out, host_sampled);
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  ASSERT_EQ(calls.size(), 4u);
  EXPECT_EQ(calls[0], expected[0]);
  EXPECT_EQ(calls[3],
            "image 80: COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL, "
            "COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_WRITE -> FRAGMENT_SHADER:SHADER_SAMPLED_READ");

  // Back to the first states, then no overrides at all: the declared listing is untouched.
  bindings.set_outgoing(out, state_of(Access::TransferRead));
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), bindings).ok());
  EXPECT_EQ(calls, expected);
  FrameBindings plain;
  plain.bind_image(out, fake_handle<VkImage>(0x50), fake_handle<VkImageView>(0x51));
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), plain).ok());
  ASSERT_EQ(calls.size(), 4u);
  EXPECT_EQ(calls[0],
            "image 80: SHADER_READ_ONLY_OPTIMAL -> COLOR_ATTACHMENT_OPTIMAL, FRAGMENT_SHADER:NONE"
            " -> COLOR_ATTACHMENT_OUTPUT:COLOR_ATTACHMENT_READ|COLOR_ATTACHMENT_WRITE");
  EXPECT_EQ(graph.dump_text(), listing);
}

TEST(FrameGraphExecute, PersistentImageStartsWhereThePreviousFrameLeftIt) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  ImageHandle history = graph.create_persistent_image(
      {"history", VK_FORMAT_R16G16B16A16_SFLOAT, kExtent, {}});
  const ImageHandle screen = graph.create_image({"screen", VK_FORMAT_R8G8B8A8_UNORM, kExtent, {}});
  PassBuilder accumulate = graph.add_pass("accumulate", PassKind::Compute);
  accumulate.storage_read(history, ShaderStage::Compute);
  history = accumulate.storage_write(history);
  graph.add_pass("blur", PassKind::Compute).side_effect().sampled(history, ShaderStage::Compute);
  PassBuilder show = graph.add_pass("show", PassKind::Graphics);
  show.side_effect().sampled_fragment(history);
  show.color_write(screen);
  graph.add_pass("stats", PassKind::Compute).side_effect().sampled(history, ShaderStage::Compute);
  ASSERT_TRUE(graph.compile().ok());

  FrameBindings first;
  first.bind_image(history, fake_handle<VkImage>(0x60), fake_handle<VkImageView>(0x61));
  first.bind_image(screen, fake_handle<VkImage>(0x70), fake_handle<VkImageView>(0x71));
  FrameBindings steady = first;
  first.set_incoming(history, ResourceState{});  // freshly created: undefined contents
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), first).ok());
  const std::vector<std::string> frame1 = calls;
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), steady).ok());
  const std::vector<std::string> frame2 = calls;
  calls.clear();
  ASSERT_TRUE(graph.execute(detail_table(), fake_handle<VkCommandBuffer>(0x1), steady).ok());
  EXPECT_EQ(calls, frame2);  // the state a steady frame leaves is the one it started from

  const std::string write =
      " -> COMPUTE_SHADER:SHADER_STORAGE_READ|SHADER_STORAGE_WRITE";
  ASSERT_FALSE(frame1.empty());
  EXPECT_EQ(frame1[0], "image 96: UNDEFINED -> GENERAL, NONE:NONE" + write);
  // Frame 1 left history sampled by blur, show (fragment) and stats: wait on all of them.
  ASSERT_FALSE(frame2.empty());
  EXPECT_EQ(frame2[0],
            "image 96: SHADER_READ_ONLY_OPTIMAL -> GENERAL, FRAGMENT_SHADER|COMPUTE_SHADER:NONE" +
                write);
  EXPECT_EQ(std::vector<std::string>(frame1.begin() + 1, frame1.end()),
            std::vector<std::string>(frame2.begin() + 1, frame2.end()));
  EXPECT_NE(graph.dump_text().find("pass accumulate (compute)\n  barrier history: "
                                   "SHADER_READ_ONLY_OPTIMAL -> GENERAL, "
                                   "FRAGMENT_SHADER|COMPUTE_SHADER:NONE" + write),
            std::string::npos)
      << graph.dump_text();
}

TEST(FrameGraphExecute, UndefinedOutgoingOverrideIsRejectedBeforeRecording) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const ResourceState host_sampled = state_of(Access::SampledFragment);
  const ImageHandle out = graph.import_image({"host_out", VK_FORMAT_B8G8R8A8_UNORM, kExtent, {}},
                                             host_sampled, host_sampled);
  graph.add_pass("flow", PassKind::Graphics).color_write(out);
  ASSERT_TRUE(graph.compile().ok());
  FrameBindings bindings;
  bindings.bind_image(out, fake_handle<VkImage>(0x50), fake_handle<VkImageView>(0x51));
  bindings.set_outgoing(out, state_of(Access::None));  // "no sync", but also no layout
  const Status status = graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'host_out'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("has layout VK_IMAGE_LAYOUT_UNDEFINED,"), std::string::npos)
      << status.message();
  EXPECT_TRUE(calls.empty());
}

TEST(FrameGraphExecute, OverridesOnlyWhereTheyApplyNameTheResource) {
  std::vector<std::string> calls;
  g_calls = &calls;
  FrameGraph graph;
  const River h = declare_river(graph, &calls);
  ASSERT_TRUE(graph.compile().ok());
  FrameBindings bindings = bind_river(h);
  bindings.set_incoming(h.color, state_of(Access::TransferRead));  // transient: no such state
  const Status status = graph.execute(fake_table(false), fake_handle<VkCommandBuffer>(0x1), bindings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'color' takes no per-execute state"), std::string::npos)
      << status.message();
  EXPECT_TRUE(calls.empty());
}

}  // namespace
}  // namespace siviflow
