#include "frame_encoder.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include <glm/gtc/packing.hpp>

#include "renderer_inspect.h"
#include "shaders/shared.h"
#include "siviflow/image_files.h"

namespace siviflow {
namespace {

// Window depth (0 near .. 1 far, glm::perspectiveRH_ZO) to distance along the view axis.
float linear_depth(float window_depth, float near_plane, float far_plane) {
  if (window_depth >= 1.0f) return std::numeric_limits<float>::infinity();
  const float a = far_plane / (near_plane - far_plane);
  const float b = far_plane * near_plane / (near_plane - far_plane);
  return b / (window_depth + a);
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
  // Each layer's compression suits its data (why, with figures: the README's capture section).
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
    frame.layers.push_back({"depth", ExrCompression::kZip, {{"depth.Z", depth_.data()}}});
  }
  if (options_.flow_aov || options_.particles_aov) decode_flow_texture(finished.flow_texture);
  // The flow texture upsampled (nearest) to the output: the texel under each pixel.
  const auto for_each_pixel = [&](auto&& visit) {
    for (uint32_t y = 0; y < height; ++y) {
      const size_t texel_row = size_t{y / layout_.texel_px} * layout_.flow_extent.x;
      for (uint32_t x = 0; x < width; ++x) {
        visit(size_t{y} * width + x, texel_row + texel_column_[x]);
      }
    }
  };
  // Flow, mask and ids are constant over texels and regions: deflate finds the repeated rows.
  if (options_.flow_aov) {
    for (std::vector<float>& plane : flow_) plane.resize(pixels);
    for_each_pixel([&](size_t pixel, size_t texel) {
      for (int c = 0; c < 3; ++c) flow_[c][pixel] = texel_flow_[texel][c];
    });
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{"flow", ExrCompression::kZip, {}});
    for (int c = 0; c < 3; ++c) layer.channels.push_back({kFlowChannels[c], flow_[c].data()});
    frame.layers.push_back(
        {"water", ExrCompression::kZip, {{"water.mask", finished.water_mask.data()}}});
  }
  if (options_.particles_aov) {
    // The flow texture holds GPU slots; the layer and the CSV use the ids unique over the run.
    std::vector<float> id_of_slot(size_t{layout_.slot_count} + 1, -1.0f);
    for (const Particle& particle : finished.particles) {
      id_of_slot[particle.slot] = static_cast<float>(particle.id);
    }
    particle_id_.resize(pixels);
    for_each_pixel([&](size_t pixel, size_t texel) {
      const uint32_t slot = texel_slot_[texel];
      const bool on_water = finished.water_mask[pixel] > 0.5f;
      particle_id_[pixel] = on_water && slot <= layout_.slot_count ? id_of_slot[slot] : -1.0f;
    });
    frame.layers.push_back(
        {"particle", ExrCompression::kZip, {{"particle.id", particle_id_.data()}}});
  }
  // The water's own layers are zero off the water, which RLE packs as well as deflate does, and
  // their noisy low mantissa bytes on it defeat deflate: RLE at a third of its time.
  const auto add_rgb = [&](const char* name, const std::vector<float>& rgba,
                           const char* const channels[3]) {
    ExrLayer& layer = frame.layers.emplace_back(ExrLayer{name, ExrCompression::kRle, {}});
    for (int c = 0; c < 3; ++c) layer.channels.push_back({channels[c], rgba.data() + c, 4});
  };
  if (options_.normal_aov) add_rgb("normal", finished.normal, kNormalChannels);
  if (options_.reflection_aov) add_rgb("reflection", finished.reflection, kReflectionChannels);
  if (options_.foam_aov) {
    frame.layers.push_back({"foam", ExrCompression::kZip, {{"foam.Y", finished.foam.data()}}});
  }
  frame.metadata.scene = options_.scene_path.empty() ? "default" : options_.scene_path;
  frame.metadata.frame = static_cast<int>(finished.frame);
  frame.metadata.time_seconds = static_cast<float>(finished.frame / options_.fps);
  frame.metadata.seed = static_cast<int>(options_.seed);
  frame.metadata.software_version = version_string();
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
    texel_flow_[t] = texel.id == SIVIFLOW_PARTICLE_NONE ? glm::vec3(0.0f) : decode_flow(texel);
  }
}

}  // namespace siviflow
