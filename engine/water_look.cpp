#include "siviflow/water_look.h"

#include <cmath>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

bool in_range(float value, float lo, float hi) { return value >= lo && value <= hi; }  // NaN: no

std::string range_problem(float value, float lo, float hi) {
  return text_format("%g is outside [%g, %g]", double(value), double(lo), double(hi));
}

}  // namespace

const char* water_material_name(WaterMaterial material) {
  switch (material) {
    case WaterMaterial::kTiledDirectionalFlow:
      return "tiled_directional_flow";
    case WaterMaterial::kFlowMap:
      return "flowmap";
  }
  return "unknown";
}

bool water_material_from_name(std::string_view name, WaterMaterial* material) {
  for (uint32_t i = 0; i < kWaterMaterialCount; ++i) {
    const auto candidate = static_cast<WaterMaterial>(i);
    if (name == water_material_name(candidate)) {
      *material = candidate;
      return true;
    }
  }
  return false;
}

std::string water_look_error(const WaterLook& look, std::string* problem) {
  if (static_cast<uint32_t>(look.material) >= kWaterMaterialCount) {
    *problem = text_format("%u is not a WaterMaterial", static_cast<unsigned>(look.material));
    return "material";
  }
  const struct {
    const char* name;
    float value, lo, hi;
  } scalars[] = {
      {"absorption_per_metre", look.absorption_per_metre, 0.0f, 100.0f},
      {"opacity_per_metre", look.opacity_per_metre, 0.0f, 100.0f},
      {"ripple_strength", look.ripple_strength, 0.0f, 4.0f},
      {"ripple_scale", look.ripple_scale, 0.25f, 4.0f},
      {"tile_size_m", look.tile_size_m, kMinTileSizeM, kMaxTileSizeM},
      {"reflection_distortion", look.reflection_distortion, 0.0f, 0.5f},
      {"refraction_distortion", look.refraction_distortion, 0.0f, 0.5f},
      {"fresnel_f0", look.fresnel_f0, 0.0f, 1.0f},
      {"sun_glint", look.sun_glint, 0.0f, 10.0f},
      {"foam_amount", look.foam_amount, 0.0f, 4.0f},
      {"reactive_strength", look.reactive_strength, 0.0f, 1.0f},
  };
  for (const auto& s : scalars) {
    if (!in_range(s.value, s.lo, s.hi)) {
      *problem = range_problem(s.value, s.lo, s.hi);
      return s.name;
    }
  }
  const struct {
    const char* name;
    glm::vec3 value;
    float hi;
  } colors[] = {{"water_color", look.water_color, 1.0f},
                {"deep_color", look.deep_color, 1.0f},
                {"sun_color", look.sun_color, 100.0f},
                {"foam_color", look.foam_color, 1.0f},
                {"opacity_tint", look.opacity_tint, 4.0f}};
  for (const auto& c : colors) {
    for (int i = 0; i < 3; ++i) {
      if (!in_range(c.value[i], 0.0f, c.hi)) {
        *problem = text_format("component %d: ", i) + range_problem(c.value[i], 0.0f, c.hi);
        return c.name;
      }
    }
  }
  const glm::vec3 sun = look.sun_direction;
  if (!std::isfinite(sun.x) || !std::isfinite(sun.y) || !std::isfinite(sun.z) ||
      !(sun.x * sun.x + sun.y * sun.y + sun.z * sun.z > 1e-12f)) {
    *problem = text_format("(%g, %g, %g) is not a finite, non-zero direction", double(sun.x),
                           double(sun.y), double(sun.z));
    return "sun_direction";
  }
  problem->clear();
  return "";
}

}  // namespace siviflow
