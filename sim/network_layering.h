// Sections of a river network (paper §2, Algorithm 1, beyond a strip): a mesh with more than two
// open ends, its arms parting and joining at junctions, with any number of islands. The nodes
// split into layers by hop distance from the root end (the network's single inflow or single
// outflow); a layer's water splits into arm segments, each running from one border (a bank, a
// tongue between two arms, an island's shore) to another. Every vertex then lies between the
// two borders of its segment, as a strip's lies between its banks.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "strip_layering.h"

namespace siviflow {

// The outer border split at its corners into sides that alternate between ends and banks, in
// loop order; consecutive sides share their corner node.
struct NetworkSides {
  std::vector<std::vector<uint32_t>> sides;
  std::vector<uint8_t> is_end;
  size_t root = 0;  // the side of the single inflow or outflow: layers count from it
  bool root_is_inflow = true;
};

// One arm of one layer: water from a border node to a node of another border, left to right
// looking downstream.
struct ArmSegment {
  uint32_t layer = 0;
  uint32_t first = 0;  // nodes in NetworkLayering::segment_nodes
  uint32_t count = 0;
  uint32_t left_border = 0;  // network border indices (see NetworkLayering::border)
  uint32_t right_border = 0;
  glm::vec3 downstream{0.0f};  // horizontal unit
};

struct NetworkLayering {
  std::vector<uint32_t> layer;  // per node: 0 on the root end
  // Per node, its border: banks 0 .. bank_count - 1 in side order, then the islands; kNoNode in
  // the water (an end's nodes between its corners included).
  std::vector<uint32_t> border;
  uint32_t bank_count = 0;
  std::vector<uint32_t> side_bank;  // per side: its bank index, or kNoNode for an end
  std::vector<uint32_t> segment_nodes;
  std::vector<ArmSegment> segments;  // ascending by layer
  uint32_t max_layer = 0;
};

// Layers the network and splits its layers into arm segments. Fails, naming the vertices, where
// a triangle lies inside one layer, an end does not run across the flow, a layer branches or
// stops in the water, or a segment meets one border twice (a bay).
Status layer_network(const MeshView& mesh, const NetworkSides& sides, NetworkLayering* out);

}  // namespace siviflow
