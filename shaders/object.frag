#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"
// glTF objects: base-colour texture (sRGB, decoded to linear by the sampler) times the factor.

layout(push_constant) uniform Push { SceneConstants scene; };
layout(set = 0, binding = 0) uniform sampler2D base_color;
layout(location = 0) in vec4 in_surface;  // scene.vert's: the texture coordinate, red, green
layout(location = 1) in vec4 in_lit;      // w: blue
layout(location = 2) in vec3 in_haze;
layout(location = 0) out vec4 out_color;

void main() {
  vec3 albedo = texture(base_color, in_surface.xy).rgb * vec3(in_surface.zw, in_lit.w);
  out_color = vec4(shade_scene(albedo, in_lit.rgb, in_haze), 1.0);
}
