#version 460
// The water's surface depth into the host's depth (CreateInfo::write_depth), drawn after the
// material with flow.vert: no colour, the depth test and write do all.
layout(location = 0) in vec3 in_world;  // flow.vert's output, declared so that it is consumed

void main() {}
