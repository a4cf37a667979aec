// The capture's encoder: turns a finished frame into the bytes of its files (the EXR, a part per
// layer with the compression that suits it; the particle CSV and the PNG preview when asked).
// It keeps its scratch planes from frame to frame; each encoding thread has its own.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "capture_options.h"
#include "motion_vectors.h"
#include "sim/flow_textures.h"
#include "sim/particles.h"
#include "siviflow/renderer.h"
#include "siviflow/status.h"

namespace siviflow {

// A finished frame copied out of its readback buffers, so that the buffers can take the next
// frame while this one is encoded and written.
struct FinishedFrame {
  uint32_t frame = 0;
  Camera camera;
  // With the motion AOV: the cameras of the frames before and after, and the moving boulders
  // and floats.
  Camera previous_camera;
  Camera next_camera;
  std::vector<MovingBody> bodies;
  std::vector<uint16_t> color_halves;
  std::vector<float> window_depth;
  std::vector<float> water_mask;
  std::vector<std::byte> flow_texture;  // as uploaded: shaders/shared.h FlowTexel per texel
  std::vector<uint16_t> normal;         // RGBA halves per pixel
  std::vector<uint16_t> reflection;     // RGBA halves per pixel
  std::vector<uint16_t> foam;           // halves
  std::vector<Particle> particles;
};

// A frame's files, encoded: what is left is to write them.
struct EncodedFrame {
  uint32_t frame = 0;
  std::vector<char> exr;
  std::string particles_csv;           // empty unless the particles AOV is asked for
  std::vector<unsigned char> preview;  // PNG; empty unless --preview
};

class FrameEncoder {
 public:
  // `layout` is the renderer's flow texture layout (fixed for the capture).
  FrameEncoder(const CaptureOptions& options, const FlowTextureLayout& layout);

  // Encodes `finished` into `out` (its buffers reused).
  Status encode(const FinishedFrame& finished, EncodedFrame* out);

 private:
  // Each texel of the flow texture, decoded once: its flow and its particle slot.
  void decode_flow_texture(const std::vector<std::byte>& flow_texture);

  const CaptureOptions options_;
  const FlowTextureLayout layout_;
  const std::vector<uint32_t> texel_column_;  // the flow texel column under each pixel column
  // Scratch planes, reused from frame to frame.
  std::vector<float> rgba_;  // the preview's
  std::vector<float> depth_;
  std::vector<uint16_t> water_;  // halves, as every water layer and motion are written
  std::vector<uint16_t> flow_[3];
  std::vector<uint32_t> particle_id_;
  std::vector<float> motion_;
  std::vector<uint16_t> motion_halves_;
  std::vector<std::array<uint16_t, 3>> texel_flow_;  // the texture's own halves
  std::vector<uint32_t> texel_slot_;
};

}  // namespace siviflow
