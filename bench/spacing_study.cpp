// The spacing study behind the default m and δ (docs/math.md, "Rules for m and δ"):
// relative L²(ω) errors, least-squares rates over N = 256 … 2048, cond(S) at the finest level and the
// contact-end error (fitted-mesh references) for s/h = 4, 6, 8, 12, the paper's m ∝ N^0.85, and
// offsets δ/s = 1, 1.5, 2 (smooth variant), on the manufactured problems and the references.
// With --before-after: per problem and variant, the full table (N, m, Newton, L²(ω), H¹(ω), L²(γ),
// contact-end error) for the earlier defaults (shifted C_γ, m ∝ N^0.85, δ = s) and the current ones.
// Usage: fictus_spacing_study [--out FILE.md] [--levels 8-11] [--before-after]. Accuracy only.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "fictus/boundary/collocation.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "manufactured_solutions.hpp"
#include "reference_comparison.hpp"

namespace {

struct Case {
  std::string name;
  fictus::Problem problem;
  const reference::Reference* reference;  // nullptr: the problem has an exact solution
};

std::string format(const char* f, auto... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, f, args...);
  return buffer;
}

/// Problem p at N: 0–2 the manufactured circle, ellipse, star; 3–5 the references.
Case make_case(int p, int N, const std::vector<reference::Reference>& refs, const std::string& source) {
  if (p < 3) {
    const auto all = manufactured::all(N);
    return {"manufactured " + all[p].name, all[p].problem, nullptr};
  }
  const reference::Reference& r = refs[p - 3];
  fictus::ProblemSpec spec = fictus::read_problem_file(source + "/tests/references/" + r.name + ".toml");
  spec.problem.N = N;
  return {"reference " + r.name, spec.problem, &r};
}

/// m for a spacing of `cells` cells (0: the paper's growth m = 34·(N/128)^0.85 scaled by L).
int multipliers(double L, int N, double cells) {
  if (cells > 0) return std::max(8, int(std::lround(L * N / cells)));
  constexpr double paper_length = 1.9376896441095;  // the paper's ellipse
  return std::max(8, int(std::lround(34.0 * L / paper_length * std::pow(N / 128.0, 0.85))));
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path;
  int first = 8, last = 11;
  bool before_after = false;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--before-after")
      before_after = true;
    else if (a == "--out" && k + 1 < argc)
      out_path = argv[++k];
    else if (a == "--levels" && k + 1 < argc)
      std::sscanf(argv[++k], "%d-%d", &first, &last);
  }
  const std::string source = FICTUS_SOURCE_DIR;
  std::vector<reference::Reference> refs;
  for (const char* name : {"ellipse", "star", "peanut"})
    refs.push_back(reference::load(source + "/tests/references", name));

  std::ostringstream report;
  if (before_after) {
    report << "# Before and after: earlier defaults (shifted C_γ, m ∝ N^0.85, δ = s) vs current (reconstructed "
              "traces, s = 8h smooth / 12h non-smooth, δ = 2s)\n\nRelative errors; contact ends: largest distance of "
              "a reference end "
              "to fictus's, in spacings s.\n";
    for (int p = 0; p < 6; ++p)
      for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth})
        for (int after = 0; after < 2; ++after) {
          std::vector<fictus::LevelResult> rows;
          std::string name, lines;
          for (int level = first; level <= last; ++level) {
            const int N = 1 << level;
            const Case c = make_case(p, N, refs, source);
            name = c.name;
            fictus::SolverOptions o;
            o.variant = variant;
            o.threads = 2;
            o.condition_number = false;
            if (!after) {
              o.normal_derivative = fictus::NormalDerivative::shifted;
              o.offset = 1.0;
              o.multipliers = multipliers(fictus::ArcLengthTable(*c.problem.gamma).length(), N, 0.0);
            }
            try {
              const fictus::Solution s = fictus::solve(c.problem, o);
              fictus::LevelResult row{N, 0, s.collocation.m, s.newton.iterations, s.fast_solves, 0, 0, 0, 0};
              double ends = -1;
              if (c.reference) {
                const reference::Comparison cmp = reference::compare(*c.reference, s);
                row.l2_omega = cmp.level.l2_omega, row.h1_omega = cmp.level.h1_omega, row.l2_gamma = cmp.level.l2_gamma;
                ends = cmp.end_error_spacings;
              } else {
                row.l2_omega = s.errors->rel_l2_omega, row.h1_omega = s.errors->rel_h1_omega,
                row.l2_gamma = s.errors->rel_l2_gamma;
              }
              rows.push_back(row);
              lines += format("| %d | %d | %d%s | %.2e | %.2e | %.2e | %s |\n", N, row.m, row.it0,
                              s.newton.converged ? "" : " (failed)", row.l2_omega, row.h1_omega, row.l2_gamma,
                              ends >= 0 ? format("%.2f", ends).c_str() : "");
            } catch (const std::exception& e) {
              lines += format("| %d | | fails: %s | | | | |\n", N, e.what());
            }
          }
          const auto fit = rows.size() > 1 ? fictus::fitted_rates(rows) : std::array<double, 3>{};
          report << "\n### " << name << ", " << fictus::to_string(variant) << ", " << (after ? "current" : "earlier")
                 << "\n\n| N | m | Newton | L²(ω) | H¹(ω) | L²(γ) | ends/s |\n|---|---|---|---|---|---|---|\n"
                 << lines << format("| rates | | | %.2f | %.2f | %.2f | |\n", fit[0], fit[1], fit[2]);
          std::cerr << name << ' ' << fictus::to_string(variant) << (after ? " current" : " earlier")
                    << format(" rates %.2f %.2f %.2f", fit[0], fit[1], fit[2]) << std::endl;
        }
    if (out_path.empty())
      std::cout << report.str();
    else
      std::ofstream(out_path) << report.str();
    return 0;
  }
  report << "# Spacing study (bench/spacing_study.cpp)\n\n"
         << "Relative L²(ω) errors at N = 2^" << first << " … 2^" << last
         << ", least-squares rate, cond(S) and the largest contact-end error (in spacings) at the finest level.\n\n";
  for (const fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth}) {
    const std::vector<double> offsets =
        variant == fictus::Variant::smooth ? std::vector<double>{1.0, 1.5, 2.0} : std::vector<double>{1.0};
    report << "## " << fictus::to_string(variant) << " variant\n\n"
           << "| problem | s/h | δ/s | errors | rate | cond | Newton | ends/s |\n|---|---|---|---|---|---|---|---|\n";
    for (int p = 0; p < 6; ++p) {
      for (double cells : {4.0, 6.0, 8.0, 12.0, 0.0})
        for (double offset : offsets) {
          std::vector<fictus::LevelResult> rows;
          std::string errors, failure;
          double cond = 0, end_error = 0;
          int newton = 0;
          std::string name;
          for (int level = first; level <= last && failure.empty(); ++level) {
            const int N = 1 << level;
            const Case c = make_case(p, N, refs, source);
            name = c.name;
            fictus::SolverOptions o;
            o.variant = variant;
            o.offset = offset;
            o.threads = 2;
            o.multipliers = multipliers(fictus::ArcLengthTable(*c.problem.gamma).length(), N, cells);
            o.condition_number = level == last;
            try {
              const fictus::Solution s = fictus::solve(c.problem, o);
              if (!s.newton.converged) {
                failure = "Newton: " + s.newton.failure;
                break;
              }
              fictus::LevelResult row;
              if (c.reference) {
                const reference::Comparison cmp = reference::compare(*c.reference, s);
                row = cmp.level;
                end_error = cmp.end_error_spacings;
              } else {
                row = {N,
                       0,
                       s.collocation.m,
                       s.newton.iterations,
                       s.fast_solves,
                       0,
                       s.errors->rel_l2_omega,
                       s.errors->rel_h1_omega,
                       s.errors->rel_l2_gamma};
              }
              rows.push_back(row);
              errors += format("%s%.2e", errors.empty() ? "" : ", ", row.l2_omega);
              newton = s.newton.iterations;
              if (s.condition_number) cond = *s.condition_number;
            } catch (const std::exception& e) {
              failure = e.what();
            }
          }
          const std::string spacing = cells > 0 ? format("%g", cells) : "paper";
          std::string line;
          if (!failure.empty())
            line = format("| %s | %s | %g | %s | — | — | — | — |", name.c_str(), spacing.c_str(), offset,
                          ("fails: " + failure.substr(0, 90)).c_str());
          else
            line = format("| %s | %s | %g | %s | %.2f | %.1e | %d | %s |", name.c_str(), spacing.c_str(), offset,
                          errors.c_str(), fictus::fitted_rates(rows)[0], cond, newton,
                          p >= 3 ? format("%.2f", end_error).c_str() : "");
          report << line << '\n';
          std::cerr << line << std::endl;
        }
    }
    report << '\n';
  }
  if (out_path.empty()) {
    std::cout << report.str();
  } else {
    std::ofstream(out_path) << report.str();
  }
  return 0;
}
