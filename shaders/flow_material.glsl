// The water material of Algorithm 3, shared by flow.frag (beauty only) and flow_aovs.frag
// (beauty plus the water mask, normal and reflection AOVs, with SIVIFLOW_FLOW_AOVS defined).
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "tiled_directional_flow.glsl"

layout(push_constant) uniform Push { FlowConstants flow; };
layout(set = 0, binding = 0) uniform usampler2D flow_texture;   // shared.h layout, texelFetch only
layout(set = 0, binding = 1) uniform sampler2D particle_aux;    // shared.h layout, texelFetch only
layout(set = 0, binding = 2) uniform sampler2D reflection_map;  // the mirrored scene
layout(set = 0, binding = 3) uniform sampler2D normal_map;      // tileable ripples, mipmapped
layout(set = 0, binding = 4) uniform usampler2D tile_table;     // this frame's, flow_tiles.comp

layout(location = 0) in vec3 in_world;
layout(location = 1) in float in_depth;
layout(location = 0) out vec4 out_color;
#ifdef SIVIFLOW_FLOW_AOVS
layout(location = 1) out float out_mask;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_reflection;
#endif

// Tunables of the water's look.
const vec3 kShallowColour = vec3(0.10, 0.22, 0.20);
const vec3 kDeepColour = vec3(0.015, 0.05, 0.07);
const float kAbsorptionPerMetre = 1.4;   // how fast the water turns from shallow to deep colour
const float kOpacityPerMetre = 2.2;      // how fast the riverbed disappears with depth
const float kShoreFadeMetres = 0.12;     // water thinner than this fades out at the banks
const float kRippleStrength = 0.55;      // van Hoesel's 0.3 transp^2 scale, brighter for rivers
const float kFresnelF0 = 0.02;           // water at normal incidence
const float kFadeInfluence = 0.25;       // how much a fading particle calms its cell

void main() {
  // The particle covering this pixel, and by its slot its speed, depth, slope, fade (slot 0, no
  // particle, reads the aux texture's all-zero texel 0: no branch needed). Its flow reaches the
  // ripples through the tile table.
  uint own = texelFetch(flow_texture, ivec2(gl_FragCoord.xy * (1.0 / flow.water.w)), 0).r;
  float fade = texelFetch(particle_aux, ivec2(own % SIVIFLOW_AUX_WIDTH,
                                               own / SIVIFLOW_AUX_WIDTH), 0).a;

  // Shallow water ripples less, so the shore is calm. A fading particle only eases its cell's
  // ripples part of the way: a full fade would print the particles' cells on the water.
  float shore = smoothstep(0.0, kShoreFadeMetres, in_depth);
  float transparency = shore * mix(1.0 - kFadeInfluence, 1.0, fade);
  TdfResult tdf = tdf_normal(in_world, vec3(0.0, 1.0, 0.0),
                             kRippleStrength * transparency * transparency, flow.water.z,
                             tile_table, normal_map);
  vec3 n = tdf.normal;

  // Reflection: the mirrored scene at this pixel, offset by the normal's tilt (paper §4.3).
  vec3 to_eye = normalize(flow.camera_position.xyz - in_world);
  vec2 uv = gl_FragCoord.xy * flow.screen.zw + tdf.tilt * flow.water.y;
  vec3 reflection = texture(reflection_map, clamp(uv, vec2(0.0), vec2(1.0))).rgb;
  float cos_theta = max(dot(n, to_eye), 0.0);
  float grazing = 1.0 - cos_theta;
  float grazing_sq = grazing * grazing;
  float fresnel = kFresnelF0 + (1.0 - kFresnelF0) * grazing_sq * grazing_sq * grazing;

  // Depth-based colour and absorption: clear in the shallows, dark and opaque in the deep.
  float light = 0.35 + 0.65 * max(dot(n, flow.sun_direction.xyz), 0.0);  // a unit vector already
  vec3 body = mix(kShallowColour, kDeepColour, 1.0 - exp(-kAbsorptionPerMetre * in_depth)) * light;
  float opacity = 1.0 - exp(-kOpacityPerMetre * in_depth);
  vec3 colour = mix(body, reflection, fresnel);
  float alpha = clamp(mix(opacity, 1.0, fresnel), 0.0, 1.0) * shore;
  out_color = vec4(colour, alpha);
#ifdef SIVIFLOW_FLOW_AOVS
  out_mask = 1.0;
  out_normal = vec4(n, 1.0);
  out_reflection = vec4(reflection, 1.0);
#endif
}
