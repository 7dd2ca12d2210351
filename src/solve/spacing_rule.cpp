#include "fictus/solve/spacing_rule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fictus/boundary/collocation.hpp"

namespace fictus {

namespace {

std::string format(const char* pattern, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buffer[320];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c, d, e);
  return buffer;
}

/// v rounded up (or down) to `digits` significant digits.
double round_to_digits(double v, int digits, bool up) {
  const double unit = std::pow(10.0, std::floor(std::log10(v)) + 1 - digits);
  if (!(unit > 0) || !std::isfinite(unit)) return v;
  return (up ? std::ceil(v / unit) : std::floor(v / unit)) * unit;
}

/// "[low, high]" with the fewest significant digits (at least three) whose printed ends, read back,
/// still lie within [low, high]: moved inward by a relative 1e-9 before rounding, so that the offset
/// a user copies from the message passes the check that refused the first one.
std::string printed_range(double low, double high) {
  const double lo = low * (1 + 1e-9), hi = high * (1 - 1e-9);
  char a[40], b[40];
  for (int digits = 3; digits <= 15 && lo > 0 && lo <= hi; ++digits) {
    std::snprintf(a, sizeof a, "%.*g", digits, round_to_digits(lo, digits, true));
    std::snprintf(b, sizeof b, "%.*g", digits, round_to_digits(hi, digits, false));
    const double read_a = std::strtod(a, nullptr), read_b = std::strtod(b, nullptr);
    if (lo <= read_a && read_a <= read_b && read_b <= hi) return std::string("[") + a + ", " + b + "]";
  }
  std::snprintf(a, sizeof a, "%.17g", 0.5 * (low + high));  // a range too narrow to print: its middle
  return std::string("[") + a + ", " + a + "]";
}

/// The most multipliers whose spacing is at least 2h.
long most_multipliers(int dim, double measure, double h) {
  const double m = dim == 2 ? measure / (2 * h) : measure / (4 * h * h);
  return long(std::min(m, 1e15));
}

/// The fewest multipliers whose spacing is at most s.
long multipliers_for_spacing(int dim, double measure, double s) {
  const double m = dim == 2 ? measure / s : measure / (s * s);
  return long(std::ceil(std::min(m, 1e15) * (1 - 1e-12)));
}

/// The smallest N >= `from` (doubling, then bisection) at which `fits(h)` holds, for a predicate
/// that holds from some N on; 0 when none up to 2^20 does.
int smallest_fitting_N(double box_width, int from, const std::function<bool(double h)>& fits) {
  long low = from, high = std::max(from, 8);
  while (!fits(box_width / high)) {
    low = high;
    high *= 2;
    if (high > (1L << 20)) return 0;
  }
  while (high - low > 1) {
    const long mid = (low + high) / 2;
    (fits(box_width / mid) ? high : low) = mid;
  }
  return int(high);
}

/// δ = offset·L/m on a curve, offset·s on a surface.
double delta_for(int dim, double measure, int m, double offset) {
  return dim == 2 ? offset * measure / m : offset * multiplier_spacing(dim, measure, m);
}

/// Γ's lower limit: the reconstructed C_γ stencil must not reach the cells that Γ cuts.
double lowest_delta(const SolverOptions& options, double h) {
  return options.normal_derivative == NormalDerivative::reconstructed ? 4 * h : 0.0;
}

}  // namespace

double multiplier_spacing(int dim, double measure, int m) { return dim == 2 ? measure / m : std::sqrt(measure / m); }

SpacingPlan plan_spacing(const SpacingInput& in, const SolverOptions& options) {
  const double h = in.h;
  SpacingPlan plan;
  const bool given_m = options.multipliers > 0;
  plan.m = given_m ? options.multipliers : in.default_m(h);
  const long most = most_multipliers(in.dim, in.measure, h);
  if (plan.m < minimum_multipliers)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(plan.m) +
                                " is too small (need m >= " + std::to_string(minimum_multipliers) + ")");
  plan.spacing = multiplier_spacing(in.dim, in.measure, plan.m);
  if (plan.spacing < 2 * h)
    throw std::invalid_argument("formulation.multipliers: m = " + std::to_string(plan.m) +
                                format(" is too large for the grid (spacing s = %.3g < 2h = %.3g; use m <= %.0f)",
                                       plan.spacing, 2 * h, double(most)));
  if (options.variant == Variant::nonsmooth) {
    plan.offset = options.offset;  // as given: no Γ to place
    return plan;
  }

  const auto delta_of = [&](double offset) { return delta_for(in.dim, in.measure, plan.m, offset); };
  const double lower = lowest_delta(options, h), upper = in.room(h);
  const int N = int(std::lround(in.box_width / h));
  if (!(lower <= upper)) {  // no δ fits at this N
    const int fitting =
        smallest_fitting_N(in.box_width, N, [&](double k) { return lowest_delta(options, k) <= in.room(k); });
    throw std::invalid_argument(
        format("formulation.offset: no room for Γ at N = %.0f: the box's 2h margin and Γ's folds allow δ <= %.3g "
               "(%.2f h), ",
               double(N), std::max(upper, 0.0), std::max(upper, 0.0) / h) +
        (lower > 0 ? format("the C_γ stencil needs δ >= 4h = %.3g; ", lower) : std::string()) +
        (fitting > 0 ? "N >= " + std::to_string(fitting) + " runs" : std::string("a larger box")));
  }
  if (options.offset > 0) {  // given: it fits, or the offsets that would are named
    plan.offset = options.offset;
    plan.delta = delta_of(options.offset);
    if (plan.delta < lower || plan.delta > upper)
      throw std::invalid_argument(
          format("formulation.offset: Γ at δ = offset·s = %.4g (%.3f h) ", plan.delta, plan.delta / h) +
          (plan.delta < lower ? format("is within reach of the C_γ stencil (need δ >= 4h = %.3g)", lower)
                              : format("has no room (the box's 2h margin and Γ's folds allow δ <= %.3g)", upper)) +
          format("; with m = %.0f (s = %.3g) offsets in ", plan.m, plan.spacing) +
          printed_range(std::max(lower / plan.spacing, 1e-3), upper / plan.spacing) + " fit");
    return plan;
  }
  // The default rule, δ = default_offset·s, moved to the nearest δ that fits; the default m follows so
  // that δ/s stays the default's where s >= 2h allows.
  const double standard = default_offset(in.dim);
  plan.offset = standard;
  plan.delta = delta_of(standard);
  if (lower <= plan.delta && plan.delta <= upper) return plan;
  const double wanted = plan.delta, wanted_cells = plan.spacing / h;
  plan.delta = std::max(lower, std::min(plan.delta, upper * (1 - 1e-9)));  // inside the room, not on its edge
  if (!given_m && plan.delta < wanted) {
    plan.m = int(std::clamp<long>(multipliers_for_spacing(in.dim, in.measure, plan.delta / standard), plan.m,
                                  std::max<long>(plan.m, most)));
    plan.spacing = multiplier_spacing(in.dim, in.measure, plan.m);
  }
  plan.offset = plan.delta / plan.spacing;
  const int keeps = given_m ? 0 : smallest_fitting_N(in.box_width, N, [&](double k) {
    const double d = delta_for(in.dim, in.measure, in.default_m(k), standard);
    return lowest_delta(options, k) <= d && d <= in.room(k);
  });
  plan.warning =
      format("formulation.offset: the default Γ (δ = %.3g s = %.3g h, s = %.3g h) does not fit at N = %.0f; using ",
             standard, wanted / h, wanted_cells, double(N)) +
      format(
          "δ = %.3g h and m = %.0f (s = %.3g h): nearer and finer than the default rule, less accurate "
          "(docs/math.md, \"Rules for m and δ\")",
          plan.delta / h, plan.m, plan.spacing / h) +
      (keeps > 0 ? "; N >= " + std::to_string(keeps) + " keeps the default" : std::string());
  return plan;
}

}  // namespace fictus
