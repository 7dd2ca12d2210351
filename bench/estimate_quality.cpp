// How well the error estimate (results.json "estimate", docs/math.md "The error estimate") predicts the
// true error, in both dimensions: for each problem, variant and N, the ratio estimated/true for û in
// L²(ω) (relative), the force, ∫û, the energy and the contact measure, and per quantity how many runs lie
// within a factor 3.
// The true errors: against the exact solution on the manufactured problems of examples/ (all but the
// contact measure: their flux vanishes like t³ at the contact ends, a special case the references avoid);
// against the fitted-mesh references of tests/references (2-D: û in L²(ω) on the reference's rule and
// the contact measure from its ends; the force, ∫û and the energy from fictus's own smooth solve at
// N = 8192, since the references store no integrals, where the error is more than 3 times that solve's
// change from N = 4096; 3-D: the force, ∫û and the contact area the references store, where the error is
// more than 3 times the reference's own change between its last two meshes).
// Usage: fictus_bench_estimate [FILTER...]: only the cases whose name contains one of the filters
// ("2d", "3d", "manufactured", "reference", a problem's name); none: all (6.5 minutes on the 2-core machine of
// bench/results).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "reference_comparison.hpp"

namespace {

const std::string source = FICTUS_SOURCE_DIR;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

enum Quantity { l2, force, integral_u, energy, measure, n_quantities };
const std::array<const char*, n_quantities> quantity_names{"l2 (rel.)", "force", "integral_u", "energy", "measure"};

/// One run: the estimate and the true error of each quantity (NaN: not known for this problem).
struct Run {
  std::string problem, kind, variant;
  int dim = 2, N = 0;
  std::array<double, n_quantities> estimated{}, truth{};  // truth: the signed error (û's: its norm)
  std::array<double, n_quantities> values{};              // the reported force, ∫û, energy and contact measure
};

/// The estimate's five numbers.
template <int dim>
std::array<double, n_quantities> estimated(const fictus::BasicSolution<dim>& s) {
  if (!s.estimate || !s.estimate->skipped.empty()) return {nan, nan, nan, nan, nan};
  const fictus::ErrorEstimate& e = *s.estimate;
  return {e.rel_l2_omega, e.force, e.integral_u, e.energy, e.measure};
}

/// The quantities a solve reports (for true errors against a finer solve or a reference's values).
template <int dim>
std::array<double, n_quantities> reported(const fictus::BasicSolution<dim>& s) {
  const fictus::ContactSummary c = fictus::contact_summary(s);
  return {nan, c.force, s.domain->integral_u, s.domain->energy, c.measure};
}

template <int dim>
fictus::BasicProblemSpec<dim> read_spec(const std::string& file, int N, fictus::Variant variant) {
  fictus::BasicProblemSpec<dim> spec = fictus::parse_problem<dim>(fictus::read_problem_text(file), file);
  spec.problem.N = N;
  spec.options.variant = variant;
  spec.options.condition_number = false;
  spec.options.threads = 2;
  return spec;
}

fictus::Variant variant_of(const std::string& name) {
  return name == "smooth" ? fictus::Variant::smooth : fictus::Variant::nonsmooth;
}

/// The manufactured problem examples/<name>.toml: true errors against its exact solution. The exact
/// force c∫u − ∫f takes both integrals from the smooth solve at `fine_N` (∫u: that solve's ∫û less its
/// error against the exact u), since the solves' errors.force, c(∫û − ∫u) on one rule, leaves out the
/// rule's error in ∫f, which the reported force and its estimate include.
template <int dim>
std::vector<Run> manufactured(const std::string& name, const std::string& variant, const std::vector<int>& Ns,
                              int fine_N) {
  const std::string file = source + "/examples/" + name + ".toml";
  static std::map<std::string, double> exact_forces;  // one per problem
  if (!exact_forces.count(name)) {
    auto fine_spec = read_spec<dim>(file, fine_N, fictus::Variant::smooth);
    fine_spec.options.error_estimate = false;
    const auto fine = fictus::solve<dim>(fine_spec.problem, fine_spec.options);
    exact_forces[name] =
        fine_spec.problem.c * (fine.domain->integral_u - fine.errors->integral_u) - fine.domain->integral_f;
  }
  std::vector<Run> runs;
  for (int N : Ns) {
    const auto spec = read_spec<dim>(file, N, variant_of(variant));
    const auto s = fictus::solve<dim>(spec.problem, spec.options);
    const fictus::ErrorNorms& e = *s.errors;
    const std::array<double, n_quantities> q = reported(s);
    runs.push_back({name,
                    "manufactured",
                    variant,
                    dim,
                    N,
                    estimated(s),
                    {e.rel_l2_omega, q[force] - exact_forces[name], e.integral_u, e.energy, nan},
                    q});
  }
  return runs;
}

/// The 2-D references' truths for the integrals: how much the N = 8192 solve changed from N = 4096.
std::vector<std::string> truth_notes;

/// A true error where it is more than 3 times the uncertainty of what it is measured against, else NaN
/// (not counted).
double counted(double error, double uncertainty) { return std::abs(error) > 3 * uncertainty ? error : nan; }

/// The 2-D reference tests/references/<name>: û in L²(ω) and the contact measure against the reference
/// (its ends are known to 2·10⁻⁵ in angle: the measure to about 1e-5), the integrals against fictus's smooth
/// solve at N = 8192, with |Q_4096 − Q_8192| as their uncertainty.
std::vector<Run> reference_2d(const std::string& name, const std::string& variant, const std::vector<int>& Ns) {
  const std::string folder = source + "/tests/references", file = folder + "/" + name + ".toml";
  const reference::Reference ref = reference::load(folder, name);
  struct Fine {
    std::array<double, n_quantities> values, uncertainty;
    double contact_length;
  };
  static std::map<std::string, Fine> fine_solves;  // one per reference
  if (!fine_solves.count(name)) {
    std::array<std::array<double, n_quantities>, 2> q;
    for (int k : {0, 1}) {
      auto spec = read_spec<2>(file, k == 0 ? 4096 : 8192, fictus::Variant::smooth);
      spec.options.error_estimate = false;
      q[std::size_t(k)] = reported(fictus::solve<2>(spec.problem, spec.options));
    }
    Fine f{q[1], {}, reference::contact_length(ref, *read_spec<2>(file, 256, fictus::Variant::smooth).problem.gamma)};
    for (int k = 0; k < n_quantities; ++k)
      f.uncertainty[std::size_t(k)] = std::abs(q[0][std::size_t(k)] - q[1][std::size_t(k)]);
    char line[200];
    std::snprintf(line, sizeof line, "| %s | %.1e | %.1e | %.1e |", name.c_str(), f.uncertainty[force],
                  f.uncertainty[integral_u], f.uncertainty[energy]);
    truth_notes.push_back(line);
    fine_solves[name] = f;
  }
  const Fine& fine = fine_solves[name];
  std::vector<Run> runs;
  for (int N : Ns) {
    const auto spec = read_spec<2>(file, N, variant_of(variant));
    const fictus::Solution s = fictus::solve<2>(spec.problem, spec.options);
    const std::array<double, n_quantities> q = reported(s);
    std::array<double, n_quantities> truth{};
    for (int k : {force, integral_u, energy})
      truth[std::size_t(k)] =
          counted(q[std::size_t(k)] - fine.values[std::size_t(k)], fine.uncertainty[std::size_t(k)]);
    truth[l2] = reference::compare(ref, s).level.l2_omega;
    truth[measure] = q[measure] - fine.contact_length;
    runs.push_back({"ref_" + name, "reference", variant, 2, N, estimated(s), truth, q});
  }
  return runs;
}

/// The 3-D reference tests/references/<name>: the force, ∫û and the contact area it stores; a true error
/// within 3 times the reference's own change between its last two meshes is not counted. The contact area
/// only where the reference stores it (the spheroid's, to 5e-7); the ellipsoid's contact fraction
/// converges at first order and changed by 1.2e-3 at the end: known to about 3e-3 of γ, too coarse.
std::vector<Run> reference_3d(const std::string& name, const std::string& variant, const std::vector<int>& Ns) {
  const std::string folder = source + "/tests/references";
  std::ifstream in(folder + "/" + name + ".json");
  const nlohmann::json j = nlohmann::json::parse(in), values = j["values"], changes = j["changes"];
  const bool has_area = values.contains("contact_area");
  std::vector<Run> runs;
  for (int N : Ns) {
    const auto spec = read_spec<3>(folder + "/" + name + ".toml", N, variant_of(variant));
    const fictus::SurfaceSolution s = fictus::solve<3>(spec.problem, spec.options);
    const std::array<double, n_quantities> q = reported(s);
    runs.push_back(
        {"ref_" + name,
         "reference",
         variant,
         3,
         N,
         estimated(s),
         {nan, counted(q[force] - values["force"].get<double>(), changes["force"].get<double>()),
          counted(q[integral_u] - values["int_u"].get<double>(), changes["int_u"].get<double>()), nan,
          has_area ? counted(q[measure] - values["contact_area"].get<double>(), changes["contact_area"].get<double>())
                   : nan},
         q});
  }
  return runs;
}

struct Case {
  std::string name;  // for the filters: "2d manufactured manufactured_circle smooth"
  std::function<std::vector<Run>()> run;
};

std::vector<Case> cases() {
  std::vector<Case> all;
  const std::vector<std::string> variants{"smooth", "nonsmooth"};
  for (const std::string& v : variants) {
    for (const char* p : {"manufactured_circle", "manufactured_ellipse", "manufactured_star"})
      all.push_back({std::string("2d manufactured ") + p + " " + v, [p, v] {
                       return manufactured<2>(p, v, {128, 256, 512, 1024}, 2048);
                     }});
    for (const char* p : {"ellipse", "peanut", "star", "tips"})
      all.push_back({std::string("2d reference ") + p + " " + v, [p, v] {
                       return reference_2d(p, v, {256, 512, 1024, 2048});
                     }});
    for (const char* p : {"manufactured_sphere", "manufactured_ellipsoid"})
      all.push_back({std::string("3d manufactured ") + p + " " + v, [p, v] {
                       return manufactured<3>(p, v, {48, 64, 96}, 128);
                     }});
    for (const char* p : {"spheroid3d", "ellipsoid3d"})
      all.push_back({std::string("3d reference ") + p + " " + v, [p, v] { return reference_3d(p, v, {64, 96, 128}); }});
  }
  return all;
}

std::string cell(double est, double truth) {
  if (std::isnan(est) || std::isnan(truth)) return "";
  char text[64];
  std::snprintf(text, sizeof text, "%.1e / %.1e (%.2f)", est, std::abs(truth), est / std::abs(truth));
  return text;
}

bool within_3(double est, double truth) { return est / std::abs(truth) >= 1.0 / 3 && est / std::abs(truth) <= 3; }

/// Whether a run's error looks asymptotic against the run at N/2 of the same case (when there is one):
/// the same sign, and smaller by a factor of 2 to 8 (orders 1 to 3). Richardson's rule assumes it.
/// −1: no run at N/2.
int asymptotic(const std::vector<Run>& runs, const Run& r, int q) {
  for (const Run& c : runs)
    if (c.problem == r.problem && c.variant == r.variant && 2 * c.N == r.N) {
      const double fine = r.truth[std::size_t(q)], coarse = c.truth[std::size_t(q)];
      if (std::isnan(fine) || std::isnan(coarse)) return -1;
      return fine * coarse > 0 && std::abs(coarse) >= 2 * std::abs(fine) && std::abs(coarse) <= 8 * std::abs(fine);
    }
  return -1;
}

void summary(const std::vector<Run>& runs) {
  std::printf("\n| quantity | dim | problems | runs | within 3× | median ratio | min | max |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int q = 0; q < n_quantities; ++q)
    for (int dim : {2, 3})
      for (const char* kind : {"manufactured", "reference"}) {
        std::vector<double> ratios;
        int within = 0;
        for (const Run& r : runs) {
          const double e = r.estimated[std::size_t(q)], t = r.truth[std::size_t(q)];
          if (r.dim != dim || r.kind != kind || std::isnan(e) || std::isnan(t)) continue;
          ratios.push_back(e / std::abs(t));
          within += within_3(e, t);
        }
        if (ratios.empty()) continue;
        std::sort(ratios.begin(), ratios.end());
        std::printf("| %s | %d | %s | %zu | %d | %.2f | %.2g | %.2g |\n", quantity_names[std::size_t(q)], dim, kind,
                    ratios.size(), within, ratios[ratios.size() / 2], ratios.front(), ratios.back());
      }
  // All runs, and split by whether the error looked asymptotic from N/2 to N.
  std::printf("\n| quantity | runs | within 3× | share | asymptotic runs: within 3× | others: within 3× |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (int q = 0; q < n_quantities; ++q) {
    std::array<int, 3> runs_in{}, within_in{};  // [not asymptotic, asymptotic, no run at N/2]
    for (const Run& r : runs) {
      const double e = r.estimated[std::size_t(q)], t = r.truth[std::size_t(q)];
      if (std::isnan(e) || std::isnan(t)) continue;
      const int a = asymptotic(runs, r, q);
      const std::size_t k = a < 0 ? 2 : std::size_t(a);
      ++runs_in[k], within_in[k] += within_3(e, t);
    }
    const int all = runs_in[0] + runs_in[1] + runs_in[2], inside = within_in[0] + within_in[1] + within_in[2];
    if (all > 0)
      std::printf("| %s | %d | %d | %.0f %% | %d of %d | %d of %d |\n", quantity_names[std::size_t(q)], all, inside,
                  100.0 * inside / all, within_in[1], runs_in[1], within_in[0], runs_in[0]);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> filters(argv + 1, argv + argc);
    std::vector<Run> runs;
    std::printf("| problem | variant | N | l2 (rel.) | force | integral_u | energy | measure |\n");
    std::printf("|---|---|---|---|---|---|---|---|\n");
    for (const Case& c : cases()) {
      if (!filters.empty() && std::none_of(filters.begin(), filters.end(),
                                           [&](const std::string& f) { return c.name.find(f) != std::string::npos; }))
        continue;
      for (const Run& r : c.run()) {
        std::printf("| %s | %s | %d |", r.problem.c_str(), r.variant.c_str(), r.N);
        for (int q = 0; q < n_quantities; ++q)
          std::printf(" %s |", cell(r.estimated[std::size_t(q)], r.truth[std::size_t(q)]).c_str());
        std::printf("\n");
        std::fflush(stdout);
        runs.push_back(r);
      }
    }
    summary(runs);
    if (!truth_notes.empty()) {
      std::printf("\n| 2-D reference | force: N = 8192 against 4096 | integral_u | energy |\n|---|---|---|---|\n");
      for (const std::string& line : truth_notes) std::printf("%s\n", line.c_str());
    }
    if (const char* path = std::getenv("RAW")) {  // every run's numbers, for trying other estimates offline
      nlohmann::json out = nlohmann::json::array();
      for (const Run& r : runs)
        out.push_back({{"problem", r.problem},
                       {"kind", r.kind},
                       {"variant", r.variant},
                       {"dim", r.dim},
                       {"N", r.N},
                       {"estimated", r.estimated},
                       {"truth", r.truth},
                       {"values", r.values}});
      std::ofstream(path) << out.dump(1) << "\n";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fictus_bench_estimate: %s\n", e.what());
    return 1;
  }
}
