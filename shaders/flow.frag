#version 460
#extension GL_GOOGLE_include_directive : require
// The water material: beauty only here; with more outputs in the variants of
// shaders/CMakeLists.txt.
#include "flow_material.glsl"
