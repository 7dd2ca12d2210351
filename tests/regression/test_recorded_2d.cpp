// The 2-D answers of fictus, recorded: the paper's problem (both variants, N = 128 … 1024, both trace
// rules, the periodic c = 0 setting, the Krylov path), every example and the fitted-mesh reference
// problems (both variants). Each case is reduced to digests of λ, the traces, û and the errors, and
// compared with tests/regression/recorded_2d.json to 1e-12 relative. A change of the code that moves
// an answer fails here; a change that is meant to move answers records them again:
//   FICTUS_RECORD=1 build/tests/fictus_regression_tests
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/paper_problem.hpp"
#include "recorded.hpp"

namespace {

using nlohmann::json;
const std::string source_dir = FICTUS_SOURCE_DIR;
const std::string recorded_path = source_dir + "/tests/regression/recorded_2d.json";

using fictus::regression::digest;

json summarize(const fictus::Solution& s) {
  json j;
  j["m"] = s.collocation.m;
  j["newton"] = s.newton.iterations;
  j["active"] = std::count(s.newton.active.begin(), s.newton.active.end(), 1);
  j["lambda"] = digest(s.lambda);
  j["trace"] = digest(s.trace);
  j["normal_derivative"] = digest(s.normal_derivative);
  j["u"] = digest(s.u);
  j["alpha"] = s.alpha;
  if (s.errors)
    j["errors"] = {s.errors->rel_l2_omega, s.errors->rel_h1_omega, s.errors->rel_h1semi_omega, s.errors->rel_l2_gamma};
  if (s.check) j["check"] = {s.check->max_difference, s.check->rms_difference};
  double u_max = 0;
  for (double v : s.u) u_max = std::max(u_max, std::abs(v));
  j["stencil_scale"] = u_max / s.grid.h();  // the size of a difference stencil's operands; not compared
  return j;
}

struct Case {
  std::string name;
  std::function<fictus::Solution()> run;
};

fictus::Solution paper(int N, fictus::Variant variant, std::function<void(fictus::SolverOptions&)> change = {},
                       double c = 1.0, fictus::Boundary boundary = fictus::Boundary::dirichlet) {
  fictus::SolverOptions options = fictus::paper_options(N, variant);
  if (change) change(options);
  return fictus::solve(fictus::paper_problem(N, c, boundary), options);
}

fictus::Solution from_file(const std::string& path, std::function<void(fictus::SolverOptions&)> change = {}) {
  fictus::ProblemSpec spec = fictus::read_problem_file(path);
  if (change) change(spec.options);
  return fictus::solve(spec.problem, spec.options);
}

std::vector<Case> cases() {
  using fictus::Variant;
  std::vector<Case> list;
  for (Variant variant : {Variant::nonsmooth, Variant::smooth})
    for (int N : {128, 256, 512, 1024})
      list.push_back({std::string("paper_") + fictus::to_string(variant) + "_" + std::to_string(N),
                      [=] { return paper(N, variant); }});
  for (Variant variant : {Variant::nonsmooth, Variant::smooth})
    list.push_back({std::string("paper_shifted_") + fictus::to_string(variant), [=] {
                      return paper(256, variant,
                                   [](auto& o) { o.normal_derivative = fictus::NormalDerivative::shifted; });
                    }});
  list.push_back({"paper_krylov_nonsmooth", [] {
                    return paper(256, Variant::nonsmooth, [](auto& o) { o.inner = fictus::InnerSolver::krylov; });
                  }});
  list.push_back(
      {"paper_periodic_c0_smooth", [] { return paper(256, Variant::smooth, {}, 0.0, fictus::Boundary::periodic); }});
  std::vector<std::filesystem::path> examples;
  for (const auto& entry : std::filesystem::directory_iterator(source_dir + "/examples"))
    if (entry.path().extension() == ".toml" &&
        fictus::problem_dimension(fictus::read_problem_text(entry.path().string())) == 2)  // 3-D: its own test
      examples.push_back(entry.path());
  std::sort(examples.begin(), examples.end());
  for (const auto& path : examples)
    list.push_back({"example_" + path.stem().string(), [path] { return from_file(path.string()); }});
  for (const char* name : {"ellipse", "star", "peanut"})
    for (Variant variant : {Variant::nonsmooth, Variant::smooth})
      list.push_back({std::string("reference_") + name + "_" + fictus::to_string(variant), [=] {
                        return from_file(source_dir + "/tests/references/" + name + ".toml",
                                         [=](auto& o) { o.variant = variant; });
                      }});
  return list;
}

TEST(Recorded2d, AnswersEqualTheRecordedValues) {
  json now;
  for (const Case& c : cases()) now[c.name] = summarize(c.run());
  if (std::getenv("FICTUS_RECORD")) {
    std::ofstream(recorded_path) << now.dump(1) << "\n";
    GTEST_SKIP() << "recorded " << now.size() << " cases to " << recorded_path;
  }
  std::ifstream in(recorded_path);
  ASSERT_TRUE(in) << "cannot read " << recorded_path;
  const json recorded = json::parse(in);
  EXPECT_EQ(recorded.size(), now.size());
  for (const auto& [name, values] : recorded.items()) {
    ASSERT_TRUE(now.contains(name)) << name << " is no longer computed";
    fictus::regression::compare_recorded(values, now[name], name);
  }
}

}  // namespace
