// The water's look: what a technical artist tunes. Renderer::set_look() takes it per frame; a
// scene file's optional "look" object gives the same fields under the same names. The defaults
// are the look SiViFlow ships with.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

namespace siviflow {

// How the ripples follow the flow.
enum class WaterMaterial : uint32_t {
  // SiViFlow's: world-anchored tiles, each with its own flow direction (van Hoesel 2010).
  kTiledDirectionalFlow,
  // The classic baseline most engines ship (Vlachos 2010): one normal map in two phases
  // scrolled along the flow and cross-faded, which pulses once per cycle; for comparison.
  kFlowMap,
};
inline constexpr uint32_t kWaterMaterialCount = 2;
// "tiled_directional_flow" or "flowmap": the scene file's names.
const char* water_material_name(WaterMaterial material);
// The material of that name; false when there is none.
bool water_material_from_name(std::string_view name, WaterMaterial* material);

struct WaterLook {
  WaterMaterial material = WaterMaterial::kTiledDirectionalFlow;
  glm::vec3 water_color{0.10f, 0.22f, 0.20f};  // linear RGB of shallow water, each in [0, 1]
  glm::vec3 deep_color{0.015f, 0.05f, 0.07f};  // linear RGB of deep water, each in [0, 1]
  // Per metre of view path through the water, in [0, 100]: how fast shallow turns deep, and
  // how fast what lies behind the water disappears.
  float absorption_per_metre = 1.4f;
  float opacity_per_metre = 2.2f;
  // Per colour channel, in [0, 4]: how much faster than opacity_per_metre red, green and blue
  // of what lies behind are absorbed (Beer-Lambert); water takes red first, so the shallows
  // show the bed nearly as it is and the deep turns it blue-green.
  glm::vec3 opacity_tint{1.35f, 0.95f, 0.70f};
  // Screen uv offset of what is seen through the water per unit of normal tilt, per metre of
  // water under the surface up to one, in [0, 0.5]: the bed wavers under the ripples.
  float refraction_distortion = 0.03f;
  float ripple_strength = 0.55f;  // tilt of the ripples, in [0, 4]: 0 is a flat mirror
  float ripple_scale = 1.0f;      // size of the ripples relative to the default, in [0.25, 4]
  // Side of a Tiled Directional Flow tile (one flow direction each), in [1, 8] metres.
  float tile_size_m = 3.0f;
  float reflection_distortion = 0.04f;  // screen uv offset per unit of normal tilt, in [0, 0.5]
  float fresnel_f0 = 0.02f;             // reflectance at normal incidence, in [0, 1]
  glm::vec3 sun_direction{0.45f, 0.62f, 0.35f};  // towards the sun, finite, any non-zero length
  glm::vec3 sun_color{1.0f, 1.0f, 1.0f};  // linear multiplier of sunlit water, each in [0, 100]
  float sun_glint = 1.0f;  // strength of the sun's specular glint on the water, in [0, 10]
  // Foam where the flow is disturbed (wakes, banks, fast turns; sim/foam.h gives where), in
  // [0, 4]: 0 none, 1 as the flow makes it, more spreads it further.
  float foam_amount = 1.0f;
  glm::vec3 foam_color{0.80f, 0.82f, 0.82f};  // linear RGB of foam in full light, each in [0, 1]
  // How much the water asks a host's temporal filter to distrust its history, in [0, 1]: the
  // reactive mask's scale (FrameInputs::reactive). Ripples, reflections and foam move against
  // the surface's motion vectors; 0 lets TAA accumulate them (smooth, may smear), 1 keeps them
  // sharp (may shimmer).
  float reactive_strength = 0.6f;
};

// Range limits of the tile size: the renderer sizes its water heights for the largest.
inline constexpr float kMinTileSizeM = 1.0f;
inline constexpr float kMaxTileSizeM = 8.0f;

// The first field of `look` out of its range, or "" when all are in range; `problem` then says
// what is wrong with its value, e.g. field "fresnel_f0", problem "1.5 is outside [0, 1]".
std::string water_look_error(const WaterLook& look, std::string* problem);

}  // namespace siviflow
