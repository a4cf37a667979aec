// siviflow::view_memory counts what a view really takes: between a small and a large view, the
// device memory the renderer allocates (through a watched vkGetDeviceProcAddr) grows by what
// the estimate says, with and without the AOV attachments; the readback estimate covers the
// buffers a host makes for the images it asks for. Bad input is refused by name.
#include <cstdio>

#include <gtest/gtest.h>

#include "device_call_faults.h"
#include "render_frames.h"

namespace siviflow::testing {
namespace {

namespace watch = device_call_faults;
constexpr double kMiB = 1024.0 * 1024.0;

class ViewMemoryTest : public RenderTest {
 protected:
  // The device memory a renderer of `info` allocates at create, and its estimate.
  void create_watched(CreateInfo info, uint64_t* allocated, ViewMemory* estimate) {
    watch::install(info.get_device_proc_addr);
    info.get_device_proc_addr = &watch::get_device_proc_addr;
    info.reflection = &World::draw_reflection;
    info.reflection_user = world_.get();
    renderer_.reset();
    ASSERT_TRUE(Renderer::create(info, &renderer_).ok());
    *allocated = watch::state.allocated_bytes;
    ASSERT_TRUE(view_memory(info, estimate).ok());
  }
};

TEST_F(ViewMemoryTest, TheEstimateGrowsAsTheAllocationsDo) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());  // the world
  for (const uint32_t images : {0u, kAllReadbackImages}) {
    CreateInfo small = make_create_info(160, 90);
    small.readback_images = images;
    CreateInfo large = make_create_info(1280, 720);
    large.readback_images = images;
    uint64_t small_bytes = 0, large_bytes = 0;
    ViewMemory small_estimate, large_estimate;
    ASSERT_NO_FATAL_FAILURE(create_watched(small, &small_bytes, &small_estimate));
    ASSERT_NO_FATAL_FAILURE(create_watched(large, &large_bytes, &large_estimate));
    VkDeviceSize readback = 0;  // what a host allocates for the large view's readback
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      if ((images & readback_bit(static_cast<ReadbackImage>(i))) == 0) continue;
      readback += renderer_->readback_bytes(static_cast<ReadbackImage>(i));
    }
    const double grown = static_cast<double>(large_bytes - small_bytes);
    const double estimated =
        static_cast<double>(large_estimate.renderer_bytes - small_estimate.renderer_bytes);
    std::printf("readback %s: 160x90 -> 1280x720 allocates %.2f MiB more, estimated %.2f MiB "
                "more; estimate at 1280x720 %.2f MiB (renderer), %.2f MiB per slot of readback, "
                "which is %.2f MiB\n",
                images != 0 ? "all" : "none", grown / kMiB, estimated / kMiB,
                large_estimate.renderer_bytes / kMiB, large_estimate.readback_bytes / kMiB,
                readback / kMiB);
    EXPECT_GT(grown, 4.0 * kMiB);
    // The particle slots (aux data) are counted at their most: up to 1 MiB apart.
    EXPECT_NEAR(estimated, grown, 0.03 * grown + 1.0 * kMiB);
    EXPECT_GE(static_cast<double>(large_estimate.renderer_bytes), grown);
    // The aux data and the tile table are counted at their most (1 MiB and 4 MiB).
    EXPECT_GE(large_estimate.readback_bytes, readback);
    EXPECT_LE(large_estimate.readback_bytes, readback + 5 * (1u << 20));
  }
}

TEST_F(ViewMemoryTest, BadInputIsRefusedByName) {
  ViewMemory memory;
  CreateInfo info;
  Status status = view_memory(info, &memory);
  EXPECT_EQ(status.message(), "siviflow::Renderer: CreateInfo::extent must be at least 1x1");
  info.extent = {64, 64};
  info.color_format = VK_FORMAT_R8_UNORM;
  status = view_memory(info, &memory);
  EXPECT_EQ(status.message(),
            "siviflow::Renderer: CreateInfo::color_format VK_FORMAT_R8_UNORM is not an "
            "uncompressed colour format with red, green and blue");
  info.color_format = VK_FORMAT_UNDEFINED;
  status = view_memory(info, &memory);
  EXPECT_EQ(status.message(),
            "siviflow::Renderer: CreateInfo::color_format is VK_FORMAT_UNDEFINED: name the format "
            "of the host's colour image");
  // What create() refuses of the depth format, view_memory() refuses too.
  info.color_format = VK_FORMAT_B10G11R11_UFLOAT_PACK32;
  info.depth_format = VK_FORMAT_D16_UNORM;
  status = view_memory(info, &memory);
  EXPECT_EQ(status.message(),
            "siviflow::Renderer: CreateInfo::depth_format VK_FORMAT_D16_UNORM is not "
            "VK_FORMAT_D32_SFLOAT, VK_FORMAT_D24_UNORM_S8_UINT or VK_FORMAT_D32_SFLOAT_S8_UINT");
  info.depth_format = VK_FORMAT_X8_D24_UNORM_PACK32;
  EXPECT_FALSE(view_memory(info, &memory).ok());
  info.depth_format = VK_FORMAT_UNDEFINED;
  EXPECT_TRUE(view_memory(info, &memory).ok());
}

}  // namespace
}  // namespace siviflow::testing
