#include "sim/procedural_river.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>

namespace siviflow {

ProceduralRiver::ProceduralRiver(const ProceduralRiverParams& params) : params_(params) {
  // std::mt19937 is specified bit-exactly by the standard, so phases are the same everywhere.
  std::mt19937 rng(params.seed);
  const float two_pi = glm::two_pi<float>();
  phase_a_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
  phase_b_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
  phase_w_ = static_cast<float>(rng() % 100000u) / 100000.0f * two_pi;
}

float ProceduralRiver::centreline_x(float z) const {
  const float k = glm::two_pi<float>() / params_.meander_wavelength;
  // A second, shorter harmonic breaks the regularity of a pure sine.
  return params_.meander_amplitude *
         (0.8f * std::sin(k * z + phase_a_) + 0.2f * std::sin(2.3f * k * z + phase_b_));
}

float ProceduralRiver::width_at(float z) const {
  const float k = glm::two_pi<float>() / (0.7f * params_.meander_wavelength);
  return params_.width * (1.0f + params_.width_variation * std::sin(k * z + phase_w_));
}

float ProceduralRiver::lateral_distance(float x, float z) const {
  // Project the horizontal offset onto the local normal of the centreline; exact enough while
  // the meander radius is large against the valley width.
  const float dz = 0.5f;
  const float slope = (centreline_x(z + dz) - centreline_x(z - dz)) / (2.0f * dz);
  return (x - centreline_x(z)) / std::sqrt(1.0f + slope * slope);
}

float ProceduralRiver::terrain_height(float x, float z) const {
  const float d = std::abs(lateral_distance(x, z));
  const float half_width = 0.5f * width_at(z);
  if (d < half_width) {
    // Riverbed: a smooth bowl from -depth at the centre up to the waterline at the bank.
    const float t = d / half_width;
    return -params_.depth * (1.0f - t * t);
  }
  // Bank: rises to bank_height over a few metres, then the valley floor climbs to the walls.
  const float bank_run = 3.0f;
  const float bank = params_.bank_height * glm::smoothstep(0.0f, 1.0f, (d - half_width) / bank_run);
  const float wall_t = std::clamp((d - half_width - bank_run) /
                                      (params_.valley_half_width - half_width - bank_run),
                                  0.0f, 1.0f);
  const float wall = params_.valley_wall_height * wall_t * wall_t;
  // Gentle undulation so the valley floor is not a perfect extrusion.
  const float undulation = 0.6f * std::sin(0.11f * x + phase_b_) * std::sin(0.07f * z + phase_a_);
  return bank + wall + undulation * wall_t;
}

}  // namespace siviflow
