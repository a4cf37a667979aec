// StreamFunction::find_junctions: where the arms of a river network meet, for the field beyond
// (stream_function.h).
#include <algorithm>

#include "siviflow/sim/stream_function.h"

namespace siviflow {
namespace {

// A tongue's tip: the section where it ends nearest the root, and the arms either side there.
struct TongueTip {
  BorderId tongue = 0;
  uint32_t section = 0;
  BorderId left = 0, right = 0;  // the arms' other borders
  double left_width = 0.0, right_width = 0.0;
};

}  // namespace

void StreamFunction::find_junctions() {
  const RiverSurface& s = surface_;
  if (!s.network()) return;
  // A tongue ends nearest the root end: in its last section in a confluence, its first in a fork.
  const bool confluence = !s.ends()[0].inflow;
  const auto section = s.node_section();
  std::vector<TongueTip> tips;
  for (size_t b = 0; b < s.banks().size(); ++b) {
    TongueTip tip;
    tip.tongue = s.banks()[b].border;
    if (tip.tongue < island_border(s.islands().size())) continue;  // a bank of the root end
    const auto path = s.bank_nodes(b);
    tip.section = section[path[0]];
    for (const uint32_t n : path) {
      tip.section =
          confluence ? std::max(tip.section, section[n]) : std::min(tip.section, section[n]);
    }
    // The arms either side: the water of that section beside the tongue (a blunt tip has
    // several nodes there, a pointed one one).
    for (const uint32_t m : s.section_nodes(tip.section)) {
      const BorderId l = s.node_left_border(m), r = s.node_right_border(m);
      const double width = double{s.node_d_left()[m]} + s.node_d_right()[m];
      if (r == tip.tongue && l != tip.tongue) {
        tip.left = l;
        tip.left_width = width;
      }
      if (l == tip.tongue && r != tip.tongue) {
        tip.right = r;
        tip.right_width = width;
      }
    }
    if (tip.left_width > 0.0 && tip.right_width > 0.0) tips.push_back(tip);
  }
  // Tips of one section whose arms touch (one's right arm the next's left: between the two
  // tongues) are one junction; each begins at a tip with no such neighbour on its left.
  auto right_of = [&](const TongueTip& a) {
    return std::find_if(tips.begin(), tips.end(), [&](const TongueTip& b) {
      return b.section == a.section && a.right == b.tongue && b.left == a.tongue;
    });
  };
  for (const TongueTip& first : tips) {
    const bool has_left = std::any_of(tips.begin(), tips.end(), [&](const TongueTip& a) {
      return a.section == first.section && a.right == first.tongue && first.left == a.tongue;
    });
    if (has_left) continue;
    Junction junction;
    junction.along = s.sections()[first.section].along;
    junction.left = first.left;
    std::vector<std::pair<double, BorderId>> at;  // the width left of each tip, its tongue
    double width = first.left_width;
    auto tip = tips.begin() + (&first - tips.data());
    for (size_t steps = 0; tip != tips.end() && steps < tips.size(); ++steps) {
      at.emplace_back(width, tip->tongue);
      width += tip->right_width;
      junction.right = tip->right;
      tip = right_of(*tip);
    }
    for (const auto& [left_width, tongue] : at)
      junction.dividers.emplace_back(left_width / width, border_psi_[tongue]);
    junctions_.push_back(std::move(junction));
  }
}

}  // namespace siviflow
