// The water material of Algorithm 3 (its ripples by Tiled Directional Flow, or by the flow-map
// baseline when the look asks for it). flow.frag is compiled in variants (shaders/CMakeLists.txt)
// that add outputs after the colour, in this order, each where its macro is defined:
// SIVIFLOW_FLOW_MOTION the motion vectors and SIVIFLOW_FLOW_REACTIVE the reactive mask (for the
// host's temporal filters), SIVIFLOW_FLOW_AOVS the water mask, normal, reflection and foam.
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "sky_common.glsl"
#include "tiled_directional_flow.glsl"
#include "flow_map.glsl"
#include "water_debug_views.glsl"

layout(push_constant) uniform Push { FlowConstants flow; };
layout(set = 0, binding = 0) uniform usampler2D flow_texture;   // shared.h layout, texelFetch only
layout(set = 0, binding = 1) uniform sampler2D particle_aux;    // shared.h layout, texelFetch only
layout(set = 0, binding = 2) uniform sampler2D reflection_map;  // the mirrored scene
layout(set = 0, binding = 3) uniform sampler2D normal_map;      // tileable ripples, mipmapped
layout(set = 0, binding = 4) uniform usampler2D tile_table;     // this frame's, flow_tiles.comp
layout(set = 0, binding = 5) uniform sampler2D host_depth;      // what the host drew, texelFetch
layout(set = 0, binding = 6) uniform Look { WaterLookConstants look; };  // siviflow/water_look.h
layout(set = 0, binding = 7) uniform sampler2D refraction_map;  // the host's colour before the
                                                                 // water, texelFetch only

layout(location = 0) in vec3 in_world;
layout(location = 0) out vec4 out_color;
#ifdef SIVIFLOW_FLOW_MOTION
layout(location = 1) out vec2 out_motion;
#define SIVIFLOW_AFTER_MOTION 2
#else
#define SIVIFLOW_AFTER_MOTION 1
#endif
#ifdef SIVIFLOW_FLOW_REACTIVE
layout(location = SIVIFLOW_AFTER_MOTION) out float out_reactive;
#define SIVIFLOW_FIRST_AOV (SIVIFLOW_AFTER_MOTION + 1)
#else
#define SIVIFLOW_FIRST_AOV SIVIFLOW_AFTER_MOTION
#endif
#ifdef SIVIFLOW_FLOW_AOVS
layout(location = SIVIFLOW_FIRST_AOV) out float out_mask;
layout(location = SIVIFLOW_FIRST_AOV + 1) out vec4 out_normal;
layout(location = SIVIFLOW_FIRST_AOV + 2) out vec4 out_reflection;
layout(location = SIVIFLOW_FIRST_AOV + 3) out float out_foam;
#endif

// Tunables of the material that are not the artist's look (that comes in `look`).
const float kShoreFadeMetres = 0.12;     // water thinner than this fades out at the banks
const float kFadeInfluence = 0.25;       // how much a fading particle calms its cell
// The sun's glint (GGX): roughness from calm water's to rippled water's, and the sun's
// brightness on the scale of the sky's (whose disc is 20).
const float kCalmRoughness = 0.07;
const float kRoughnessPerRipple = 0.45;  // per unit of applied ripple strength
const float kMaxRoughness = 0.45;
const float kSunIntensity = 8.0;  // at WaterLook::sun_glint 1
const float kPi = 3.14159265;
const float kMaxWaterPath = 1.0e4;       // metres: the host's far plane or sky behind the water
const float kFoamEdge = 0.25;            // ripple-height band over which foam patches fade in
const int kMaterialFlowMap = 1;          // siviflow::WaterMaterial::kFlowMap
// One pipeline per material, and per debug views on or off (engine/passes/flow_pass.cpp): as
// branches on the look they would cost every pixel even untaken, on a software rasterizer.
layout(constant_id = 0) const int kMaterial = 0;  // siviflow::WaterMaterial
layout(constant_id = 1) const bool kDebugViews = false;

// How much of the water foam covers: where the ripple height through the tiles (moving with the
// flow) rises above 1 - the foam there, so thin foam is scattered patches on the crests and full
// foam covers all.
float foam_coverage(float foam, float pattern) {
  float density = clamp(foam, 0.0, 1.0);
  return smoothstep(1.0 - density, 1.0 - density + kFoamEdge, pattern) * min(4.0 * density, 1.0);
}

void main() {
  // The particle covering this pixel, and by its slot its fade (slot 0, no particle, reads the
  // aux texture's all-zero texel 0: no branch needed). Its flow and foam reach the ripples
  // through the tile table.
  vec2 pixel = gl_FragCoord.xy - flow.screen.xy;  // in the view's viewport
  uvec4 texel = texelFetch(flow_texture, ivec2(pixel * (1.0 / flow.water.w)), 0);
  uint own = texel.r;
  float fade = texelFetch(particle_aux, SIVIFLOW_AUX_TEXEL(own), 0).a;

  // The water the view ray crosses: from the surface to what the host drew behind it. Both
  // depths lie on this pixel's ray, where view distances go as (depth - k).
  vec3 to_eye = flow.camera_position.xyz - in_world;
  float eye_distance = length(to_eye);
  to_eye /= eye_distance;
  float behind = texelFetch(host_depth, ivec2(gl_FragCoord.xy), 0).r;
  float k = flow.camera_position.w;
  float path = clamp(eye_distance * ((gl_FragCoord.z - k) / (behind - k) - 1.0), 0.0, kMaxWaterPath);
  float below = path * abs(to_eye.y);  // the depth of the bed under the surface there

  // Shallow water ripples less, so the shore is calm. A fading particle only eases its cell's
  // ripples part of the way: a full fade would print the particles' cells on the water.
  float shore = smoothstep(0.0, kShoreFadeMetres, below);
  float transparency = shore * mix(1.0 - kFadeInfluence, 1.0, fade);
  float strength = look.sun_color.w * transparency * transparency;
  TdfResult ripples;
  if (kMaterial == kMaterialFlowMap) {
    FlowMapSample here = flow_map_at(pixel, flow.water.w, flow_texture, particle_aux);
    ripples = flow_map_normal(in_world, strength, flow.water.z * look.surface.y / kTdfScaleFast,
                              look.clock.x, here, normal_map);
  } else {
    ripples = tdf_normal(in_world, vec3(0.0, 1.0, 0.0), strength, flow.water.z, tile_table,
                         normal_map);
  }
  vec3 n = ripples.normal;

  // Reflection: the mirrored scene at this pixel, offset by the normal's tilt (paper §4.3); the
  // sky seen along the reflected ray where the host's reflection drew nothing.
  vec2 uv = pixel * flow.screen.zw + ripples.tilt * flow.water.y;
  vec4 mirrored = texture(reflection_map, clamp(uv, vec2(0.0), vec2(1.0)));
  vec3 reflected_ray = reflect(-to_eye, n);
  reflected_ray.y = abs(reflected_ray.y);  // a ray tilted under the horizon sees the sky's edge
  vec3 sky = sky_radiance(reflected_ray, flow.sun_direction.xyz, 0.0);  // still unit length
  vec3 reflection = mix(sky, mirrored.rgb, mirrored.a);
  float cos_theta = max(dot(n, to_eye), 0.0);
  float grazing = 1.0 - cos_theta;
  float grazing_sq = grazing * grazing;
  float f0 = look.surface.x;
  float fresnel = f0 + (1.0 - f0) * grazing_sq * grazing_sq * grazing;

  // Refraction: what lies under the water (the host's colour before it), seen through the
  // surface bent by the normal, the more the more water lies under it (up to a metre). Where the
  // bent view lands on something in front of the water, the pixel's own straight view is taken:
  // the refraction never shows what is in front.
  vec2 viewport_size = 1.0 / flow.screen.zw;
  vec2 bend = ripples.tilt * (look.refraction.w * min(below, 1.0)) * viewport_size;  // pixels
  // The texel whose depth is checked is the one taken, unfiltered: a filtered sample could
  // blend in a neighbour in front of the water.
  vec2 bent = floor(clamp(pixel + bend, vec2(0.0), viewport_size - 1.0)) + 0.5;
  float bent_behind = texelFetch(host_depth, ivec2(flow.screen.xy + bent), 0).r;
  float bent_path = eye_distance * ((gl_FragCoord.z - k) / (bent_behind - k) - 1.0);
  if (!(bent_path > 0.0)) {
    bent = pixel;
    bent_path = path;
  }
  vec3 seen = texelFetch(refraction_map, ivec2(bent), 0).rgb;

  // The water's own colour, and what lies behind absorbed per colour channel by the water the
  // light crosses (Beer-Lambert), the water's colour scattered in for what it takes: clear in
  // the shallows, dark in the deep.
  vec3 light = 0.35 + 0.65 * look.sun_color.rgb * max(dot(n, flow.sun_direction.xyz), 0.0);
  vec3 body = mix(look.water_color.rgb, look.deep_color.rgb,
                  1.0 - exp(-look.water_color.w * path)) * light;
  vec3 transmittance = exp(-look.refraction.rgb * clamp(bent_path, 0.0, kMaxWaterPath));
  vec3 under = seen * transmittance + body * (1.0 - transmittance);
  vec3 colour = mix(under, reflection, fresnel);
  float alpha = shore;  // the water holds what lies behind it; only the thinnest shore blends

  // Foam: opaque, diffusely lit, over the water's colour (thinning out with the shore's water).
  float foam = foam_coverage(ripples.foam * look.foam.w, ripples.foam_pattern) * shore;
  colour = mix(colour, look.foam.rgb * light, foam);

  // Sunlight: the sun's specular glint on the rippled surface (GGX distribution, Schlick Fresnel,
  // no shadowing), as broad as the applied ripples make the water rough: sharp glints on calm
  // water, a broad sheen on rough. It is light the surface adds over what shows through it;
  // blending takes a share alpha = shore of it, as of the rest of the water.
  vec3 sun = flow.sun_direction.xyz;
  vec3 half_vector = normalize(sun + to_eye);
  // (The shore's calm, not the particles' fade: a per-particle roughness would print their cells.)
  float ripple = look.sun_color.w * shore * shore;
  float roughness = clamp(kCalmRoughness + kRoughnessPerRipple * ripple, kCalmRoughness, kMaxRoughness);
  float a2 = roughness * roughness * roughness * roughness;
  float n_dot_h = max(dot(n, half_vector), 0.0);
  float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  float v_dot_h = 1.0 - max(dot(half_vector, to_eye), 0.0);
  float v_dot_h_sq = v_dot_h * v_dot_h;
  float sun_fresnel = f0 + (1.0 - f0) * v_dot_h_sq * v_dot_h_sq * v_dot_h;
  float lit = step(0.0, dot(n, sun)) * step(0.0, sun.y) * (1.0 - foam);  // foam is rough: none
  // GGX's a2 / (pi d^2) over the 4 cos(theta) of the specular term, in one division.
  float glint = kSunIntensity * look.surface.z * a2 * sun_fresnel * lit /
                (4.0 * kPi * d * d * max(cos_theta, 0.1));
  colour += look.sun_color.rgb * glint;
  out_color = vec4(colour, alpha);
  if (kDebugViews) {
    out_color = debug_view_colour(int(look.surface.w), out_color, texel, fade, in_world,
                                  flow.water.z, look.surface.y, tile_table);
  }
#ifdef SIVIFLOW_FLOW_MOTION
  // Viewport uv of the surface point now and a frame ago, both without jitter: what a temporal
  // filter needs to find the point in its history.
  vec4 now = look.motion_now * vec4(in_world, 1.0);
  vec4 before = look.motion_before * vec4(in_world, 1.0);
  // A point behind the last frame's camera has no place in its history: no motion to give.
  out_motion = before.w > 0.0 ? 0.5 * (before.xy / before.w - now.xy / now.w) : vec2(0.0);
#endif
#ifdef SIVIFLOW_FLOW_REACTIVE
  // What moves over the surface rather than with it: the ripples as the shore lets them (not the
  // particles' fade, which would print their cells into the mask), the reflection's share and
  // the foam; as opaque as the water is.
  out_reactive = look.temporal.x * alpha * min(1.0, ripple + fresnel + foam);
#endif
#ifdef SIVIFLOW_FLOW_AOVS
  out_mask = 1.0;
  out_normal = vec4(n, 1.0);
  out_reflection = vec4(reflection, 1.0);
  out_foam = foam;
#endif
}
