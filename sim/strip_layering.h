// Sections of a river mesh from its topology (paper §2, Algorithm 1): the nodes split into rows
// by hop distance from the upstream end, and the checks that the rows make a strip. A strip may
// have islands (holes): a row that meets an island goes on from the island's far side, and the
// island's shore edges across the flow join nodes of one row.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <string>
#include <vector>

#include "siviflow/status.h"

namespace siviflow {

inline constexpr uint32_t kNoNode = 0xffffffffu;

// A CSR adjacency: neighbours of node n are list[start[n] .. start[n+1]).
struct Csr {
  std::vector<uint32_t> start;
  std::vector<uint32_t> list;
  std::span<const uint32_t> of(uint32_t n) const {
    return {list.data() + start[n], start[n + 1] - start[n]};
  }
};

// What a successful layering from one candidate upstream end gives.
struct Layering {
  std::vector<uint32_t> layer;        // section of every node
  std::vector<uint32_t> chain_start;  // per section, offset into chain_nodes (+1 at the end)
  // Sections, each from bank_a to bank_b; where a section meets an island it goes on from the
  // island's node on the far side (the two are consecutive here but share no edge).
  std::vector<uint32_t> chain_nodes;
  std::vector<uint32_t> bank_a;  // shore node of every section on one bank
  std::vector<uint32_t> bank_b;  // ... and on the other
};

// Everything the layering reads: the welded mesh and its islands.
struct MeshView {
  const std::vector<glm::vec3>* positions;
  const std::vector<uint32_t>* tris;
  const Csr* adjacency;
  const std::vector<uint32_t>* node_vertex;  // node -> first input vertex, for messages
  // Island border loops, each in border order; node_island[n] is the island of node n or
  // kNoNode (empty when there are no islands).
  const std::vector<std::vector<uint32_t>>* islands;
  const std::vector<uint32_t>* node_island;
};

std::string vertex_name(const MeshView& mesh, uint32_t node);

// Length of a path of nodes (a side of the border), in double.
double path_length(const std::vector<glm::vec3>& pos, const std::vector<uint32_t>& path);

// Hop distance of every node from `sources` (the mesh is connected: every node is reached).
std::vector<uint32_t> hops_from(const Csr& adj, const std::vector<uint32_t>& sources);

// Hops from `sources` where the edges in `free_edges` (each node's at most two) cost nothing:
// a 0-1 breadth-first pass, so a shore's edges across the flow join nodes of one section.
std::vector<uint32_t> layers_with_free_edges(const Csr& adj, const std::vector<uint32_t>& sources,
                                             const std::vector<std::array<uint32_t, 2>>& free_edges);

// Splits the mesh into sections by hop distance from the upstream end `end_a` (a border path),
// then checks that the result is a strip: every triangle joins two neighbouring sections, every
// section is one chain from bank to bank (around its islands), each bank holds exactly one
// vertex per section, and the last section is the far end `end_b`. bank_1 runs from
// end_a.back() to end_b.front(), bank_2 from end_a.front() to end_b.back().
Status layer_strip(const MeshView& mesh, const std::vector<uint32_t>& end_a,
                   const std::vector<uint32_t>& end_b, const std::vector<uint32_t>& bank_1,
                   const std::vector<uint32_t>& bank_2, Layering* out);

}  // namespace siviflow
