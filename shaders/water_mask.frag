#version 460
// Depth-tested against the scene, without writing depth: only visible water is marked.
layout(location = 0) out float out_mask;

void main() {
  out_mask = 1.0;
}
