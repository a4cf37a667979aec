#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"

// The river surface, drawn over the scene with the water material.
layout(push_constant) uniform Push { FlowConstants flow; };
layout(location = SIVIFLOW_ATTR_POSITION) in vec3 in_position;
layout(location = 0) out vec3 out_world;

void main() {
  out_world = in_position;
  gl_Position = flow.view_proj * vec4(in_position, 1.0);
}
