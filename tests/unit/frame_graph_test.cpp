// Frame graph and Access table, on the CPU: compile results are asserted through the text dump,
// and execute() is run against a fake device table that records the commands it receives.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vk/access.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"

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

TEST(AccessTable, NamesAreStable) {
  EXPECT_EQ(access_name(Access::StorageWriteCompute), std::string("StorageWriteCompute"));
  EXPECT_EQ(stage_flags_name(0), "NONE");
  EXPECT_EQ(stage_flags_name(access_info(Access::DepthAttachmentWrite).stage),
            "EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS");
  EXPECT_EQ(stage_flags_name(VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT), "TRANSFER");
  EXPECT_EQ(access_flags_name(VK_ACCESS_2_TRANSFER_WRITE_BIT | (1ull << 60)),
            "TRANSFER_WRITE|0x1000000000000000");
  EXPECT_EQ(layout_name(VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL), "TRANSFER_DST_OPTIMAL");
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
  EXPECT_FALSE(format_graph.compile().ok());
}

// --- execute() against a fake device table --------------------------------------------------

std::vector<std::string>* g_calls = nullptr;
VkClearValue g_clear{};

VKAPI_ATTR void VKAPI_CALL fake_barrier(VkCommandBuffer, const VkDependencyInfo* dependency) {
  std::string line = "barrier images=" + std::to_string(dependency->imageMemoryBarrierCount) +
                     " buffers=" + std::to_string(dependency->bufferMemoryBarrierCount);
  for (uint32_t i = 0; i < dependency->imageMemoryBarrierCount; ++i) {
    line += " " + layout_name(dependency->pImageMemoryBarriers[i].newLayout);
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
  EXPECT_NE(status.message().find("'depth'"), std::string::npos) << status.message();
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

}  // namespace
}  // namespace siviflow
