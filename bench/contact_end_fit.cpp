// Experiment: the smooth variant's error where the contact ends fall between points. For each N:
// (a) the plain solve; (b) the same problem with the contact set fixed to the reference's exact
// intervals (u = g there, ∂u/∂n = 0 on the rest) and the points placed part by part, so arcs end at the
// exact ends; (c) the same with fictus's own located ends from (a).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "reference_comparison.hpp"

namespace {
double angle_of(const fictus::Point2& c, const fictus::Point2& x) {
  double t = std::atan2(x.y - c.y, x.x - c.x);
  return t < 0 ? t + 2 * std::numbers::pi : t;
}
// contact intervals given by sorted ends and flags: in_contact of (e_j, e_{j+1})
struct Intervals {
  std::vector<double> ends;
  std::vector<char> contact;
  bool at(double t) const {
    const std::size_t k = ends.size();
    for (std::size_t j = 0; j < k; ++j) {
      const double a = ends[j], b = ends[(j + 1) % k];
      const bool inside = a < b ? (t >= a && t < b) : (t >= a || t < b);
      if (inside) return contact[j];
    }
    return false;
  }
};
}  // namespace

int main(int argc, char** argv) {
  const std::string dir = std::string(FICTUS_SOURCE_DIR) + "/tests/references/";
  const std::string name = argc > 1 ? argv[1] : "tips";
  const fictus::Variant variant = (argc > 2 && std::string(argv[2]) == "nonsmooth") ? fictus::Variant::nonsmooth
                                                                                    : fictus::Variant::smooth;
  const reference::Reference ref = reference::load(dir, name);
  for (int a = 3; a < argc; ++a) {
    const int N = std::stoi(argv[a]);
    fictus::ProblemSpec spec = fictus::read_problem_file(dir + name + ".toml");
    spec.problem.N = N;
    spec.options.variant = variant;
    spec.options.condition_number = false;
    spec.options.error_estimate = false;
    spec.options.threads = 2;
    const fictus::Solution plain = fictus::solve(spec.problem, spec.options);
    const reference::Comparison cp = reference::compare(ref, plain);
    // exact intervals: the reference's ends alternate start, end of contact
    Intervals exact;
    {
      std::vector<std::pair<double, char>> e;
      for (std::size_t j = 0; j < ref.ends.size(); ++j) e.push_back({ref.ends[j], j % 2 == 0});
      std::sort(e.begin(), e.end());
      for (auto& [t, c] : e) exact.ends.push_back(t), exact.contact.push_back(c);
    }
    Intervals own;
    {
      for (const auto& x : plain.contact_boundary) own.ends.push_back(angle_of(ref.center, x));
      std::sort(own.ends.begin(), own.ends.end());
      for (std::size_t j = 0; j < own.ends.size(); ++j) {
        double a = own.ends[j], b = own.ends[(j + 1) % own.ends.size()];
        if (b <= a) b += 2 * std::numbers::pi;
        const double mid = 0.5 * (a + b);
        // nearest point's status
        int best = 0;
        double bd = 1e300;
        for (int i = 0; i < plain.collocation.m; ++i) {
          double d = std::abs(std::remainder(angle_of(ref.center, plain.collocation.point[i]) - mid, 2 * std::numbers::pi));
          if (d < bd) bd = d, best = i;
        }
        own.contact.push_back(plain.in_contact(best));
      }
    }
    auto fixed = [&](const Intervals& iv) {
      fictus::Problem p = spec.problem;
      const auto g = spec.problem.g_along_curve;
      const fictus::Point2 c = ref.center;
      p.conditions.dirichlet = [iv, c](const fictus::Point2& x) { return iv.at(angle_of(c, x)) ? 1.0 : 0.0; };
      p.conditions.neumann = [iv, c](const fictus::Point2& x) { return iv.at(angle_of(c, x)) ? 0.0 : 1.0; };
      p.conditions.u = [g](const fictus::Point2& x) { return g(x.x, x.y, 0.0); };  // g of the tips problem depends on x, y only
      const fictus::Solution s = fictus::solve(p, spec.options);
      return reference::compare(ref, s);
    };
    const reference::Comparison ce = fixed(exact), co = fixed(own);
    std::printf("N %5d m %5d  plain %.3e (ends %.3f s)  exact-ends %.3e  own-ends %.3e", N, plain.collocation.m,
                cp.level.l2_omega, cp.resolved_end_error_spacings, ce.level.l2_omega, co.level.l2_omega);
    for (int passes = 1; passes <= 3; ++passes) {
      fictus::SolverOptions o = spec.options;
      o.fit_contact = passes;
      const fictus::Solution f = fictus::solve(spec.problem, o);
      const reference::Comparison cf = reference::compare(ref, f);
      std::printf("  fit%d %.3e (ends %.3f s, moved %.3f, newton %d, %.2f s of %.2f s)", passes, cf.level.l2_omega,
                  cf.resolved_end_error_spacings, f.contact_fit ? f.contact_fit->moved.back() : -1.0,
                  f.newton.iterations, f.contact_fit ? f.contact_fit->seconds : 0.0, f.timings.total);
    }
    std::printf("  plain %.2f s\n", plain.timings.total);
    std::fflush(stdout);
  }
}
