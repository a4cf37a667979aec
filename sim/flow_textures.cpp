#include "sim/flow_textures.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace siviflow {
namespace {

// The staging bytes are read by the device as little-endian texels.
static_assert(std::endian::native == std::endian::little);
static_assert(kDefaultFlowTexelPx == SIVIFLOW_FLOW_TEXEL_PX);
static_assert(kMaxParticleSlots <= 0xffffu, "ids are 16-bit, 0 meaning none");

size_t align_up(size_t v, size_t a) { return (v + a - 1) / a * a; }

// Texels [x0, x1) of a row of the flow texture, all `t`.
void write_run(std::byte* row, int x0, int x1, const gpu::FlowTexel& t) {
  for (int x = x0; x < x1; ++x) {
    std::memcpy(row + static_cast<size_t>(x) * sizeof(gpu::FlowTexel), &t, sizeof t);
  }
}

// Floor and ceiling without libm (SSE2 has no rounding instruction).
int floor_int(float x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<float>(i));
}
int ceil_int(float x) {
  const int i = static_cast<int>(x);
  return i + (x > static_cast<float>(i));
}

// Particle positions are clamped to this many texels from the origin (beyond any texture).
constexpr float kFarTexels = 1e6f;

// Largest flow texture side accepted (a 16384-pixel output at 1 pixel per texel).
constexpr uint32_t kMaxFlowTextureSide = 16384;

}  // namespace

glm::vec3 decode_flow(const gpu::FlowTexel& t) {
  return {from_half(t.flow_x), from_half(t.flow_y), from_half(t.flow_z)};
}

Status make_flow_texture_layout(glm::uvec2 viewport, uint32_t texel_px, uint32_t slot_count,
                                FlowTextureLayout* out) {
  if (texel_px == 0) return Status::error("flow textures: texel_px must be >= 1");
  if (viewport.x == 0 || viewport.y == 0) return Status::error("flow textures: empty viewport");
  if (slot_count == 0 || slot_count > kMaxParticleSlots) {
    return Status::error("flow textures: slot_count must be in 1.." +
                         std::to_string(kMaxParticleSlots) + " (16-bit ids, 0 = none)");
  }
  FlowTextureLayout l;
  l.viewport = viewport;
  l.texel_px = texel_px;
  l.flow_extent = (viewport + (texel_px - 1u)) / texel_px;
  if (l.flow_extent.x > kMaxFlowTextureSide || l.flow_extent.y > kMaxFlowTextureSide) {
    return Status::error("flow textures: the flow texture would exceed " +
                         std::to_string(kMaxFlowTextureSide) + " texels a side");
  }
  l.aux_extent = {SIVIFLOW_AUX_WIDTH, (slot_count + 1u + SIVIFLOW_AUX_WIDTH - 1u) / SIVIFLOW_AUX_WIDTH};
  l.slot_count = slot_count;
  l.flow_offset = 0;
  l.flow_bytes = size_t{l.flow_extent.x} * l.flow_extent.y * sizeof(gpu::FlowTexel);
  l.aux_offset = align_up(l.flow_bytes, kStagingBlockAlignment);
  l.aux_bytes = size_t{l.aux_extent.x} * l.aux_extent.y * sizeof(gpu::ParticleAux);
  l.total_bytes = l.aux_offset + l.aux_bytes;
  *out = l;
  return Status::success();
}

Status FlowTextures::create(const FlowTextureLayout& layout, FlowTextures* out) {
  FlowTextureLayout check;
  SIVIFLOW_TRY(make_flow_texture_layout(layout.viewport, layout.texel_px, layout.slot_count, &check));
  if (check.total_bytes != layout.total_bytes || check.aux_offset != layout.aux_offset) {
    return Status::error("flow textures: the layout was not made by make_flow_texture_layout");
  }
  FlowTextures t;
  t.layout_ = layout;
  t.row_start_.reserve(size_t{layout.flow_extent.y} + 1);
  t.texel_of_.resize(size_t{layout.slot_count} + 1);
  t.seen_.resize(size_t{layout.slot_count} + 1);
  *out = std::move(t);
  return Status::success();
}

Status FlowTextures::create(const ParticleField& field, uint32_t texel_px, FlowTextures* out) {
  FlowTextureLayout layout;
  SIVIFLOW_TRY(make_flow_texture_layout(field.params().viewport, texel_px, field.slot_count(), &layout));
  return create(layout, out);
}

Status FlowTextures::pack(const ParticleField& field, std::span<std::byte> staging) {
  return pack(field.particles(), kFlowCoverRadiusFactor * field.cover_radius_px(), staging);
}

Status FlowTextures::pack(std::span<const Particle> particles, float cover_radius_px,
                          std::span<std::byte> staging) {
  const FlowTextureLayout& l = layout_;
  if (staging.size() < l.total_bytes) {
    return Status::error("flow textures: the staging block holds " + std::to_string(staging.size()) +
                         " bytes, the layout needs " + std::to_string(l.total_bytes));
  }
  if (!(cover_radius_px >= 0.0f) || !std::isfinite(cover_radius_px)) {
    return Status::error("flow textures: cover radius must be finite and >= 0");
  }
  std::fill(seen_.begin(), seen_.end(), uint8_t{0});
  for (const Particle& p : particles) {
    if (p.slot == 0 || p.slot > l.slot_count) {
      return Status::error("flow textures: particle " + std::to_string(p.id) + " has id " +
                           std::to_string(p.slot) + ", outside 1.." + std::to_string(l.slot_count));
    }
    if (seen_[p.slot]) {
      return Status::error("flow textures: id " + std::to_string(p.slot) + " is used twice");
    }
    seen_[p.slot] = 1;
    if (!std::isfinite(p.screen.x) || !std::isfinite(p.screen.y)) {
      return Status::error("flow textures: particle " + std::to_string(p.id) +
                           " has a non-finite screen position");
    }
  }

  texel_of_[0] = gpu::FlowTexel{SIVIFLOW_PARTICLE_NONE, 0, 0, 0};
  for (const Particle& p : particles) {
    texel_of_[p.slot] = {p.slot, to_half(p.flow.x), to_half(p.flow.y), to_half(p.flow.z)};
  }

  // Nearest particle per texel, exactly, one row at a time: along a row the squared distance to
  // particle i is the parabola (x - u_i)^2 + c_i, and the row's owners are the lower envelope of
  // the parabolas of the particles within the cover radius of the row (Felzenszwalb and
  // Huttenlocher's 1-D distance transform). Cost ~ texels + particles x rows of their disc: the
  // screen's size, not the river's. Texel centres sit at integer coordinates here.
  const int w = static_cast<int>(l.flow_extent.x), h = static_cast<int>(l.flow_extent.y);
  const float inv_texel = 1.0f / static_cast<float>(l.texel_px);
  const float r = std::min(cover_radius_px * inv_texel, kFarTexels);
  const float r2 = r * r;
  const size_t n = particles.size();
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  // Clamped far outside any texture, so float-to-int conversions below stay defined.
  const auto u_of = [&](uint32_t i) {
    return std::clamp(particles[i].screen.x * inv_texel - 0.5f, -kFarTexels, kFarTexels);
  };
  const auto v_of = [&](uint32_t i) {
    return std::clamp(particles[i].screen.y * inv_texel - 0.5f, -kFarTexels, kFarTexels);
  };
  std::sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) {
    const float ua = u_of(a), ub = u_of(b);
    return ua < ub || (ua == ub && particles[a].slot < particles[b].slot);
  });
  // Rows each particle reaches, bucketed by row in x order (counting sort).
  row_start_.assign(static_cast<size_t>(h) + 1, 0u);
  const auto rows_of = [&](uint32_t i, int* y0, int* y1) {
    const float v = v_of(i);
    *y0 = std::max(0, ceil_int(v - r));
    *y1 = std::min(h - 1, floor_int(v + r));
  };
  for (uint32_t i : order_) {
    int y0, y1;
    rows_of(i, &y0, &y1);
    for (int y = y0; y <= y1; ++y) row_start_[static_cast<size_t>(y) + 1]++;
  }
  for (int y = 0; y < h; ++y) row_start_[y + 1] += row_start_[y];
  row_items_.resize(row_start_[h]);
  uint32_t longest = 0;
  for (int y = 0; y < h; ++y) longest = std::max(longest, row_start_[y + 1] - row_start_[y]);
  env_.resize(size_t{longest} + 1);
  z_.resize(size_t{longest} + 2);
  row_fill_.assign(row_start_.begin(), row_start_.end() - 1);
  for (uint32_t i : order_) {
    int y0, y1;
    rows_of(i, &y0, &y1);
    const float u = u_of(i), v = v_of(i);
    for (int y = y0; y <= y1; ++y) {
      const float dy = static_cast<float>(y) - v;
      row_items_[row_fill_[y]++] = {u, dy * dy, particles[i].slot};
    }
  }

  std::byte* flow = staging.data() + l.flow_offset;
  Parabola* env = env_.data();  // sized for the longest row below
  float* z = z_.data();
  for (int y = 0; y < h; ++y) {
    // The envelope: parabola env[k] owns x in [z[k], z[k + 1]); m parabolas so far.
    size_t m = 0;
    for (uint32_t t = row_start_[y]; t < row_start_[y + 1]; ++t) {
      const Parabola q = row_items_[t];
      if (q.c > r2) continue;
      float s = -std::numeric_limits<float>::infinity();
      while (m > 0) {
        const Parabola& p = env[m - 1];
        if (q.u == p.u) {  // same column: the lower one wins everywhere (ties: the lower id)
          if (q.c >= p.c) break;
          --m;
          continue;
        }
        // q undercuts p from s = (q.u + p.u) / 2 + (q.c - p.c) / (2 (q.u - p.u)) on (q.u > p.u);
        // p keeps a column range if s > z (where p starts), tested without the division.
        const float du = q.u - p.u;
        if (q.c - p.c > (2.0f * z[m - 1] - q.u - p.u) * du) {
          s = 0.5f * (q.u + p.u) + (q.c - p.c) / (2.0f * du);
          break;
        }
        --m;
      }
      if (m > 0 && q.u == env[m - 1].u) continue;  // dominated
      env[m] = q;
      z[m] = s;
      ++m;
    }
    z[m] = std::numeric_limits<float>::infinity();
    // Write the row as runs (no branch per texel): each envelope parabola's columns are "none"
    // outside the cover radius and its own texel inside.
    std::byte* out = flow + static_cast<size_t>(y) * w * sizeof(gpu::FlowTexel);
    const float limit = static_cast<float>(w) + 1.0f;
    int x = 0;
    for (size_t k = 0; k < m && x < w; ++k) {
      const int end = std::clamp(ceil_int(std::clamp(z[k + 1], -1.0f, limit)), x, w);
      const float half = std::sqrt(r2 - env[k].c);
      const int a = std::clamp(ceil_int(std::clamp(env[k].u - half, -1.0f, limit)), x, end);
      const int b = std::clamp(floor_int(std::clamp(env[k].u + half, -1.0f, limit)) + 1, a, end);
      write_run(out, x, a, texel_of_[SIVIFLOW_PARTICLE_NONE]);
      write_run(out, a, b, texel_of_[env[k].slot]);
      write_run(out, b, end, texel_of_[SIVIFLOW_PARTICLE_NONE]);
      x = end;
    }
    write_run(out, x, w, texel_of_[SIVIFLOW_PARTICLE_NONE]);
  }
  std::memset(staging.data() + l.flow_offset + l.flow_bytes, 0, l.aux_offset - l.flow_bytes);
  std::byte* aux = staging.data() + l.aux_offset;
  std::memset(aux, 0, l.aux_bytes);
  for (const Particle& p : particles) {
    const gpu::ParticleAux a{p.speed, p.depth, p.foam, p.fade};
    std::memcpy(aux + size_t{p.slot} * sizeof(gpu::ParticleAux), &a, sizeof a);
  }
  return Status::success();
}

Status read_flow_texel(std::span<const std::byte> staging, const FlowTextureLayout& layout,
                       uint32_t x, uint32_t y, gpu::FlowTexel* out) {
  if (x >= layout.flow_extent.x || y >= layout.flow_extent.y) {
    return Status::error("flow textures: texel (" + std::to_string(x) + ", " + std::to_string(y) +
                         ") is outside the flow texture");
  }
  const size_t at = layout.flow_offset + (size_t{y} * layout.flow_extent.x + x) * sizeof(gpu::FlowTexel);
  if (at + sizeof(gpu::FlowTexel) > staging.size()) {
    return Status::error("flow textures: the staging block is too small for the layout");
  }
  std::memcpy(out, staging.data() + at, sizeof(gpu::FlowTexel));
  return Status::success();
}

Status read_particle_aux(std::span<const std::byte> staging, const FlowTextureLayout& layout,
                         uint32_t id, gpu::ParticleAux* out) {
  if (id > layout.slot_count) {
    return Status::error("flow textures: id " + std::to_string(id) + " is above the slot count " +
                         std::to_string(layout.slot_count));
  }
  const size_t at = layout.aux_offset + size_t{id} * sizeof(gpu::ParticleAux);
  if (at + sizeof(gpu::ParticleAux) > staging.size()) {
    return Status::error("flow textures: the staging block is too small for the layout");
  }
  std::memcpy(out, staging.data() + at, sizeof(gpu::ParticleAux));
  return Status::success();
}

}  // namespace siviflow
