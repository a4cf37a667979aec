#include "frame_encoder.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "renderer_inspect.h"
#include "shaders/shared.h"
#include "sim/half_float.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

// Window depth (0 near .. 1 far, glm::perspectiveRH_ZO) to distance along the view axis.
// In doubles: far from the camera, window depth + a cancels to a few significant bits.
float linear_depth(float window_depth, float near_plane, float far_plane) {
  if (window_depth >= 1.0f) return std::numeric_limits<float>::infinity();
  const double a = double{far_plane} / (double{near_plane} - far_plane);
  const double b = double{far_plane} * near_plane / (double{near_plane} - far_plane);
  return static_cast<float>(b / (window_depth + a));
}

// The frame's camera in OpenEXR's conventions (siviflow/image_files.h, ExrCamera).
ExrCamera exr_camera(const Camera& camera, VkExtent2D extent) {
  const View view = camera_view(camera, extent);
  // Our view space looks down -Z; OpenEXR's camera space looks down +Z, x right, y up.
  const glm::mat4 world_to_camera = glm::scale(glm::mat4(1.0f), {1.0f, 1.0f, -1.0f}) * view.view;
  // Vulkan clip space (x right, y down, -1..1) to NDC (0..1 from the top-left corner).
  const glm::mat4 clip_to_ndc = glm::translate(glm::mat4(1.0f), {0.5f, 0.5f, 0.0f}) *
                                glm::scale(glm::mat4(1.0f), {0.5f, 0.5f, 1.0f});
  const glm::mat4 world_to_ndc = clip_to_ndc * view.projection * view.view;
  ExrCamera out;
  out.present = true;
  std::memcpy(out.world_to_camera, &world_to_camera[0][0], sizeof(out.world_to_camera));
  std::memcpy(out.world_to_ndc, &world_to_ndc[0][0], sizeof(out.world_to_ndc));
  out.fov_y_deg = camera.fov_y_deg;
  out.near_plane = camera.near_plane;
  out.far_plane = camera.far_plane;
  return out;
}

// `values` as half bits in `halves` (resized), rounded to nearest even.
void convert_to_halves(const std::vector<float>& values, std::vector<uint16_t>* halves) {
  halves->resize(values.size());
  to_halves(values, *halves);
}

std::vector<uint32_t> texel_columns(uint32_t width, uint32_t texel_px) {
  std::vector<uint32_t> columns(width);
  for (uint32_t x = 0; x < width; ++x) columns[x] = x / texel_px;
  return columns;
}

// id,state,sx,sy,...: one row per particle of the frame.
std::string particles_csv(const std::vector<Particle>& particles) {
  std::string csv = "id,state,sx,sy,wx,wy,wz,fx,fy,fz,speed,depth,slope,fade\n";
  char row[512];
  for (const Particle& p : particles) {
    std::snprintf(row, sizeof(row), "%u,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                  p.id, to_string(p.state), p.screen.x, p.screen.y, p.world.x, p.world.y, p.world.z,
                  p.flow.x, p.flow.y, p.flow.z, p.speed, p.depth, p.slope, p.fade);
    csv += row;
  }
  return csv;
}

}  // namespace

FrameEncoder::FrameEncoder(const CaptureOptions& options, const FlowTextureLayout& layout)
    : options_(options), layout_(layout),
      texel_column_(texel_columns(options.size.width, layout.texel_px)) {}

Status FrameEncoder::encode(const FinishedFrame& finished, EncodedFrame* out) {
  const uint32_t width = options_.size.width;
  const uint32_t height = options_.size.height;
  const size_t pixels = size_t{width} * height;
  // Each layer's compression suits its data (why, with figures: docs/output.md).
  ExrFrame frame;
  frame.width = static_cast<int>(width);
  frame.height = static_cast<int>(height);
  frame.rgba_half = finished.color_halves.data();  // half as rendered: no rounding anywhere
  frame.rgba_compression = ExrCompression::kPiz;
  if (options_.depth_aov) {
    depth_.resize(pixels);
    const Camera& camera = finished.camera;
    for (size_t i = 0; i < pixels; ++i) {
      depth_[i] = linear_depth(finished.window_depth[i], camera.near_plane, camera.far_plane);
    }
    // Depth's low mantissa bytes are noise: deflate packs it to half of RLE's size but costs a
    // 1080p capture 50 ms a frame more (docs/output.md).
    frame.layers.push_back({"depth", ExrCompression::kRle, {{kDepthChannel, depth_.data()}}});
  }
  if (options_.flow_aov || options_.particles_aov) decode_flow_texture(finished.flow_texture);
  // The flow texture upsampled (nearest) to the output: the texel under each pixel, on visible
  // water only (a texel reaches past the water's edge).
  const auto for_each_water_pixel = [&](auto&& visit) {
    for (uint32_t y = 0; y < height; ++y) {
      const size_t texel_row = size_t{y / layout_.texel_px} * layout_.flow_extent.x;
      for (uint32_t x = 0; x < width; ++x) {
        const size_t pixel = size_t{y} * width + x;
        if (finished.water_mask[pixel] > 0.5f) visit(pixel, texel_row + texel_column_[x]);
      }
    }
  };
  // Every water layer and the motion are HALF, which keeps what they hold (docs/output.md); depth
  // stays FLOAT, as half would place a point a kilometre away to half a metre.
  if (water_layers(options_)) {
    convert_to_halves(finished.water_mask, &water_);
    frame.layers.push_back(
        {"water", ExrCompression::kZip, {{.name = kWaterMaskChannel, .halves = water_.data()}}});
  }
  // Flow, mask and ids are constant over texels and regions: deflate finds the repeated rows.
  if (options_.flow_aov) {
    for (std::vector<uint16_t>& plane : flow_) plane.assign(pixels, 0);
    for_each_water_pixel([&](size_t pixel, size_t texel) {
      for (int c = 0; c < 3; ++c) flow_[c][pixel] = texel_flow_[texel][c];
    });
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{"flow", ExrCompression::kZip, {}});
    for (int c = 0; c < 3; ++c) {
      layer.channels.push_back({.name = kFlowChannels[c], .halves = flow_[c].data()});
    }
  }
  if (options_.particles_aov) {
    // The flow texture holds GPU slots; the layer and the CSV use the ids unique over the run.
    std::vector<uint32_t> id_of_slot(size_t{layout_.slot_count} + 1, kNoParticleId);
    for (const Particle& particle : finished.particles) id_of_slot[particle.slot] = particle.id;
    particle_id_.assign(pixels, kNoParticleId);
    for_each_water_pixel([&](size_t pixel, size_t texel) {
      const uint32_t slot = texel_slot_[texel];
      if (slot <= layout_.slot_count) particle_id_[pixel] = id_of_slot[slot];
    });
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{"particle", ExrCompression::kZip, {}});
    layer.channels.push_back({.name = kParticleIdChannel, .ids = particle_id_.data()});
  }
  // The water's own layers are zero off the water, which RLE packs as well as deflate does, and
  // their noisy low mantissa bytes on it defeat deflate: RLE at a third of its time.
  const auto add_rgb = [&](const char* name, const std::vector<uint16_t>& rgba,
                           const char* const channels[3]) {
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{name, ExrCompression::kRle, {}});
    for (int c = 0; c < 3; ++c) {
      layer.channels.push_back({.name = channels[c], .stride = 4, .halves = rgba.data() + c});
    }
  };
  if (options_.normal_aov) add_rgb("normal", finished.normal, kNormalChannels);
  if (options_.reflection_aov) add_rgb("reflection", finished.reflection, kReflectionChannels);
  if (options_.foam_aov) {
    frame.layers.push_back(
        {"foam", ExrCompression::kZip, {{.name = kFoamChannel, .halves = finished.foam.data()}}});
  }
  if (options_.motion_aov) {
    const VkExtent2D extent{width, height};
    MotionFrame motion;
    motion.width = width;
    motion.height = height;
    motion.window_depth = finished.window_depth.data();
    motion.water_mask = finished.water_mask.data();
    motion.previous = camera_view(finished.previous_camera, extent);
    motion.current = camera_view(finished.camera, extent);
    motion.next = camera_view(finished.next_camera, extent);
    motion.bodies = finished.bodies;
    compute_motion(motion, &motion_);
    convert_to_halves(motion_, &motion_halves_);
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{"motion", ExrCompression::kZip, {}});
    for (int c = 0; c < 4; ++c) {
      layer.channels.push_back(
          {.name = kMotionChannels[c], .stride = 4, .halves = motion_halves_.data() + c});
    }
  }
  frame.metadata.scene = options_.scene_path.empty() ? "default" : options_.scene_path;
  frame.metadata.frame = static_cast<int>(finished.frame);
  frame.metadata.time_seconds = static_cast<float>(finished.frame / options_.fps);
  frame.metadata.seed = static_cast<int>(options_.seed);
  frame.metadata.software_version = version_string();
  frame.metadata.frames_per_second = options_.fps;
  frame.metadata.camera = exr_camera(finished.camera, {width, height});
  frame.metadata.scene_digest = options_.scene_digest;
  frame.metadata.fps = options_.fps;
  frame.metadata.aovs = aov_names(options_);

  out->frame = finished.frame;
  SIVIFLOW_TRY(encode_exr(frame, &out->exr));
  out->particles_csv.clear();
  if (options_.particles_aov) out->particles_csv = particles_csv(finished.particles);
  out->preview.clear();
  if (options_.preview) {
    rgba_.resize(pixels * 4);
    for (size_t i = 0; i < pixels * 4; ++i) {
      rgba_[i] = glm::unpackHalf1x16(finished.color_halves[i]);
    }
    SIVIFLOW_TRY(
        encode_png(frame.width, frame.height, rgba_.data(), PngChannels::kRgb, &out->preview));
  }
  return Status::success();
}

void FrameEncoder::decode_flow_texture(const std::vector<std::byte>& flow_texture) {
  const size_t texels = size_t{layout_.flow_extent.x} * layout_.flow_extent.y;
  texel_flow_.resize(texels);
  texel_slot_.resize(texels);
  for (size_t t = 0; t < texels; ++t) {
    gpu::FlowTexel texel{};
    std::memcpy(&texel, flow_texture.data() + t * sizeof(texel), sizeof(texel));
    texel_slot_[t] = texel.id;
    texel_flow_[t] = {texel.flow_x, texel.flow_y, texel.flow_z};
    if (texel.id == SIVIFLOW_PARTICLE_NONE) texel_flow_[t] = {0, 0, 0};
  }
}

}  // namespace siviflow
