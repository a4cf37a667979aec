#include "end_discharges.h"

#include <algorithm>
#include <cmath>

#include "siviflow/text_format.h"

namespace siviflow {
namespace {

// Sums agree when they differ by less than this fraction of the larger (float inputs).
constexpr double kBalanceTolerance = 1e-5;

// Whether a and b agree, relative to the larger of them and `scale`.
bool agree(double a, double b, double scale = 0.0) {
  return std::abs(a - b) <= kBalanceTolerance * std::max({std::abs(a), std::abs(b), scale, 1e-30});
}

std::string end_name(const RiverSurface& s, size_t e) {
  const RiverEnd& end = s.ends()[e];
  const std::string named =
      end.mark != kNoEndMark ? text_format(", ends[%u]", end.mark) : std::string();
  return text_format("end %zu (the %s at vertex %u%s)", e, end.inflow ? "inflow" : "outflow",
                     s.vertex_of_node(s.end_nodes(e)[0]), named.c_str());
}

}  // namespace

Status end_discharges(const RiverSurface& surface, double total, const std::vector<float>& given,
                      std::vector<double>* out) {
  const auto ends = surface.ends();
  std::vector<double> q(ends.size(), 0.0);
  if (given.empty()) {
    const bool root_inflow = ends[0].inflow;
    double shared_width = 0.0;
    for (size_t e = 1; e < ends.size(); ++e) shared_width += ends[e].width;
    q[0] = total;
    for (size_t e = 1; e < ends.size(); ++e) {
      // Every other end is of the other kind: the root is the network's single inflow or outflow.
      q[e] = ends[e].inflow != root_inflow ? total * ends[e].width / shared_width : 0.0;
    }
    *out = std::move(q);
    return Status::success();
  }
  if (given.size() != ends.size()) {
    return Status::error(text_format("flow end discharges: %zu given for a river with %zu ends",
                                     given.size(), ends.size()));
  }
  double in = 0.0, out_sum = 0.0;
  for (size_t e = 0; e < ends.size(); ++e) {
    if (!std::isfinite(given[e]) || given[e] < 0.0f) {
      return Status::error(text_format("flow end discharge of %s is %g m^2/s: it must be 0 or more",
                                       end_name(surface, e).c_str(), given[e]));
    }
    q[e] = given[e];
    (ends[e].inflow ? in : out_sum) += q[e];
  }
  if (!agree(in, out_sum)) {
    return Status::error(text_format(
        "flow end discharges do not balance: %g m^2/s flows in and %g m^2/s out", in, out_sum));
  }
  if (!agree(in, total)) {
    return Status::error(text_format(
        "flow end discharges bring in %g m^2/s, but the river's discharge is %g m^2/s", in, total));
  }
  *out = std::move(q);
  return Status::success();
}

Status bank_stream_values(const RiverSurface& surface, const std::vector<double>& end_discharge,
                          std::vector<double>* out) {
  const auto ends = surface.ends();
  double scale = 0.0;
  for (const double q : end_discharge) scale += q;
  std::vector<double> psi(surface.border_count(), 0.0);
  std::vector<uint8_t> known(psi.size(), 0);
  known[kRightBankBorder] = 1;
  // Each pass settles every end with one border known; the ends form a ring, so E passes do.
  for (size_t pass = 0; pass < ends.size(); ++pass) {
    for (size_t e = 0; e < ends.size(); ++e) {
      const BorderId l = ends[e].left_border, r = ends[e].right_border;
      if (known[l] && !known[r]) psi[r] = psi[l] - end_discharge[e];
      if (known[r] && !known[l]) psi[l] = psi[r] + end_discharge[e];
      known[l] = known[r] = known[l] | known[r];
    }
  }
  for (size_t e = 0; e < ends.size(); ++e) {
    const BorderId l = ends[e].left_border, r = ends[e].right_border;
    if (!known[l] || !known[r] || !agree(psi[l] - psi[r], end_discharge[e], scale)) {
      return Status::error(text_format(
          "the stream function on the banks could not be set: %s carries %g m^2/s between "
          "borders %u and %u, which the other ends fix at a difference of %g",
          end_name(surface, e).c_str(), end_discharge[e], unsigned{l}, unsigned{r},
          psi[l] - psi[r]));
    }
  }
  *out = std::move(psi);
  return Status::success();
}

}  // namespace siviflow
