// The renderer inside a host's frame, seen as the host sees it: a host's box standing in the
// river hides the water behind it and is covered by the water in front of its submerged part;
// every pixel off the water keeps the host's colour bit for bit; a deeper bed drawn by the host
// darkens the water; and the path a shipping host runs (no readback, no AOV attachments) matches
// the golden frame, with the host copying its own colour image.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "golden/golden_compare.h"
#include "gpu_test.h"
#include "run_command.h"
#include "scene/default_scene.h"
#include "siviflow/image_files.h"
#include "siviflow/scene_file.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kWidth = 320;
constexpr uint32_t kHeight = 180;
// Where the host leaves its colour: ready to be copied, as a host reading its frame back would.
constexpr ImageState kCopySource = {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                    VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};

// What one frame left in the host's images.
struct HostShot {
  std::vector<float> before;  // the host's colour before the water (RGBA, linear)
  std::vector<float> after;   // ... and after it
  std::vector<float> depth;   // with readback: the host's depth
  std::vector<float> mask;    // with readback: 1 where the water is the nearest thing seen
};

class HostEmbeddingTest : public GpuTest {
 protected:
  // The world of `world_scene` (null: the default scene) and the water of the default scene,
  // with the world's ground and objects as the water's occluders (as our tools give them).
  void create(const SceneFile* world_scene, bool readback, uint64_t seed = 0) {
    renderer_.reset();
    world_.reset();
    read_back_ = readback;
    WorldCreateInfo world_info =
        context_->world_create_info(VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT);
    world_info.scene = world_scene;
    Status status = World::create(world_info, &world_);
    ASSERT_TRUE(status.ok()) << status.message();
    CreateInfo info = make_create_info(kWidth, kHeight);
    info.readback_images = readback ? readback_bit(ReadbackImage::kDepth) |
                                          readback_bit(ReadbackImage::kWaterMask)
                                    : 0;
    info.seed = seed;
    info.reflection = &World::draw_reflection;
    info.reflection_user = world_.get();
    status = Renderer::create(info, &renderer_);
    if (status.ok()) status = renderer_->set_occluders(world_->occluders());
    ASSERT_TRUE(status.ok()) << status.message();
  }

  // One frame: the world, a copy of the host's colour, the water, a copy again.
  HostShot shoot(const View& view, double time) {
    HostShot shot;
    HostImage color_image;
    HostImage depth_image;
    EXPECT_TRUE(context_->create_target_image(VK_FORMAT_R16G16B16A16_SFLOAT, {kWidth, kHeight},
                                              &color_image).ok());
    EXPECT_TRUE(context_->create_depth_image(VK_FORMAT_D32_SFLOAT, {kWidth, kHeight},
                                             &depth_image).ok());
    const VkDeviceSize color_bytes = renderer_->readback_bytes(ReadbackImage::kColor);
    HostBuffer before;
    HostBuffer after;
    EXPECT_TRUE(context_->create_readback_buffer(color_bytes, &before).ok());
    EXPECT_TRUE(context_->create_readback_buffer(color_bytes, &after).ok());
    HostBuffer readback[kReadbackImageCount];
    ReadbackTargets targets;
    const bool reads_back = read_back_;
    if (reads_back) {  // only the two images asked for
      for (const ReadbackImage kind : {ReadbackImage::kDepth, ReadbackImage::kWaterMask}) {
        const auto i = static_cast<uint32_t>(kind);
        EXPECT_TRUE(context_->create_readback_buffer(renderer_->readback_bytes(kind), &readback[i]).ok());
        targets.buffers[i] = readback[i].buffer;
      }
    }
    const auto copy_image = reinterpret_cast<PFN_vkCmdCopyImageToBuffer>(
        context_->get_device_proc_addr()(context_->device(), "vkCmdCopyImageToBuffer"));
    EXPECT_NE(copy_image, nullptr);
    if (copy_image == nullptr) return shot;
    const auto copy = [&](VkCommandBuffer cmd, const HostBuffer& into) {
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {kWidth, kHeight, 1};
      copy_image(cmd, color_image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, into.buffer, 1,
                 &region);
    };

    VkCommandBuffer cmd = VK_NULL_HANDLE;
    EXPECT_TRUE(context_->begin_slot(0, &cmd).ok());
    EXPECT_TRUE(renderer_->begin_frame(0).ok());
    Status status = renderer_->update(view, time);
    EXPECT_TRUE(status.ok()) << status.message();
    ExternalImage color{color_image.image, color_image.view, VK_FORMAT_R16G16B16A16_SFLOAT,
                        {kWidth, kHeight}, ImageState{}, kCopySource, color_image.usage};
    ExternalImage depth{depth_image.image, depth_image.view, VK_FORMAT_D32_SFLOAT,
                        {kWidth, kHeight}, ImageState{},
                        {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                         VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL},
                        depth_image.usage};
    EXPECT_TRUE(world_->begin_frame(0).ok());
    status = world_->record(cmd, view, time, color, depth);
    EXPECT_TRUE(status.ok()) << status.message();
    copy(cmd, before);
    FrameInputs inputs;
    inputs.color = color;
    inputs.color.current = kCopySource;
    inputs.depth = depth;
    inputs.depth.current = depth.final;
    inputs.depth.final = {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                          VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL};
    inputs.readback = targets;
    status = renderer_->record(cmd, inputs);
    EXPECT_TRUE(status.ok()) << status.message();
    copy(cmd, after);
    EXPECT_TRUE(context_->end_slot_and_submit(0).ok());
    EXPECT_TRUE(context_->wait_slot(0).ok());

    const size_t pixels = size_t{kWidth} * kHeight;
    const auto unpack = [pixels](const HostBuffer& buffer) {
      std::vector<float> rgba(pixels * 4);
      const auto* halves = static_cast<const uint16_t*>(buffer.data);
      for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = glm::unpackHalf1x16(halves[i]);
      return rgba;
    };
    shot.before = unpack(before);
    shot.after = unpack(after);
    if (reads_back) {
      const auto* d = static_cast<const float*>(readback[static_cast<uint32_t>(ReadbackImage::kDepth)].data);
      shot.depth.assign(d, d + pixels);
      const auto* m = static_cast<const float*>(readback[static_cast<uint32_t>(ReadbackImage::kWaterMask)].data);
      shot.mask.assign(m, m + pixels);
    }
    return shot;
  }

  bool read_back_ = false;  // the renderer copies its images into readback buffers
};

// The default scene as a scene file, with `objects` standing in it.
SceneFile default_scene_file(std::vector<SceneObject> objects = {}) {
  SceneFile scene;
  scene.path = "host.json";
  scene.rivers[0].procedural = default_river_params();
  scene.obstacles = default_scene_obstacles(ProceduralRiver(default_river_params()));
  scene.objects = std::move(objects);
  return scene;
}

// The river's surface height nearest to (x, z).
float surface_height(const RiverMesh& mesh, float x, float z) {
  float best = INFINITY;
  float height = 0.0f;
  for (const glm::vec3& p : mesh.positions) {
    const float d = glm::length(glm::vec2(p.x - x, p.z - z));
    if (d < best) {
      best = d;
      height = p.y;
    }
  }
  return height;
}

// Pixels off the water whose colour the water pass changed.
size_t dry_pixels_changed(const HostShot& shot) {
  size_t changed = 0;
  for (size_t i = 0; i < shot.mask.size(); ++i) {
    if (shot.mask[i] == 0.0f &&
        std::memcmp(&shot.before[i * 4], &shot.after[i * 4], 4 * sizeof(float)) != 0) {
      ++changed;
    }
  }
  return changed;
}

TEST_F(HostEmbeddingTest, HostBoxHidesTheWaterBehindItAndKeepsEveryDryPixel) {
  const ProceduralRiver river(default_river_params());
  RiverMesh mesh;
  ASSERT_TRUE(river.generate_mesh(&mesh).ok());
  const float z = 0.0f;
  const glm::vec3 at(river.centreline_x(z), surface_height(mesh, river.centreline_x(z), z), z);
  const fs::path dir = fresh_test_dir("host_embedding");
  write_box_gltf(dir / "box.gltf", {1.2f, 2.0f, 1.2f});  // 2 m under the water, 2 m above
  SceneObject box;
  box.gltf = (dir / "box.gltf").string();
  box.translation = at;
  Camera camera;
  camera.position = at + glm::vec3(-3.0f, 3.5f, -14.0f);
  camera.target = at;
  const View view = camera_view(camera, {kWidth, kHeight});

  const SceneFile with_box = default_scene_file({box});
  create(&with_box, true);
  const HostShot boxed = shoot(view, 0.0);
  const SceneFile without_box = default_scene_file();
  create(&without_box, true);
  const HostShot open = shoot(view, 0.0);
  ASSERT_FALSE(boxed.mask.empty());
  ASSERT_FALSE(open.mask.empty());

  EXPECT_EQ(dry_pixels_changed(boxed), 0u) << "the host's colour off the water is untouched";
  EXPECT_EQ(dry_pixels_changed(open), 0u);
  size_t box_pixels = 0, hidden = 0, over_box = 0;
  for (size_t i = 0; i < boxed.mask.size(); ++i) {
    if (boxed.depth[i] == open.depth[i]) continue;  // the box does not show here
    ++box_pixels;
    if (open.mask[i] == 1.0f && boxed.mask[i] == 0.0f) ++hidden;  // water behind the box
    if (boxed.mask[i] == 1.0f) ++over_box;  // water in front of the box's submerged part
  }
  EXPECT_GT(box_pixels, 1000u) << "the box fills the middle of the view";
  EXPECT_GT(hidden, 200u) << "the box hides the water behind it";
  EXPECT_GT(over_box, 100u) << "the water covers the part of the box below it";
}

double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

TEST_F(HostEmbeddingTest, DeeperHostBedDarkensTheWater) {
  // The same water over beds the host draws 0.4 m and 4 m deep: the path through the water,
  // read from the host's depth, takes the colour from the bed's towards the deep colour.
  const View view = camera_view(default_camera(ProceduralRiver(default_river_params()), 1.0),
                                {kWidth, kHeight});
  HostShot shots[2];
  const float depths[2] = {0.4f, 4.0f};
  for (int i = 0; i < 2; ++i) {
    SceneFile scene = default_scene_file();
    scene.rivers[0].procedural.depth = depths[i];
    create(&scene, true);
    shots[i] = shoot(view, 1.0);
    ASSERT_FALSE(shots[i].mask.empty());
  }
  // Over the pixels that are water in both (a shallow bed's banks rise through the surface).
  double sum[2] = {};
  size_t water = 0, darker = 0;
  for (size_t p = 0; p < shots[0].mask.size(); ++p) {
    if (shots[0].mask[p] != 1.0f || shots[1].mask[p] != 1.0f) continue;
    ++water;
    const double shallow = luminance(&shots[0].after[p * 4]);
    const double deep = luminance(&shots[1].after[p * 4]);
    sum[0] += shallow;
    sum[1] += deep;
    darker += deep < shallow ? 1 : 0;
  }
  ASSERT_GT(water, 2000u);
  EXPECT_LT(sum[1], 0.8 * sum[0]) << "deep water is darker";
  EXPECT_GT(darker, water * 9 / 10) << "nearly everywhere";
}

TEST_F(HostEmbeddingTest, ShippingPathWithoutReadbackMatchesTheGoldenFrame) {
  // The host's own copy of its colour, the renderer with no readback and no AOV attachments:
  // frame 0 of the default scene as `siviflow capture --size 320x180` renders it (seed 1).
  create(nullptr, false, 1);
  const HostShot shot = shoot(camera_view(world_->scene_camera(0.0), {kWidth, kHeight}), 0.0);
  ASSERT_FALSE(shot.after.empty());
  const std::string graph = renderer_->dump_frame_graph();
  EXPECT_EQ(graph.find("readback"), std::string::npos) << graph;
  EXPECT_EQ(graph.find("water mask"), std::string::npos) << "no AOV attachments: " << graph;

  const fs::path dir = fresh_test_dir("shipping_path");
  ExrFrame frame;
  frame.width = kWidth;
  frame.height = kHeight;
  frame.rgba = shot.after.data();
  ASSERT_TRUE(write_exr((dir / "frame_00000.exr").string(), frame).ok());
  const fs::path golden = fs::path(SIVIFLOW_TEST_DATA_DIR).parent_path() / "golden" / "frame_00000.exr";
  GoldenTolerance beauty;
  beauty.beauty_only = true;
  const GoldenResult result = compare_with_golden((dir / "frame_00000.exr").string(), golden.string(),
                                                  (dir / "diff.png").string(), beauty);
  EXPECT_TRUE(result.pass) << result.message;
}

// A straight channel along +Z of its own, as an engine would describe its river: 7 vertices
// across 8 m, one section a metre, 1 m deep in mid-river.
struct Channel {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<float> depth;
  std::vector<float> slope;
  WaterRiver river() const {
    WaterRiver r;
    r.positions = positions;
    r.indices = indices;
    r.depth = depth;
    r.slope = slope;
    r.flow.discharge = 6.0f;
    return r;
  }
};

Channel straight_channel() {
  Channel c;
  constexpr int kSections = 60, kAcross = 7;
  for (int k = 0; k < kSections; ++k) {
    for (int j = 0; j < kAcross; ++j) {
      const float u = static_cast<float>(j) / (kAcross - 1);  // 0 on the left bank (+X)
      c.positions.push_back({4.0f - 8.0f * u, 0.0f, static_cast<float>(k)});
      c.depth.push_back(4.0f * u * (1.0f - u));
      c.slope.push_back(std::abs(4.0f * (1.0f - 2.0f * u)) / 8.0f);
    }
  }
  for (uint32_t k = 0; k + 1 < kSections; ++k) {
    for (uint32_t j = 0; j + 1 < kAcross; ++j) {
      const uint32_t a = k * kAcross + j, b = a + 1, d = a + kAcross, e = d + 1;
      c.indices.insert(c.indices.end(), {a, d, b, b, d, e});
    }
  }
  return c;
}

TEST_F(HostEmbeddingTest, HostsOwnRiverFlowsAndBadArraysAreRefusedByName) {
  // The world draws the default valley (any host world will do); the water is the host's
  // channel, which runs down +Z at Q / width = 0.75 m/s in mid-river or so.
  create(nullptr, true);
  const Channel channel = straight_channel();
  const WaterRiver river = channel.river();
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.readback_images = readback_bit(ReadbackImage::kDepth) | readback_bit(ReadbackImage::kWaterMask);
  info.reflection = &World::draw_reflection;
  info.reflection_user = world_.get();
  info.river = &river;
  Status status = Renderer::create(info, &renderer_);
  ASSERT_TRUE(status.ok()) << status.message();
  Camera camera;
  camera.position = {0.0f, 12.0f, -8.0f};
  camera.target = {0.0f, 0.0f, 20.0f};
  const HostShot shot = shoot(camera_view(camera, {kWidth, kHeight}), 0.0);
  size_t water = 0;
  for (const float m : shot.mask) water += m == 1.0f ? 1 : 0;
  EXPECT_GT(water, 1000u) << "the host's channel is drawn";
  EXPECT_EQ(renderer_->flow_solves(), 1u);

  const auto refused = [&](const WaterRiver& bad, const char* part) {
    CreateInfo bad_info = info;
    bad_info.river = &bad;
    std::unique_ptr<Renderer> renderer;
    const Status s = Renderer::create(bad_info, &renderer);
    ASSERT_FALSE(s.ok()) << part;
    EXPECT_NE(s.message().find(part), std::string::npos) << s.message();
    EXPECT_EQ(renderer, nullptr);
  };
  WaterRiver short_depth = river;
  short_depth.depth = short_depth.depth.first(10);
  refused(short_depth, "CreateInfo::river->depth has 10 values for 420 positions");
  Channel broken = channel;
  broken.positions[7].y = NAN;
  refused(broken.river(), "CreateInfo::river->positions[7] is not finite");
  broken = channel;
  broken.positions[8].x = 2.0e6f;
  refused(broken.river(), "CreateInfo::river->positions[8] (2e+06, ");
  broken = channel;
  broken.slope[3] = -1.0f;
  refused(broken.river(), "CreateInfo::river->slope[3] -1");
  WaterObstacle flat;
  flat.polygon = {{0.0f, 0.0f}, {1.0f, 0.0f}, {2.0f, 0.0f}};
  const WaterObstacle obstacles[] = {flat};
  WaterRiver with_flat = river;
  with_flat.obstacles = obstacles;
  refused(with_flat, "CreateInfo::river->obstacles: obstacle 0");
}

TEST_F(HostEmbeddingTest, WorldRefusesAnImageOfAnotherFormatNamingBothFormats) {
  create(nullptr, false);
  ExternalImage color;
  color.format = VK_FORMAT_B8G8R8A8_SRGB;
  ExternalImage depth;
  depth.format = VK_FORMAT_D32_SFLOAT;
  const View view = camera_view(Camera{}, {kWidth, kHeight});
  Status status = world_->record(VK_NULL_HANDLE, view, 0.0, color, depth);
  EXPECT_EQ(status.message(),
            "siviflow::World: the colour image's format VK_FORMAT_B8G8R8A8_SRGB differs from "
            "WorldCreateInfo's VK_FORMAT_R16G16B16A16_SFLOAT");
  color.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  depth.format = VK_FORMAT_D24_UNORM_S8_UINT;
  status = world_->record(VK_NULL_HANDLE, view, 0.0, color, depth);
  EXPECT_EQ(status.message(),
            "siviflow::World: the depth image's format VK_FORMAT_D24_UNORM_S8_UINT differs from "
            "WorldCreateInfo's VK_FORMAT_D32_SFLOAT");
}

}  // namespace
}  // namespace siviflow::testing
