#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
#include "scene_lighting.glsl"

layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = SIVIFLOW_ATTR_POSITION) in vec3 in_position;
layout(location = SIVIFLOW_ATTR_NORMAL) in vec3 in_normal;
layout(location = SIVIFLOW_ATTR_COLOR) in vec4 in_color;
layout(location = SIVIFLOW_ATTR_TEXCOORD) in vec2 in_texcoord;
// The object pipeline's (glTF objects, object.frag): a base-colour texture coordinate in place
// of the world position.
layout(constant_id = 0) const bool kTextured = false;
// x, y: world x and z, or (kTextured) the texture coordinate. z, w: the ground's height above
// the water and its rock (SIVIFLOW_GROUND_VERTEX), else the colour's red and green.
layout(location = 0) out vec4 out_surface;
layout(location = 1) out vec4 out_lit;  // SceneLight::lit; w: -1 for the ground, else the blue
layout(location = 2) out vec3 out_haze;

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[1];
};

void main() {
  const bool ground = in_color.a < 0.0;  // SIVIFLOW_GROUND_VERTEX
  SceneLight light = light_scene(scene, ground ? 1.0 : in_color.a, in_position, in_normal);
  out_surface = vec4(kTextured ? in_texcoord : in_position.xz, ground ? in_texcoord : in_color.rg);
  out_lit = vec4(light.lit, ground ? -1.0 : in_color.b);
  out_haze = light.haze;
  gl_Position = scene.view_proj * vec4(in_position, 1.0);
  // The reflection pass sets a water plane here; the main view uses a plane that keeps all.
  gl_ClipDistance[0] = dot(scene.clip_plane.xyz, in_position) + scene.clip_plane.w;
}
