#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"

layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = SIVIFLOW_ATTR_POSITION) in vec3 in_position;
layout(location = SIVIFLOW_ATTR_NORMAL) in vec3 in_normal;
layout(location = SIVIFLOW_ATTR_COLOR) in vec4 in_color;
layout(location = SIVIFLOW_ATTR_TEXCOORD) in vec2 in_texcoord;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_irradiance;
layout(location = 2) out vec4 out_color;
layout(location = 3) out vec2 out_texcoord;
layout(location = 4) out vec4 out_fog;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  out_world = in_position;
  float occlusion = in_color.a < 0.0 ? 1.0 : in_color.a;  // ground: SIVIFLOW_GROUND_VERTEX
  SceneLight light = light_scene(scene, occlusion, in_position, in_normal);
  out_irradiance = light.irradiance;
  out_fog = light.fog;
  out_color = in_color;
  out_texcoord = in_texcoord;
  gl_Position = scene.view_proj * vec4(in_position, 1.0);
  // The reflection pass sets a water plane here; the main view uses a plane that keeps all.
  gl_ClipDistance[0] = dot(scene.clip_plane.xyz, in_position) + scene.clip_plane.w;
}
