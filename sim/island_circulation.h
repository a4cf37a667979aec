// The stream function's value on each island's shore (algorithms.md §1.1: an island is a closed
// boundary with its own psi, which sets how the discharge splits between its arms).
//
// The value is the one that makes the flow around the island irrotational: potential flow in a
// region with holes is unique only once each hole's circulation is fixed, and a river parted by
// an island carries none. It comes from the potential flow itself: psi harmonic (the P1 finite
// elements' cotangent Laplacian on the river mesh), each bank at its own psi, each island's shore
// one unknown. The equation of that unknown is the sum of its shore's rows, which
// says the flux of grad psi out of the shore - the circulation of the velocity about the island -
// is zero. Islands are solved in clusters, each on the sections within half a river width of
// them, psi linear across the sections that close the cluster (the uniform flow away from an
// island), by conjugate gradients preconditioned with an incomplete Cholesky factor.
#pragma once

#include <vector>

#include "siviflow/sim/river_surface.h"
#include "siviflow/status.h"

namespace siviflow {

// psi on the shore of every island of `surface`, given psi on every other border (`border_psi`,
// by BorderId; the islands' entries are not read). Fails, naming the island, when its solve does
// not converge.
Status island_stream_values(const RiverSurface& surface, const std::vector<double>& border_psi,
                            std::vector<double>* out);

}  // namespace siviflow
