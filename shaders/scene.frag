#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "sky_common.glsl"

layout(push_constant) uniform Push { SceneConstants scene; };
layout(set = 0, binding = 0) uniform sampler2D ground_detail;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec4 in_color;
layout(location = 0) out vec4 out_color;

void main() {
  vec3 n = normalize(in_normal);
  vec3 sun = scene.sun_direction.xyz;
  // Two scales of the tileable detail texture, in world metres, break up the vertex colours.
  float detail = texture(ground_detail, in_world.xz * 0.25).r * 0.6 +
                 texture(ground_detail, in_world.xz * 0.031).g * 0.4;
  vec3 albedo = in_color.rgb * mix(0.75, 1.25, detail);
  // Sun (Lambert) plus a hemispheric sky term; ambient occlusion baked into the vertex alpha.
  float diffuse = max(dot(n, sun), 0.0);
  vec3 sky_light = mix(vec3(0.20, 0.19, 0.17), vec3(0.35, 0.45, 0.62), n.y * 0.5 + 0.5);
  vec3 lit = albedo * (vec3(1.0, 0.95, 0.85) * 1.1 * diffuse + sky_light * in_color.a);
  // Height-attenuated exponential fog towards the sky colour of the view direction.
  vec3 to_fragment = in_world - scene.camera_position.xyz;
  float dist = length(to_fragment);
  vec3 direction = to_fragment / max(dist, 1e-4);
  float fog = 1.0 - exp(-scene.fog.x * dist * exp(-scene.fog.y * max(in_world.y + scene.fog.z, 0.0)));
  vec3 fog_color = sky_radiance(direction, sun, 0.0);
  out_color = vec4(mix(lit, fog_color, clamp(fog, 0.0, 1.0)), 1.0);
}
