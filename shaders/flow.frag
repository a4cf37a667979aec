#version 460
#extension GL_GOOGLE_include_directive : require
// The water material, beauty only (what an embedding host records).
#include "flow_material.glsl"
