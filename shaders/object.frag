#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"
// glTF objects: base-colour texture (sRGB, decoded to linear by the sampler) times the factor.

layout(push_constant) uniform Push { SceneConstants scene; };
layout(set = 0, binding = 0) uniform sampler2D base_color;
layout(location = 0) in vec3 in_world;  // scene.vert's output, declared so that it is consumed
layout(location = 1) in vec3 in_irradiance;
layout(location = 2) in vec4 in_color;
layout(location = 3) in vec2 in_texcoord;
layout(location = 4) in vec4 in_fog;
layout(location = 0) out vec4 out_color;

void main() {
  vec3 albedo = texture(base_color, in_texcoord).rgb * in_color.rgb;
  out_color = vec4(shade_scene(albedo, in_irradiance, in_fog), 1.0);
}
