// Flow Texture Mapper (paper §3.2, Algorithm 2 lines 10-11): packs the particles of a frame into
// the flow texture (per texel: the id of the nearest particle and its flow vector) and the
// auxiliary data addressed by that id (speed, depth, foam, fade), as plain bytes in a caller-
// provided block (the frame slot's staging block). shaders/shared.h documents every channel;
// FlowTextureLayout says where each image's texels start, row-major, tightly packed (the
// bufferRowLength = 0 of vkCmdCopyBufferToImage).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "shaders/shared.h"
#include "sim/half_float.h"
#include "sim/particle_tuning.h"
#include "sim/particles.h"
#include "siviflow/status.h"

namespace siviflow {

struct FlowTextureLayout {
  glm::uvec2 viewport{0u};
  uint32_t texel_px = 0;         // screen pixels per flow texel side
  glm::uvec2 flow_extent{0u};    // ceil(viewport / texel_px), R16G16B16A16_UINT
  glm::uvec2 aux_extent{0u};     // SIVIFLOW_AUX_WIDTH x rows, R32G32B32A32_SFLOAT
  uint32_t slot_count = 0;       // ids run 1..slot_count
  size_t flow_offset = 0;        // bytes into the staging block
  size_t flow_bytes = 0;
  size_t aux_offset = 0;         // a multiple of kStagingBlockAlignment
  size_t aux_bytes = 0;
  size_t total_bytes = 0;        // what the staging block must hold
};

// Fixed for a configuration (viewport, texel size, slot count): the images can be created once.
Status make_flow_texture_layout(glm::uvec2 viewport, uint32_t texel_px, uint32_t slot_count,
                                FlowTextureLayout* out);

class FlowTextures {
 public:
  // Scratch is sized by the flow texture (the screen), never by the river.
  static Status create(const FlowTextureLayout& layout, FlowTextures* out);
  // The layout of a field's viewport and slots, at `texel_px` pixels per texel.
  static Status create(const ParticleField& field, uint32_t texel_px, FlowTextures* out);
  const FlowTextureLayout& layout() const { return layout_; }

  // Writes the whole block [0, layout().total_bytes) of `staging` (every byte, padding zeroed).
  // A texel takes the particle nearest to its centre (any state; exact up to float rounding at
  // the cell borders) within cover_radius_px, else id 0. Fails, writing nothing, when `staging`
  // is too small, an id is 0 or above slot_count, an id repeats, or a position is not finite.
  Status pack(std::span<const Particle> particles, float cover_radius_px,
              std::span<std::byte> staging);
  // The same with the field's particles and cover radius kFlowCoverRadiusFactor x cover_radius_px().
  Status pack(const ParticleField& field, std::span<std::byte> staging);

 private:
  FlowTextureLayout layout_;
  struct Parabola {
    float u;        // texel column of the particle
    float c;        // squared row distance to it
    uint16_t slot;  // its id
  };
  // Scratch, sized by the screen and the particle count (never by the river).
  std::vector<uint32_t> order_;            // particles by screen x
  std::vector<uint32_t> row_start_;        // per row: first entry of row_items_
  std::vector<uint32_t> row_fill_;
  std::vector<Parabola> row_items_;        // particles reaching each row, in x order
  std::vector<Parabola> env_;              // a row's lower envelope
  std::vector<float> z_;                   // where each envelope parabola starts owning
  std::vector<gpu::FlowTexel> texel_of_;   // per id: the packed flow texel
  std::vector<uint8_t> seen_;              // per id: duplicate check
};

// Decoding, for tests and dumps (the GPU reads the same bytes).
Status read_flow_texel(std::span<const std::byte> staging, const FlowTextureLayout& layout,
                       uint32_t x, uint32_t y, gpu::FlowTexel* out);
Status read_particle_aux(std::span<const std::byte> staging, const FlowTextureLayout& layout,
                         uint32_t id, gpu::ParticleAux* out);
glm::vec3 decode_flow(const gpu::FlowTexel& texel);

}  // namespace siviflow
