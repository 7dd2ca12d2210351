#pragma once
// The number of multipliers m and the smooth variant's distance δ of Γ from γ, in any dimension
// (docs/math.md, "Rules for m and δ"). The multipliers sit at spacing s = L/m on a curve of length
// L (dim = 2) or s = √(A/m) on a surface of area A (dim = 3); Γ is γ moved by δ along its outward
// normal. The rules:
//   m  formulation.multipliers, or the default rule's m (a few cells per spacing; the caller's);
//      8 <= m and s >= 2h;
//   δ  formulation.offset·s when the offset is given; the default rule δ = 2·s on a curve and
//      δ = 1.5·s on a surface otherwise (default_offset).
//      Γ needs 4h <= δ (reconstructed traces: the C_γ stencil reaches 2.1h from γ, the cells cut
//      by Γ 1.4h from Γ) and δ <= room(h) (Γ keeps 2h from ∂Ω and does not fold).
// On a coarse grid the default rule may not fit: then δ is the nearest value that does, and with
// the default m the points move closer (m grows, s = δ/default_offset, down to s = 2h), with a warning. A
// given offset that does not fit, or a grid where nothing fits, is refused with the offsets or the
// N that would fit, before any grid work.
#include <functional>
#include <string>

#include "fictus/solve/solver_options.hpp"

namespace fictus {

/// The default rule's δ/s. The piecewise-constant controls on Γ leave a ripple of relative size about
/// e^{−2πδ/s}, whose error in û falls more slowly with N than the second-order one (docs/math.md "Rules
/// for m and δ"): on a curve, from N ≈ 2048 on, δ = 1.5·s let it overtake the second-order error and
/// δ = 2·s keeps it below; on a surface, at N = 96 and 128 on the references, δ = 2·s moved the
/// quantities both ways, and it would leave Γ no room on more coarse grids, so surfaces keep 1.5·s.
constexpr double default_offset(int dim) { return dim == 2 ? 2.0 : 1.5; }

/// The largest δ for which Γ keeps 2h from ∂Ω and does not fold, at grid spacing h (+∞ when nothing
/// limits it; below 0 when γ itself is within 2h of ∂Ω).
using OffsetRoom = std::function<double(double h)>;

/// The spacing s of m multipliers on a boundary of measure `measure` (length or area).
double multiplier_spacing(int dim, double measure, int m);

struct SpacingPlan {
  int m = 0;
  double spacing = 0;   // s
  double offset = 0;    // δ/s in effect (smooth variant; the option as given in the non-smooth one)
  double delta = 0;     // δ (smooth variant; 0 in the non-smooth one)
  std::string warning;  // one line when the default rule was changed to fit, else empty
};

/// The boundary a spacing is planned for, and its grid.
struct SpacingInput {
  int dim = 2;
  double measure = 0;  // L or A
  double h = 0;
  double box_width = 0;                    // along x: N = box_width/h (to name an N that fits)
  std::function<int(double h)> default_m;  // the default rule's m at grid spacing h
  OffsetRoom room;                         // smooth variant only
};

/// m, s and δ by the rules above; throws std::invalid_argument naming formulation.multipliers or
/// formulation.offset when they cannot be met.
SpacingPlan plan_spacing(const SpacingInput& input, const SolverOptions& options);

}  // namespace fictus
