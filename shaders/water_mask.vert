#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"

// The river surface, for the water mask: where it is the nearest surface on screen.
layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = SIVIFLOW_ATTR_POSITION) in vec3 in_position;

void main() {
  gl_Position = scene.view_proj * vec4(in_position, 1.0);
}
