// The contact fit (solver.fit_contact, docs/math.md "Fitting the points to the contact set") against the
// 2-D fitted-mesh references: relative L²(ω) errors and the located ends' distance from the reference's,
// per N, for 0 … 3 passes, and for the limit the fit aims at: the same problem with the contact set
// fixed to the reference's own intervals (u = g there, ∂u/∂n = 0 elsewhere, mixed conditions), whose
// points are placed part by part so that their arcs end at the exact ends. Least-squares rates over the
// powers of two and over all N, and the spread of error·N² (1 for clean second order).
// Usage: fictus_bench_contact_fit REFERENCE smooth|nonsmooth N... (accuracy only; times are one run each).
//        fictus_bench_contact_fit REFERENCE shifted N...: the smooth variant's error with the contact set
//        fixed to the reference's intervals with each end moved along γ by δ spacings s = L/m (δ > 0: the
//        contact set grows), for δ = −0.5 … 0.1: how much an error of the located ends costs.
//        fictus_bench_contact_fit REFERENCE quadrature N_FINE N...: each N's error against the reference
//        and against fictus's own solve at N_FINE, on the reference's rule and on one 64 times finer.
//        Trials: OFFSET=x sets formulation.offset in every mode's solves; in the quadrature mode also
//        FIT=k (solver.fit_contact) and VARIANT=smooth|nonsmooth. The settings in effect head the output.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "reference_comparison.hpp"

namespace {

/// A trial's setting from the environment variable `name`, if set: a number, or the run stops.
std::optional<double> trial_setting(const char* name) {
  const char* text = std::getenv(name);
  if (!text) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value))
    throw std::invalid_argument(std::string(name) + ": not a number: '" + text + "'");
  return value;
}

/// formulation.offset from OFFSET (every mode).
void offset_override(fictus::SolverOptions& o) {
  if (const auto offset = trial_setting("OFFSET")) o.offset = *offset;
}

/// The quadrature mode's trials: OFFSET, FIT (solver.fit_contact), VARIANT = smooth or nonsmooth.
void overrides(fictus::SolverOptions& o) {
  offset_override(o);
  if (const auto passes = trial_setting("FIT")) o.fit_contact = int(*passes);
  if (const char* e = std::getenv("VARIANT")) {
    if (std::string(e) != "smooth" && std::string(e) != "nonsmooth")
      throw std::invalid_argument("VARIANT: smooth or nonsmooth, not '" + std::string(e) + "'");
    o.variant = std::string(e) == "nonsmooth" ? fictus::Variant::nonsmooth : fictus::Variant::smooth;
  }
}

/// The problem file at grid N as the bench solves it: the variant given, no condition number and no
/// estimate, 2 threads, the offset of a trial (OFFSET).
fictus::ProblemSpec bench_spec(const std::string& file, int N, fictus::Variant variant) {
  fictus::ProblemSpec spec = fictus::read_problem_file(file);
  spec.problem.N = N;
  spec.options.variant = variant;
  spec.options.condition_number = false;
  spec.options.error_estimate = false;
  spec.options.threads = 2;
  offset_override(spec.options);
  return spec;
}

/// A line naming the trial settings in effect, if any.
void print_trials() {
  std::string in_effect;
  for (const char* name : {"OFFSET", "FIT", "VARIANT"})
    if (const char* e = std::getenv(name)) in_effect += std::string(" ") + name + "=" + e;
  if (!in_effect.empty()) std::printf("trial settings:%s\n\n", in_effect.c_str());
}

/// The reference's contact intervals (polar angles about `centre`, [ends[2k], ends[2k+1]] in contact) with
/// each end moved along γ by `shift` in arc length, outwards (the contact set grows) for shift > 0.
std::vector<double> shifted_ends(const std::vector<double>& ends, const fictus::Point2& centre,
                                 const fictus::Curve& curve, double shift) {
  const fictus::ArcLengthTable table(curve);
  const double L = table.length(), pi = std::numbers::pi;
  const auto angle_at = [&](double t) { return reference::angle_about(centre, curve.position(t)); };
  const auto off = [pi](double a, double b) { return std::remainder(a - b, 2 * pi); };  // a − b in (−π, π]
  constexpr int samples = 20000;
  std::vector<double> moved;
  for (std::size_t k = 0; k < ends.size(); ++k) {
    // The parameter where γ's polar angle passes the end (γ is star-shaped about the centre).
    double lo = 0, hi = 0;
    for (int i = 0; i < samples; ++i) {
      const double a = 2 * pi * i / samples, b = 2 * pi * (i + 1) / samples;
      if (off(angle_at(a), ends[k]) <= 0 && off(angle_at(b), ends[k]) > 0) lo = a, hi = b;
    }
    if (hi == 0) throw std::runtime_error("shifted: gamma's polar angle about the centre never passes an end");
    for (int it = 0; it < 60; ++it) (off(angle_at(0.5 * (lo + hi)), ends[k]) <= 0 ? lo : hi) = 0.5 * (lo + hi);
    const double along = k % 2 == 0 ? -shift : shift;  // a start moves back, an end on
    const double s = std::fmod(table.s_of_t(0.5 * (lo + hi)) + along + L, L);
    moved.push_back(angle_at(table.t_of_s(s)));
  }
  return moved;
}

/// The problem with the contact set fixed to the intervals `ends` (u = g there, ∂u/∂n = 0 elsewhere; the
/// tips' g depends on x, y only).
fictus::Problem fixed_contact(const fictus::Problem& problem, const fictus::Point2& centre,
                              const std::vector<double>& ends) {
  fictus::Problem fixed = problem;
  const auto g = problem.g_along_curve;
  fixed.conditions.dirichlet = [=](const fictus::Point2& x) {
    return reference::in_contact(ends, reference::angle_about(centre, x)) ? 1.0 : 0.0;
  };
  fixed.conditions.neumann = [=](const fictus::Point2& x) {
    return reference::in_contact(ends, reference::angle_about(centre, x)) ? 0.0 : 1.0;
  };
  fixed.conditions.u = [g](const fictus::Point2& x) { return g(x.x, x.y, 0.0); };
  return fixed;
}

/// The shifted mode: one row per N.
void shifted(const reference::Reference& ref, const std::string& file, const std::vector<int>& Ns) {
  const std::vector<double> shifts = {-0.5, -0.3, -0.2, -0.15, -0.1, -0.05, -0.02, 0.0, 0.02, 0.05, 0.1};
  std::printf("| N | m |");
  for (double d : shifts) std::printf(" δ = %+.2f |", d);
  std::printf("\n|---|---|");
  for (std::size_t k = 0; k < shifts.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (int N : Ns) {
    fictus::ProblemSpec spec = bench_spec(file, N, fictus::Variant::smooth);
    spec.options.fit_contact = 0;
    const fictus::Solution plain = fictus::solve(spec.problem, spec.options);
    const double spacing = plain.collocation.length / plain.collocation.m;
    std::printf("| %d | %d |", N, plain.collocation.m);
    for (double d : shifts) {
      const std::vector<double> ends = shifted_ends(ref.ends, ref.center, *spec.problem.gamma, d * spacing);
      const fictus::Solution s = fictus::solve(fixed_contact(spec.problem, ref.center, ends), spec.options);
      std::printf(" %.2e |", reference::compare(ref, s).level.l2_omega);
      std::fflush(stdout);
    }
    std::printf("\n");
  }
}

/// The quadrature mode: each N's relative L²(ω) error three ways, against the reference on its own rule,
/// against a fictus solve at N_fine on that rule, and against the same on a rule 64 times finer (2048
/// angles, 64 Gauss points in ρ). If the reference's rule undersamples the error near the contact ends,
/// the first two swing together from one N to the next and the third does not.
void quadrature(const reference::Reference& ref, const std::string& file, int fine_N, const std::vector<int>& Ns) {
  const auto solve_at = [&file](int N) {
    fictus::ProblemSpec spec = bench_spec(file, N, fictus::Variant::smooth);
    overrides(spec.options);
    return fictus::solve(spec.problem, spec.options);
  };
  const fictus::Solution fine = solve_at(fine_N);
  const auto at = [](const fictus::Solution& s, const fictus::Point2& x) {
    return fictus::sample_q1(s.grid, s.u, s.grid.cell_x(x.x), s.grid.cell_y(x.y), x.x, x.y).value;
  };
  const double to_reference = reference::compare(ref, fine).level.l2_omega;
  std::printf("fictus at N = %d against the reference (its rule): %.2e\n\n", fine_N, to_reference);
  std::printf("| N | against the reference | against N = %d, the reference's rule | the same, 64× finer rule |\n",
              fine_N);
  std::printf("|---|---|---|---|\n");
  for (int N : Ns) {
    const fictus::Solution s = solve_at(N);
    const auto difference = [&](int n_theta, int n_rho) {  // ‖û_N − û_fine‖ on that polar rule
      double sum = 0;
      reference::for_each_polar_point(ref, n_theta, n_rho, [&](const fictus::Point2& x, double w, std::size_t) {
        sum += w * std::pow(at(s, x) - at(fine, x), 2);
      });
      return std::sqrt(sum);
    };
    std::printf("| %d | %.2e | %.2e | %.2e |\n", N, reference::compare(ref, s).level.l2_omega,
                difference(ref.n_theta, ref.n_rho) / ref.l2_omega,
                difference(16 * ref.n_theta, 4 * ref.n_rho) / ref.l2_omega);
    std::fflush(stdout);
  }
}

double fitted_rate(const std::vector<int>& N, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(N.size());
  for (std::size_t k = 0; k < N.size(); ++k) {
    const double x = -std::log(double(N[k])), y = std::log(e[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

int run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s REFERENCE smooth|nonsmooth|shifted N... | REFERENCE quadrature N_FINE N...\n",
                 argv[0]);
    return 1;
  }
  const std::string dir = std::string(FICTUS_SOURCE_DIR) + "/tests/references/", name = argv[1];
  const fictus::Variant variant =
      std::string(argv[2]) == "nonsmooth" ? fictus::Variant::nonsmooth : fictus::Variant::smooth;
  const reference::Reference ref = reference::load(dir, name);
  print_trials();
  if (std::string(argv[2]) != "quadrature" && (std::getenv("FIT") || std::getenv("VARIANT")))
    throw std::invalid_argument("FIT and VARIANT apply to the quadrature mode only");
  if (std::string(argv[2]) == "shifted") {
    std::vector<int> Ns;
    for (int a = 3; a < argc; ++a) Ns.push_back(std::stoi(argv[a]));
    shifted(ref, dir + name + ".toml", Ns);
    return 0;
  }
  if (std::string(argv[2]) == "quadrature") {
    std::vector<int> Ns;
    for (int a = 4; a < argc; ++a) Ns.push_back(std::stoi(argv[a]));
    quadrature(ref, dir + name + ".toml", std::stoi(argv[3]), Ns);
    return 0;
  }
  constexpr int max_passes = 3;
  std::vector<int> Ns;
  std::vector<std::vector<double>> errors(max_passes + 2);  // passes 0 … 3, then the exact ends
  std::printf("| N | m | exact ends | 0 passes | 1 | 2 | 3 | ends [s]: 0 / 1 / 2 / 3 | seconds: 0 / 2 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (int a = 3; a < argc; ++a) {
    const int N = std::stoi(argv[a]);
    const fictus::ProblemSpec spec = bench_spec(dir + name + ".toml", N, variant);
    Ns.push_back(N);
    std::string ends, seconds;
    int m = 0;
    for (int passes = 0; passes <= max_passes; ++passes) {
      fictus::SolverOptions o = spec.options;
      o.fit_contact = passes;
      const fictus::Solution s = fictus::solve(spec.problem, o);
      const reference::Comparison c = reference::compare(ref, s);
      errors[std::size_t(passes)].push_back(c.level.l2_omega);
      char text[64];
      std::snprintf(text, sizeof text, "%s%.3f", passes ? " / " : "", c.resolved_end_error_spacings);
      ends += text;
      if (passes == 0 || passes == 2) {
        std::snprintf(text, sizeof text, "%s%.2f", passes ? " / " : "", s.timings.total);
        seconds += text;
      }
      m = s.collocation.m;
    }
    // The contact set fixed to the reference's intervals.
    fictus::SolverOptions o = spec.options;
    o.fit_contact = 0;
    errors[max_passes + 1].push_back(
        reference::compare(ref, fictus::solve(fixed_contact(spec.problem, ref.center, ref.ends), o)).level.l2_omega);
    std::printf("| %d | %d | %.2e | %.2e | %.2e | %.2e | %.2e | %s | %s |\n", N, m, errors[max_passes + 1].back(),
                errors[0].back(), errors[1].back(), errors[2].back(), errors[3].back(), ends.c_str(), seconds.c_str());
    std::fflush(stdout);
  }
  std::vector<int> powers;
  for (int N : Ns)
    if ((N & (N - 1)) == 0) powers.push_back(N);
  std::printf("\n| | exact ends | 0 passes | 1 | 2 | 3 |\n|---|---|---|---|---|---|\n");
  const auto row = [&](const char* what, auto value) {
    std::printf("| %s", what);
    for (int k : {max_passes + 1, 0, 1, 2, 3}) std::printf(" | %.2f", value(errors[std::size_t(k)]));
    std::printf(" |\n");
  };
  row("rate, all N", [&](const std::vector<double>& e) { return fitted_rate(Ns, e); });
  if (powers.size() > 1)
    row("rate, powers of 2", [&](const std::vector<double>& e) {
      std::vector<double> p;
      for (std::size_t k = 0; k < Ns.size(); ++k)
        if ((Ns[k] & (Ns[k] - 1)) == 0) p.push_back(e[k]);
      return fitted_rate(powers, p);
    });
  row("max/min of error·N²", [&](const std::vector<double>& e) {
    double lo = 1e300, hi = 0;
    for (std::size_t k = 0; k < Ns.size(); ++k) {
      const double v = e[k] * double(Ns[k]) * double(Ns[k]);
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    return hi / lo;
  });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // a bad trial setting, a missing reference file, a refused problem
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
