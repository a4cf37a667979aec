// The fields of WaterLook by their scene-file names ("look" keys): one table for the parser and
// for our tools that write a look back into a scene file.
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "siviflow/water_look.h"

namespace siviflow {

struct LookScalarField {
  const char* name;
  float WaterLook::*member;
};
struct LookVectorField {
  const char* name;
  glm::vec3 WaterLook::*member;
};

inline constexpr std::array<LookScalarField, 11> kLookScalarFields{{
    {"absorption_per_metre", &WaterLook::absorption_per_metre},
    {"opacity_per_metre", &WaterLook::opacity_per_metre},
    {"ripple_strength", &WaterLook::ripple_strength},
    {"ripple_scale", &WaterLook::ripple_scale},
    {"tile_size_m", &WaterLook::tile_size_m},
    {"reflection_distortion", &WaterLook::reflection_distortion},
    {"refraction_distortion", &WaterLook::refraction_distortion},
    {"fresnel_f0", &WaterLook::fresnel_f0},
    {"sun_glint", &WaterLook::sun_glint},
    {"foam_amount", &WaterLook::foam_amount},
    {"reactive_strength", &WaterLook::reactive_strength},
}};
inline constexpr std::array<LookVectorField, 6> kLookVectorFields{{
    {"water_color", &WaterLook::water_color},
    {"deep_color", &WaterLook::deep_color},
    {"opacity_tint", &WaterLook::opacity_tint},
    {"sun_direction", &WaterLook::sun_direction},
    {"sun_color", &WaterLook::sun_color},
    {"foam_color", &WaterLook::foam_color},
}};

}  // namespace siviflow
