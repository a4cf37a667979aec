#version 460
#extension GL_GOOGLE_include_directive : require
// The water material with the water mask, normal, reflection and foam AOVs (tools and tests).
#define SIVIFLOW_FLOW_AOVS 1
#include "flow_material.glsl"
