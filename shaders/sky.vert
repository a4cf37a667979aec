#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared.h"
// Full-screen triangle on the far plane. The far-plane point of a pixel, before the divide by w,
// is linear in screen position: unprojected here for the three vertices only and interpolated,
// so the fragment shader needs no matrix inverse.
layout(push_constant) uniform Push { SceneConstants scene; };
layout(location = 0) out vec4 out_far_point;

void main() {
  vec2 ndc = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2)) * 2.0 - 1.0;
  float far_depth = scene.fog.w;  // 1, or 0 under reverse-Z (an infinite far plane: w = 0 below)
  out_far_point = inverse(scene.view_proj) * vec4(ndc, far_depth, 1.0);
  gl_Position = vec4(ndc, far_depth, 1.0);  // on the far plane: only where nothing was drawn
}
