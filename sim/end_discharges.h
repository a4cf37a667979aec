// How the river's discharge divides among its ends, and the stream function on its banks that
// follows (algorithms.md §1.1: psi is constant on each border, and the discharge through an end
// is the difference of psi between the borders at its corners).
//
// Each end e carries q_e >= 0 (in through an inflow, out through an outflow), and looking
// downstream across it psi(left border) - psi(right border) = q_e. With psi = 0 on the right bank
// of the upstream end, walking the outer border from end to end gives every bank its psi; the
// walk closes only when the ends balance (the sum in equals the sum out).
#pragma once

#include <vector>

#include "siviflow/sim/river_surface.h"
#include "siviflow/status.h"

namespace siviflow {

// The discharge of every end of `surface` (in RiverSurface::ends() order): `given` when not
// empty, else the rule: the upstream end (the root of a network) carries `total` and the ends of
// the other kind share it in proportion to their widths. Fails, naming the end and the values,
// on a count that does not match, a negative or non-finite value, or ends that do not balance or
// disagree with `total`.
Status end_discharges(const RiverSurface& surface, double total, const std::vector<float>& given,
                      std::vector<double>* out);

// psi on every border that is not an island's (indexed by BorderId; island entries 0), from the
// ends' discharges.
Status bank_stream_values(const RiverSurface& surface, const std::vector<double>& end_discharge,
                          std::vector<double>* out);

}  // namespace siviflow
