// Holes cut in a grid strip (sections of equal vertex count, two triangles a quad): how the
// procedural river and the tests make islands.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <vector>

namespace siviflow {

// From a grid strip of `across` vertices a section (vertex k * across + j, quad (k, j) between
// sections k and k + 1 and vertices j and j + 1, its two triangles at 2 (k (across - 1) + j)
// and the next) removes the quads for which cut(k, j) holds, and then the vertices no triangle
// uses any more (`depth`, when given, follows the positions). A quad touching cut ones only at a
// corner is cut too, so every hole's shore is one simple loop. Returns the quads cut (none, and
// nothing changed, when the indices are not two triangles for each of the grid's quads).
size_t cut_grid_quads(uint32_t across, const std::function<bool(uint32_t, uint32_t)>& cut,
                      std::vector<glm::vec3>* positions, std::vector<uint32_t>* indices,
                      std::vector<float>* depth = nullptr);

}  // namespace siviflow
