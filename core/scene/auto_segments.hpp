// Segment counts chosen for an accuracy (docs/study_files.md "segments": "auto"): the number of
// segments of a beam follows from its own bending frequencies.
//
// A segmented beam is a chain of massless elastic sub-beams between generated bodies that carry
// the distributed mass (core/scene/scene_loader.cpp). Its discretization error shows first in its
// bending frequencies, which converge at order 2 in the number of segments n. The rule models the
// beam alone as a clamped-free member in each of its two bending planes, with exactly the stiffness
// and lumped masses beamrail gives it, and estimates the relative error of a frequency at n
// segments from the same beam at 2n and 4n: e(n) = |f(n) - f(2n)| / (1 - 2^-p) / f(2n), p the
// observed order clamped to [1, 2] (Richardson). It picks the smallest n of a ladder (1, 2, 3, 4,
// 5, 6, 8, 10, ... 128) at which every checked frequency is within the target: the first bending
// frequency of each plane, and with a band every one up to max_frequency_hz plus, for a frequency
// of the band above the last of them, the next one's error scaled by max_frequency_hz over its
// frequency (the error grows like the wavenumber squared, i.e. like the frequency).
#pragma once

#include <string>
#include <vector>

#include "core/model/model.hpp"

namespace beamrail {

// What "segments": "auto" aims at (the scene's "segmentation" object).
struct SegmentationTarget {
  double frequency_error = 1e-3;  // relative error of each checked bending frequency
  double max_frequency_hz = 0.0;  // check every bending frequency up to this; 0: the first only
};

// A beam as the rule sees it: length and, per bending plane (about local y, about local z), its
// bending stiffness E I and rotary density rho I; the mass per length rho S.
struct UniformBeam {
  double length = 0.0;           // [m]
  double ei[2] = {0.0, 0.0};     // [N m^2]
  double rho_i[2] = {0.0, 0.0};  // [kg m]
  double rho_area = 0.0;         // [kg/m]
};

// The bending frequencies [Hz], ascending, in the plane about local y (plane 0) or z (plane 1) of
// the beam clamped at one end and free at the other, split into n segments as beamrail splits it:
// Euler-Bernoulli segments of length l = L/n, interior bodies of mass rho S l and rotary inertia
// rho I l + rho S l^3 / 12, the free end half of that (rho I l / 2 + rho S l^3 / 24). The lowest
// `count` of them (all 2n when count is 0 or at least 2n).
std::vector<double> cantilever_bending_frequencies(const UniformBeam& beam, int plane, long n,
                                                   long count = 0);

// The largest count the rule picks; beyond it the target is reported as missed.
inline constexpr long kMaxAutoSegments = 128;

// The smallest count of the ladder that meets `target` for `beam` (named `name` in the result).
SegmentChoice choose_segments(const std::string& name, const UniformBeam& beam,
                              const SegmentationTarget& target);

}  // namespace beamrail
