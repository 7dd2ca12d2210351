// The 3-D answers of fictus, recorded: the manufactured sphere, ellipsoid, torus, implicit torus and
// mesh torus of examples/, both variants, N = 64 and 96, the default rule for δ. Each case is reduced to digests of λ,
// the traces, û and the errors, the active set and the Newton steps, and compared with
// tests/regression/recorded_3d.json to 1e-12 relative (the digests' sums of squares to 2e-12). A change
// of the code that moves an answer fails here; a change that is meant to move answers records them again:
//   FICTUS_RECORD=1 build/tests/fictus_regression_tests --gtest_filter='Recorded3d*'
// (each case writes its own entry; the others in the file are kept).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/io/problem_file.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/surface_discretization.hpp"
#include "recorded.hpp"

namespace {

using fictus::regression::digest;
using nlohmann::json;
const std::string source_dir = FICTUS_SOURCE_DIR;
const std::string recorded_path = source_dir + "/tests/regression/recorded_3d.json";

struct Case3d {
  std::string example;  // examples/manufactured_<example>.toml
  fictus::Variant variant;
  int N;
  std::string name() const { return example + "_" + fictus::to_string(variant) + "_" + std::to_string(N); }
};

json summarize(const fictus::SurfaceSolution& s) {
  json j;
  j["m"] = s.gamma.m;
  j["newton"] = s.newton.iterations;
  j["active"] = digest(s.newton.active);
  j["lambda"] = digest(s.lambda);
  j["trace"] = digest(s.trace);
  j["normal_derivative"] = digest(s.normal_derivative);
  j["u"] = digest(s.u);
  j["alpha"] = s.alpha;
  j["delta"] = s.delta;
  if (s.errors)
    j["errors"] = {s.errors->rel_l2_omega, s.errors->rel_h1_omega, s.errors->rel_h1semi_omega, s.errors->rel_l2_gamma};
  return j;
}

fictus::SurfaceSolution solve(const Case3d& c) {
  const std::string path = source_dir + "/examples/manufactured_" + c.example + ".toml";
  fictus::SurfaceProblemSpec spec = fictus::parse_surface_problem_text(fictus::read_problem_text(path), path);
  spec.problem.N = c.N;
  spec.options.variant = c.variant;
  spec.options.offset = 0;  // the default rule for δ (a file's offset need not fit at N = 64)
  spec.options.threads = 2;
  spec.options.error_estimate = false;  // not among the recorded answers (tests/convergence/test_quantities.cpp)
  return fictus::solve(spec.problem, spec.options);
}

std::vector<Case3d> cases() {
  std::vector<Case3d> list;
  for (int N : {64, 96})
    for (const char* example : {"sphere", "ellipsoid", "torus", "torus_implicit", "torus_mesh"})
      for (fictus::Variant variant : {fictus::Variant::smooth, fictus::Variant::nonsmooth})
        list.push_back({example, variant, N});
  return list;
}

class Recorded3d : public ::testing::TestWithParam<Case3d> {};

TEST_P(Recorded3d, AnswersEqualTheRecordedValues) {
  const Case3d& c = GetParam();
  const json now = summarize(solve(c));
  json recorded = json::object();
  if (std::ifstream in(recorded_path); in) recorded = json::parse(in);
  if (std::getenv("FICTUS_RECORD")) {
    recorded[c.name()] = now;
    std::ofstream(recorded_path) << recorded.dump(1) << "\n";
    GTEST_SKIP() << "recorded " << c.name() << " to " << recorded_path;
  }
  ASSERT_TRUE(recorded.contains(c.name())) << c.name() << " is not recorded in " << recorded_path;
  fictus::regression::compare_recorded(recorded[c.name()], now, c.name());
}

INSTANTIATE_TEST_SUITE_P(Examples, Recorded3d, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case3d>& info) { return info.param.name(); });

}  // namespace
