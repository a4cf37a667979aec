// The classic two-phase flow-map material (Vlachos 2010), SiViFlow's baseline to compare Tiled
// Directional Flow with: one normal map, anchored to the world, sampled twice with offsets that
// grow along the flow for one cycle and then restart, the two phases half a cycle apart and
// cross-faded so each restarts while invisible. Its mean tilt dips at every cross-fade (two
// uncorrelated samples mixed half and half): the pulsing Tiled Directional Flow avoids. Drawn
// from the same flow texture, filtered bilinearly as a flow-map texture is sampled.
//
// Requires: GL_GOOGLE_include_directive; call flow_map_normal from uniform control flow (it
// takes dFdx/dFdy). Bindings as tiled_directional_flow.glsl's, plus the flow texture
// (usampler2D) and the particle aux texture (sampler2D), texelFetch only.
#ifndef SIVIFLOW_FLOW_MAP_GLSL
#define SIVIFLOW_FLOW_MAP_GLSL

#include "shared.h"
#include "tiled_directional_flow.glsl"

// One phase's life in seconds; it divides SIVIFLOW_TDF_TIME_PERIOD, so the time's wrap is seamless.
const float kFlowMapCycleSeconds = 1.0;
const float kFlowMapAdvection = 1.0;  // pattern speed / flow speed: the classic scrolls at the flow's

struct FlowMapSample {
  vec2 flow;   // world x, z (m/s); zero where no particle is near
  float foam;  // 0..1
};

// The flow map under a pixel (in the view's viewport): the four nearest flow texels weighted
// bilinearly, those without a particle left out.
FlowMapSample flow_map_at(vec2 pixel, float texel_px, usampler2D flow_texture,
                          sampler2D particle_aux) {
  vec2 t = pixel / texel_px - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 f = t - vec2(base);
  ivec2 last = textureSize(flow_texture, 0) - 1;
  vec3 sum = vec3(0.0);  // flow x, z and foam
  float weight = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 corner = ivec2(k & 1, k >> 1);
    uvec4 texel = texelFetch(flow_texture, clamp(base + corner, ivec2(0), last), 0);
    if (texel.r == SIVIFLOW_PARTICLE_NONE) continue;
    vec2 axis = mix(1.0 - f, f, vec2(corner));
    float w = axis.x * axis.y;
    float foam = texelFetch(particle_aux, SIVIFLOW_AUX_TEXEL(texel.r), 0).b;
    sum += w * vec3(tdf_texel_flow(texel).xz, foam);
    weight += w;
  }
  if (weight > 0.0) sum /= weight;
  return FlowMapSample(sum.xy, sum.z);
}

// The flow-map normal of a water fragment on level water (the same result as tdf_normal's).
//   strength      as tdf_normal's; repeat_m: metres per normal-map repeat; time: seconds,
//   wrapped to SIVIFLOW_TDF_TIME_PERIOD
TdfResult flow_map_normal(vec3 world, float strength, float repeat_m, float time,
                          FlowMapSample here, sampler2D normal_map) {
  vec2 uv = world.xz / repeat_m;
  vec2 duv_dx = dFdx(uv);  // the world's, not the phases': their offsets jump between texels
  vec2 duv_dy = dFdy(uv);
  float phase_a = fract(time / kFlowMapCycleSeconds);
  float phase_b = fract(phase_a + 0.5);
  // How far the pattern moves in one cycle, in map units.
  vec2 drift = here.flow * (kFlowMapAdvection * kFlowMapCycleSeconds / repeat_m);
  vec4 a = textureGrad(normal_map, uv - drift * phase_a, duv_dx, duv_dy);
  vec4 b = textureGrad(normal_map, uv - drift * phase_b + 0.5, duv_dx, duv_dy);
  vec4 mixed = mix(a, b, abs(1.0 - 2.0 * phase_a));  // a phase weighs 0 when it restarts
  vec2 tilt = (mixed.rg * 2.0 - 1.0) * (0.5 * strength);
  float len_sq = dot(tilt, tilt);
  if (len_sq > kTdfMaxTilt * kTdfMaxTilt) {
    tilt *= kTdfMaxTilt * inversesqrt(len_sq);
    len_sq = kTdfMaxTilt * kTdfMaxTilt;
  }
  TdfResult result;
  result.normal = vec3(tilt.x, sqrt(max(1.0 - len_sq, 0.0)), tilt.y);
  result.tilt = tilt;
  result.foam = here.foam;
  result.foam_pattern = mixed.a;
  return result;
}

#endif  // SIVIFLOW_FLOW_MAP_GLSL
