// What our tools and tests read of a renderer's simulation, beyond the embedding interface (not
// installed): the particles of the last simulated frame, the flow texture's layout, the
// river's flow per vertex and the water's triangles drawn.
#pragma once

#include "siviflow/renderer.h"
#include "sim/flow_textures.h"
#include "sim/particles.h"

namespace siviflow {

class RendererInspector {
 public:
  // The particles of the last simulated frame (particles() in id order, their parameters).
  static const ParticleField& particle_field(const Renderer& renderer);
  // Where the flow texture's and the aux data's texels are (sizes, texel size in pixels).
  static const FlowTextureLayout& flow_texture_layout(const Renderer& renderer);
  // The river's flow per vertex as the next update's particles read it (shared by its views).
  static const RiverFlowField& flow_field(const Renderer& renderer);
  // The triangles of the water surface the last updated view draws (its chunks in view).
  static uint32_t drawn_water_triangles(const Renderer& renderer);
  // Whether the flow reads the river's positions and indices from the GPU's vertex and index
  // buffers (a unified-memory device's) rather than from a copy of its own.
  static bool flow_reads_gpu_mesh(const Renderer& renderer);
  // The last updated frame's ReflectionView::area, and the reflection target's size.
  static VkRect2D reflection_area(const Renderer& renderer);
  static VkExtent2D reflection_extent(const Renderer& renderer);
  // The last updated frame's part of the view the refraction copy takes (view pixels).
  static VkRect2D refraction_area(const Renderer& renderer);
};

inline const ParticleField& particle_field(const Renderer& renderer) {
  return RendererInspector::particle_field(renderer);
}
inline const FlowTextureLayout& flow_texture_layout(const Renderer& renderer) {
  return RendererInspector::flow_texture_layout(renderer);
}
inline const RiverFlowField& flow_field(const Renderer& renderer) {
  return RendererInspector::flow_field(renderer);
}
inline uint32_t drawn_water_triangles(const Renderer& renderer) {
  return RendererInspector::drawn_water_triangles(renderer);
}

}  // namespace siviflow
