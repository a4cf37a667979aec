// The water in a modern engine's frame: the colour formats engines render to, a TAA jitter,
// views that share pixels under scissors, a river placed in a Z-up world, the water's box and
// its depth, and the words of what is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <string>
#include <vector>

#include "render_frames.h"
#include "vk/device_table.h"

namespace siviflow::testing {
namespace {

// Mean linear colour of the water's pixels.
glm::vec3 mean_water_colour(const Frame& frame) {
  glm::dvec3 sum(0.0);
  size_t count = 0;
  for (size_t i = 0; i < frame.water_mask.size(); ++i) {
    if (frame.water_mask[i] < 0.5f) continue;
    sum += glm::dvec3(frame.rgba[i * 4], frame.rgba[i * 4 + 1], frame.rgba[i * 4 + 2]);
    ++count;
  }
  return count == 0 ? glm::vec3(0.0f) : glm::vec3(sum / static_cast<double>(count));
}

// The spread (largest standard deviation over the channels) of a series of colours.
float spread(const std::vector<glm::vec3>& colours) {
  glm::dvec3 mean(0.0), square(0.0);
  for (const glm::vec3& c : colours) {
    mean += glm::dvec3(c);
    square += glm::dvec3(c) * glm::dvec3(c);
  }
  mean /= static_cast<double>(colours.size());
  square /= static_cast<double>(colours.size());
  const glm::dvec3 variance = glm::max(square - mean * mean, glm::dvec3(0.0));
  return static_cast<float>(std::sqrt(std::max({variance.x, variance.y, variance.z})));
}

class ModernEngineTest : public RenderTest {
 protected:
  // Frame 3 of the default scene with the host's colour in `format`.
  Frame frame_in(VkFormat format) {
    color_format_ = format;
    renderer_.reset();
    world_.reset();
    const Status status = create_renderer(make_create_info(kWidth, kHeight));
    EXPECT_TRUE(status.ok()) << status.message();
    if (!status.ok()) return Frame{};
    std::vector<Frame> frames = render(0, 4);
    return frames.empty() ? Frame{} : frames.back();
  }
};

struct FormatTolerance {
  VkFormat format;
  float absolute;  // linear units, after clamping to what the format holds
  float relative;  // of the value
  bool unorm;      // holds [0, 1] only
  bool srgb;       // compared in its encoded steps
};

// Each listed format renders the RGBA16F frame within its own precision: the world is drawn,
// copied, reflected and blended over in that format, so a few of its steps.
TEST_F(ModernEngineTest, EveryColourFormatRendersTheFrameWithinItsPrecision) {
  const Frame reference = frame_in(VK_FORMAT_R16G16B16A16_SFLOAT);
  ASSERT_FALSE(reference.rgba.empty());
  const FormatTolerance formats[] = {
      {VK_FORMAT_R32G32B32A32_SFLOAT, 2e-3f, 2e-3f, false, false},
      {VK_FORMAT_B10G11R11_UFLOAT_PACK32, 2e-3f, 0.06f, false, false},
      {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 4.0f / 1023.0f, 0.0f, true, false},
      {VK_FORMAT_R8G8B8A8_UNORM, 4.0f / 255.0f, 0.0f, true, false},
      {VK_FORMAT_B8G8R8A8_UNORM, 4.0f / 255.0f, 0.0f, true, false},
      {VK_FORMAT_R8G8B8A8_SRGB, 4.0f / 255.0f, 0.0f, true, true},
      {VK_FORMAT_B8G8R8A8_SRGB, 4.0f / 255.0f, 0.0f, true, true},
  };
  for (const FormatTolerance& f : formats) {
    SCOPED_TRACE(f.format);
    const Frame frame = frame_in(f.format);
    ASSERT_EQ(frame.rgba.size(), reference.rgba.size());
    EXPECT_EQ(frame.water_mask, reference.water_mask) << "the same water covers the same pixels";
    size_t outside = 0;
    double error_sum = 0.0;
    for (size_t i = 0; i < reference.rgba.size(); ++i) {
      if (i % 4 == 3) continue;  // alpha: the water's blend keeps what the host's holds
      float want = reference.rgba[i];
      float got = frame.rgba[i];
      if (f.unorm) want = std::clamp(want, 0.0f, 1.0f);
      if (f.srgb) {  // the encoded steps, where 8 bits round
        const auto encode = [](float x) {
          return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
        };
        want = encode(want);
        got = encode(got);
      }
      const float error = std::abs(got - want);
      error_sum += error;
      outside += error > f.absolute + f.relative * std::abs(want) ? 1 : 0;
    }
    const size_t channels = reference.rgba.size() / 4 * 3;
    EXPECT_LT(outside, channels / 200) << outside << " of " << channels << " channels differ";
    EXPECT_LT(error_sum / channels, 0.5 * f.absolute + 0.5 * f.relative * 0.2);
  }
}

TEST_F(ModernEngineTest, AFormatTheDeviceCannotBlendIsRefusedByName) {
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.color_format = VK_FORMAT_R16G16B16A16_UINT;
  std::unique_ptr<Renderer> renderer;
  const Status status = Renderer::create(info, &renderer);
  EXPECT_EQ(status.message(),
            "siviflow::Renderer: CreateInfo::color_format VK_FORMAT_R16G16B16A16_UINT lacks "
            "VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT on this device (the water blends into "
            "it, copies it and samples the copy)");
  EXPECT_EQ(status.code(), VK_ERROR_FORMAT_NOT_SUPPORTED);
  info.color_format = VK_FORMAT_UNDEFINED;
  EXPECT_EQ(Renderer::create(info, &renderer).message(),
            "siviflow::Renderer: CreateInfo::color_format is VK_FORMAT_UNDEFINED: name the format "
            "of the host's colour image");
}

// A still camera under a Halton jitter keeps exactly the particles of the unjittered one, and
// the water's colour moves no more than it does without the jitter.
TEST_F(ModernEngineTest, JitterChurnsNoParticlesAndAddsNoShimmer) {
  constexpr uint32_t kFrames = 60;
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  const View still = camera_view(world_->scene_camera(0.0), {kWidth, kHeight});
  const std::vector<Frame> plain =
      render_views(0, kFrames, kWidth, kHeight, [&](double) { return still; });
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  const std::vector<Frame> shaken = render_views(0, kFrames, kWidth, kHeight, [&](double time) {
    const auto frame = static_cast<uint32_t>(std::lround(time * 30.0));
    return with_taa_jitter(still, frame, {kWidth, kHeight});
  });
  ASSERT_EQ(plain.size(), kFrames);
  ASSERT_EQ(shaken.size(), kFrames);
  std::vector<glm::vec3> plain_colours, shaken_colours;
  for (uint32_t f = 0; f < kFrames; ++f) {
    // The flow texture holds each texel's particle id: the same ids over the same texels.
    EXPECT_EQ(plain[f].flow_texture, shaken[f].flow_texture) << "frame " << f;
    EXPECT_EQ(plain[f].particle_aux, shaken[f].particle_aux) << "frame " << f;
    // The tiles pick the same particles: the ripples' flow and foam do not churn either.
    EXPECT_EQ(plain[f].tile_table, shaken[f].tile_table) << "frame " << f;
    plain_colours.push_back(mean_water_colour(plain[f]));
    shaken_colours.push_back(mean_water_colour(shaken[f]));
  }
  EXPECT_LE(spread(shaken_colours), 1.25f * spread(plain_colours) + 1e-3f)
      << "without jitter " << spread(plain_colours);
}

// Two views over the same pixels (a picture in picture), each kept to its scissor.
TEST_F(ModernEngineTest, OverlappingViewsStayInsideTheirScissors) {
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.readback_images = readback_bit(ReadbackImage::kWaterMask);
  ASSERT_TRUE(create_renderer(info).ok());
  CreateInfo second_info = info;
  second_info.share_river_with = renderer_.get();
  second_info.reflection = &World::draw_reflection;
  second_info.reflection_user = world_.get();
  std::unique_ptr<Renderer> second;
  ASSERT_TRUE(Renderer::create(second_info, &second).ok());
  const VkRect2D left{{0, 0}, {kWidth / 2, kHeight}};
  const VkRect2D right{{static_cast<int32_t>(kWidth / 2), 0}, {kWidth / 2, kHeight}};
  HostTargets targets;
  ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
  HostBuffer masks[2];
  for (HostBuffer& mask : masks) {
    ASSERT_TRUE(
        context_
            ->create_readback_buffer(renderer_->readback_bytes(ReadbackImage::kWaterMask), &mask)
            .ok());
  }
  // Three frames from `first` on (the river's time only goes forward).
  const auto render_pair = [&](bool scissored, uint32_t first) {
    Renderer* renderers[2] = {renderer_.get(), second.get()};
    for (uint32_t frame = first; frame < first + 3; ++frame) {
      const double time = frame / 30.0;
      View views[2] = {camera_view(world_->scene_camera(time), {kWidth, kHeight}),
                       camera_view(world_->scene_camera(time + 3.0), {kWidth, kHeight})};
      if (scissored) {
        views[0].scissor = left;
        views[1].scissor = right;
      }
      VkCommandBuffer cmd = VK_NULL_HANDLE;
      ASSERT_TRUE(context_->begin_slot(0, &cmd).ok());
      ASSERT_TRUE(world_->begin_frame(0).ok());
      for (int v = 0; v < 2; ++v) {
        ASSERT_TRUE(renderers[v]->begin_frame(0).ok());
        const Status updated = renderers[v]->update(views[v], time);
        ASSERT_TRUE(updated.ok()) << updated.message();
        ReadbackTargets readback;
        readback[ReadbackImage::kWaterMask] = masks[v].buffer;
        Renderer* const one[] = {renderers[v]};
        const Status status = record_view(cmd, *world_, one, views[v], time, readback, &targets);
        ASSERT_TRUE(status.ok()) << status.message();
      }
      ASSERT_TRUE(context_->end_slot_and_submit(0).ok());
      ASSERT_TRUE(context_->wait_slot(0).ok());
    }
  };
  // Water pixels of each view's mask inside and outside a rectangle.
  const auto count = [&](int v, const VkRect2D& rect, size_t* inside, size_t* outside) {
    *inside = *outside = 0;
    const auto* mask = static_cast<const float*>(masks[v].data);
    for (uint32_t y = 0; y < kHeight; ++y) {
      for (uint32_t x = 0; x < kWidth; ++x) {
        if (mask[size_t{y} * kWidth + x] < 0.5f) continue;
        const bool in =
            x >= static_cast<uint32_t>(rect.offset.x) && x < rect.offset.x + rect.extent.width;
        (in ? *inside : *outside) += 1;
      }
    }
  };
  size_t inside = 0, outside = 0;
  render_pair(false, 0);
  count(0, left, &inside, &outside);
  ASSERT_GT(outside, 300u) << "without scissors the first view's water crosses the middle";
  render_pair(true, 3);
  count(0, left, &inside, &outside);
  EXPECT_GT(inside, 1000u);
  EXPECT_EQ(outside, 0u) << "the first view's water left its scissor";
  count(1, right, &inside, &outside);
  EXPECT_GT(inside, 1000u);
  EXPECT_EQ(outside, 0u) << "the second view's water left its scissor";
}

// A host without a world of its own: its colour cleared to grey, its depth to the far plane,
// the water over them with its sky reflected; colour, depth and water mask read back.
class BareHostTest : public GpuTest {
 protected:
  struct Result {
    std::vector<float> rgba;
    std::vector<float> depth;
    std::vector<float> mask;
  };

  void SetUp() override {
    GpuTest::SetUp();
    const char* missing = nullptr;
    ASSERT_EQ(
        load_device_table(context_->instance(), context_->physical_device(), context_->device(),
                          context_->get_instance_proc_addr(), nullptr, false, &table_, &missing),
        VK_SUCCESS);
  }

  static CreateInfo bare_info(HeadlessContext& context) {
    CreateInfo info =
        context.renderer_create_info({kWidth, kHeight}, VK_FORMAT_R16G16B16A16_SFLOAT);
    info.depth_format = VK_FORMAT_D32_SFLOAT;
    info.frames_in_flight = 1;
    info.write_depth = true;
    info.readback_images = readback_bit(ReadbackImage::kColor) |
                           readback_bit(ReadbackImage::kDepth) |
                           readback_bit(ReadbackImage::kWaterMask);
    return info;
  }

  // Frame `frames - 1` of `renderer` seen through `view_at(frame)`.
  template <typename ViewAt>
  Result render(Renderer& renderer, uint32_t frames, ViewAt view_at) {
    Result result;
    HostTargets targets;
    EXPECT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
    HostBuffer buffers[3];
    const ReadbackImage images[3] = {ReadbackImage::kColor, ReadbackImage::kDepth,
                                     ReadbackImage::kWaterMask};
    ReadbackTargets readback;
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(
          context_->create_readback_buffer(renderer.readback_bytes(images[i]), &buffers[i]).ok());
      readback[images[i]] = buffers[i].buffer;
    }
    for (uint32_t frame = 0; frame < frames; ++frame) {
      VkCommandBuffer cmd = VK_NULL_HANDLE;
      EXPECT_TRUE(context_->begin_slot(0, &cmd).ok());
      EXPECT_TRUE(renderer.begin_frame(0).ok());
      const View view = view_at(frame);
      Status status = renderer.update(view, frame / 30.0);
      EXPECT_TRUE(status.ok()) << status.message();
      clear(cmd, targets);
      FrameInputs inputs;
      inputs.color = targets.color;
      inputs.depth = targets.depth;
      inputs.readback = readback;
      status = renderer.record(cmd, inputs);
      EXPECT_TRUE(status.ok()) << status.message();
      EXPECT_TRUE(context_->end_slot_and_submit(0).ok());
      EXPECT_TRUE(context_->wait_slot(0).ok());
    }
    const size_t pixels = size_t{kWidth} * kHeight;
    result.rgba = decode_color(VK_FORMAT_R16G16B16A16_SFLOAT, buffers[0].data, pixels);
    const auto* depth = static_cast<const float*>(buffers[1].data);
    result.depth.assign(depth, depth + pixels);
    const auto* mask = static_cast<const float*>(buffers[2].data);
    result.mask.assign(mask, mask + pixels);
    return result;
  }

  // The host's pass before the water: both images cleared (a grey, the far plane) by a
  // rendering of their own, and stated as attachments just written.
  void clear(VkCommandBuffer cmd, HostTargets& targets) {
    VkImageMemoryBarrier2 barriers[2] = {{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2},
                                         {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2}};
    const ExternalImage* images[2] = {&targets.color, &targets.depth};
    const ImageState written[2] = {
        {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
         VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
        {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL}};
    for (int i = 0; i < 2; ++i) {
      barriers[i].srcStageMask = images[i]->current.stage;
      barriers[i].srcAccessMask = images[i]->current.access;
      barriers[i].dstStageMask = written[i].stage;
      barriers[i].dstAccessMask = written[i].access;
      barriers[i].oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      barriers[i].newLayout = written[i].layout;
      barriers[i].srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      barriers[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      barriers[i].image = images[i]->image;
      const VkImageAspectFlags aspect =
          i == 0 ? VK_IMAGE_ASPECT_COLOR_BIT : VK_IMAGE_ASPECT_DEPTH_BIT;
      barriers[i].subresourceRange = {aspect, 0, 1, 0, 1};
    }
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.imageMemoryBarrierCount = 2;
    dependency.pImageMemoryBarriers = barriers;
    table_.vkCmdPipelineBarrier2(cmd, &dependency);
    VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    color.imageView = targets.color.view;
    color.imageLayout = written[0].layout;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.clearValue.color = {{0.3f, 0.3f, 0.3f, 1.0f}};
    VkRenderingAttachmentInfo depth = color;
    depth.imageView = targets.depth.view;
    depth.imageLayout = written[1].layout;
    depth.clearValue.depthStencil = {1.0f, 0};
    VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
    rendering.renderArea = {{0, 0}, {kWidth, kHeight}};
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = 1;
    rendering.pColorAttachments = &color;
    rendering.pDepthAttachment = &depth;
    table_.vkCmdBeginRendering(cmd, &rendering);
    table_.vkCmdEndRendering(cmd);
    targets.color.current = written[0];
    targets.depth.current = written[1];
  }

  DeviceTable table_;
};

// A Z-up engine: river space's +Y is the world's +Z, and the river lies away from the origin.
glm::mat4 z_up_placement() {
  const glm::mat4 to_z_up =
      glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(1.0f, 0.0f, 0.0f));
  return glm::translate(glm::mat4(1.0f), glm::vec3(250.0f, -40.0f, 12.0f)) * to_z_up;
}

TEST_F(BareHostTest, RiverPlacedInAZUpWorldEqualsTheRotatedView) {
  const glm::mat4 placement = z_up_placement();
  const View river_view = camera_view(Camera{}, {kWidth, kHeight});  // looks at the river
  // The host's view of its world, which sees the placed river as river_view sees it.
  View world_view = river_view;
  world_view.view = river_view.view * glm::inverse(placement);

  // The reflection each asks its host to draw (drawing nothing: the sky is reflected).
  ReflectionView mirrored[2];
  const ReflectionCallback keep = [](VkCommandBuffer, const ReflectionView& view, void* user) {
    *static_cast<ReflectionView*>(user) = view;
  };
  CreateInfo info = bare_info(*context_);
  info.reflection = keep;
  std::unique_ptr<Renderer> placed;
  info.world_from_river = placement;
  info.reflection_user = &mirrored[0];
  ASSERT_TRUE(Renderer::create(info, &placed).ok());
  const Result a = render(*placed, 4, [&](uint32_t) { return world_view; });

  info.world_from_river = glm::mat4(1.0f);
  info.reflection_user = &mirrored[1];
  std::unique_ptr<Renderer> plain;
  ASSERT_TRUE(Renderer::create(info, &plain).ok());
  const Result b = render(*plain, 4, [&](uint32_t) { return river_view; });

  // The placed river's reflection, in the host's world, is the plain one's carried there: the
  // same clip position and side of the clip plane for each river point, the camera moved along.
  glm::mat4 world_mirror, river_mirror;
  std::memcpy(&world_mirror[0][0], mirrored[0].view_proj, sizeof(world_mirror));
  std::memcpy(&river_mirror[0][0], mirrored[1].view_proj, sizeof(river_mirror));
  const glm::vec4 world_plane = glm::make_vec4(mirrored[0].clip_plane);
  const glm::vec4 river_plane = glm::make_vec4(mirrored[1].clip_plane);
  for (const glm::vec3 p : {glm::vec3(0.0f, 2.0f, 10.0f), glm::vec3(-5.0f, -1.0f, 30.0f),
                            glm::vec3(8.0f, 0.5f, -20.0f)}) {
    const glm::vec4 in_world = placement * glm::vec4(p, 1.0f);
    const glm::vec4 expected = river_mirror * glm::vec4(p, 1.0f);
    const glm::vec4 got = world_mirror * in_world;
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(got[c], expected[c], 1e-3f * (1.0f + std::abs(expected[c])));
    EXPECT_NEAR(glm::dot(world_plane, in_world), glm::dot(river_plane, glm::vec4(p, 1.0f)), 1e-3f);
  }
  const glm::vec3 camera =
      glm::vec3(placement * glm::vec4(glm::make_vec3(mirrored[1].camera_position), 1.0f));
  const glm::vec3 placed_camera = glm::make_vec3(mirrored[0].camera_position);
  EXPECT_LT(glm::distance(camera, placed_camera), 1e-3f);

  size_t water = 0, differ = 0;
  for (size_t i = 0; i < a.mask.size(); ++i) water += a.mask[i] > 0.5f ? 1 : 0;
  EXPECT_GT(water, a.mask.size() / 10);
  for (size_t i = 0; i < a.rgba.size(); ++i) differ += std::abs(a.rgba[i] - b.rgba[i]) > 4e-3f;
  EXPECT_LT(differ, a.rgba.size() / 1000) << differ << " channels differ";

  // Every water pixel's surface point, from the depth the water wrote, lies in river_bounds().
  const Renderer::Bounds bounds = placed->river_bounds();
  const glm::mat4 to_world = glm::inverse(world_view.projection * world_view.view);
  const glm::vec3 slack = 0.01f * (bounds.max - bounds.min) + 0.05f;
  size_t outside = 0, unwritten = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      const size_t i = size_t{y} * kWidth + x;
      if (a.mask[i] < 0.5f) continue;
      unwritten += a.depth[i] >= 1.0f ? 1 : 0;
      const glm::vec4 ndc(2.0f * (x + 0.5f) / kWidth - 1.0f, 2.0f * (y + 0.5f) / kHeight - 1.0f,
                          a.depth[i], 1.0f);
      const glm::vec4 h = to_world * ndc;
      const glm::vec3 p = glm::vec3(h) / h.w;
      const bool in = glm::all(glm::greaterThanEqual(p, bounds.min - slack)) &&
                      glm::all(glm::lessThanEqual(p, bounds.max + slack));
      outside += in ? 0 : 1;
    }
  }
  EXPECT_EQ(unwritten, 0u) << "write_depth leaves the water's depth in the host's";
  EXPECT_EQ(outside, 0u);
  // Up is world +Z: the box is thin in z (the river's fall) and long in x and y.
  EXPECT_LT(bounds.max.z - bounds.min.z, 0.25f * (bounds.max.y - bounds.min.y));
}

TEST_F(BareHostTest, DefaultRiverLiesWhereTheReadmeSays) {
  std::unique_ptr<Renderer> renderer;
  ASSERT_TRUE(Renderer::create(bare_info(*context_), &renderer).ok());
  const Renderer::Bounds b = renderer->river_bounds();
  // docs/embedding.md, "Space": level at y = 0, x -20.7 .. 19.0, z -122.2 .. 123.0.
  EXPECT_NEAR(b.min.x, -20.7f, 0.1f);
  EXPECT_NEAR(b.max.x, 19.0f, 0.1f);
  EXPECT_NEAR(b.min.y, 0.0f, 1e-3f);
  EXPECT_NEAR(b.max.y, 0.0f, 1e-3f);
  EXPECT_NEAR(b.min.z, -122.2f, 0.1f);
  EXPECT_NEAR(b.max.z, 123.0f, 0.1f);
}

TEST_F(BareHostTest, BadPlacementJitterAndScissorAreRefusedByName) {
  CreateInfo info = bare_info(*context_);
  info.world_from_river = glm::mat4(0.0f);
  info.world_from_river[3][3] = 1.0f;
  std::unique_ptr<Renderer> renderer;
  EXPECT_EQ(Renderer::create(info, &renderer).message(),
            "siviflow::Renderer: CreateInfo::world_from_river [0 0 0 0] [0 0 0 0] [0 0 0 0] "
            "[0 0 0 1] is not a finite, invertible affine transform (last row 0 0 0 1)");
  info.world_from_river = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 3.4e38f, 0.0f));
  EXPECT_EQ(Renderer::create(info, &renderer).message(),
            "siviflow::Renderer: CreateInfo::world_from_river's translation (0, 3.4e+38, 0) lies "
            "beyond the world limit of ±1e+06 m");
  info.world_from_river = glm::scale(glm::mat4(1.0f), glm::vec3(1e30f, 1.0f, 1.0f));
  EXPECT_EQ(Renderer::create(info, &renderer).message(),
            "siviflow::Renderer: CreateInfo::world_from_river scales axis 0 by 1e+30: a placement "
            "(a rotation, at most a moderate scale) keeps each axis's scale within [1/1000, 1000]");
  info.world_from_river = glm::mat4(1.0f);
  info.motion_format = VK_FORMAT_R8_UNORM;
  EXPECT_EQ(Renderer::create(info, &renderer).message(),
            "siviflow::Renderer: CreateInfo::motion_format VK_FORMAT_R8_UNORM is not "
            "VK_FORMAT_R16G16_SFLOAT or VK_FORMAT_R32G32_SFLOAT");
  info.motion_format = VK_FORMAT_R16G16_SFLOAT;
  ASSERT_TRUE(Renderer::create(info, &renderer).ok());

  View view = camera_view(Camera{}, {kWidth, kHeight});
  View bad = view;
  bad.jitter = {std::nanf(""), 0.0f};
  ASSERT_TRUE(renderer->begin_frame(0).ok());
  EXPECT_EQ(renderer->update(bad, 0.0).message(),
            "siviflow::Renderer: View::jitter (nan, 0) is not a finite offset within 64 pixels");
  bad = view;
  bad.jitter = {0.25f, 100.0f};
  EXPECT_FALSE(renderer->update(bad, 0.0).ok());
  bad = view;
  bad.scissor = {{300, 0}, {40, 10}};
  EXPECT_EQ(renderer->update(bad, 0.0).message(),
            "siviflow::Renderer: View::scissor (300, 0) + 40x10 is not inside the viewport "
            "(0, 0) + 320x180");
  EXPECT_EQ(renderer->next_frame(), 0u) << "a refused view advances nothing";
  ASSERT_TRUE(renderer->update(view, 0.0).ok());
  EXPECT_EQ(renderer->begin_frame(0).message(),
            "siviflow::Renderer: begin_frame called again before record: record the updated "
            "frame, or abandon_frame() it");

  // The motion image the configuration asks for: its format, size and usage checked by name.
  HostTargets targets;
  ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
  ASSERT_TRUE(create_temporal_targets(*context_, VK_FORMAT_R16G16_SFLOAT, VK_FORMAT_UNDEFINED,
                                      {kWidth, kHeight}, &targets)
                  .ok());
  HostBuffer buffers[3];
  const ReadbackImage images[3] = {ReadbackImage::kColor, ReadbackImage::kDepth,
                                   ReadbackImage::kWaterMask};
  FrameInputs inputs;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(
        context_->create_readback_buffer(renderer->readback_bytes(images[i]), &buffers[i]).ok());
    inputs.readback[images[i]] = buffers[i].buffer;
  }
  inputs.color = targets.color;
  inputs.depth = targets.depth;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  ASSERT_TRUE(context_->begin_slot(0, &cmd).ok());
  inputs.motion = targets.motion;
  inputs.motion.format = VK_FORMAT_R32G32_SFLOAT;
  EXPECT_EQ(renderer->record(cmd, inputs).message(),
            "siviflow::Renderer: FrameInputs::motion.format VK_FORMAT_R32G32_SFLOAT differs from "
            "the configured VK_FORMAT_R16G16_SFLOAT");
  inputs.motion = targets.motion;
  inputs.motion.extent = {kWidth, kHeight / 2};
  EXPECT_EQ(renderer->record(cmd, inputs).message(),
            "siviflow::Renderer: FrameInputs::motion.extent 320x90 does not contain the view's "
            "viewport (0, 0) + 320x180");
  inputs.motion = targets.motion;
  inputs.motion.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  EXPECT_EQ(renderer->record(cmd, inputs).message(),
            "siviflow::Renderer: FrameInputs::motion.usage VK_IMAGE_USAGE_TRANSFER_SRC_BIT | "
            "VK_IMAGE_USAGE_SAMPLED_BIT lacks VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT");
  inputs.motion = targets.motion;
  Status status = renderer->record(cmd, inputs);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(renderer->record(cmd, inputs).message(),
            "siviflow::Renderer: record called twice for one frame: begin_frame and update start "
            "the next");
  ASSERT_TRUE(context_->end_slot_and_submit(0).ok());
  ASSERT_TRUE(context_->wait_slot(0).ok());
}

}  // namespace
}  // namespace siviflow::testing
