#pragma once
// Fitted-mesh references (tests/references/<name>.json, written by tests/references/generate.sh) and
// the comparison of a fictus solution with them: errors in ω from the reference's polar Gauss rule,
// on γ from its trace samples, and the distance of the contact ends. Used by the convergence tests
// and the benches spacing_study.cpp, contact_fit.cpp and estimate_quality.cpp.
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "fictus/grid/quadrature.hpp"
#include "fictus/io/expression.hpp"
#include "fictus/solve/convergence_table.hpp"
#include "fictus/solve/error_norms.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"

namespace reference {

constexpr double two_pi = 2.0 * std::numbers::pi;

struct Reference {
  std::string name;
  fictus::Point2 center;
  std::function<double(double)> radius;  // r_b(θ), θ the polar angle about the center
  int n_theta = 0, n_rho = 0;
  std::vector<double> u, ux, uy;         // interior samples, index j·n_rho + k
  std::vector<double> trace_u, trace_g;  // on γ at θ_j = 2πj/n
  std::vector<double> ends;              // θ of the ends of the contact intervals
  double l2_omega = 0, h1semi_omega = 0, l2_gamma = 0;
};

/// Reads <folder>/<name>.json.
inline Reference load(const std::string& folder, const std::string& name) {
  std::ifstream in(folder + "/" + name + ".json");
  if (!in) throw std::runtime_error("cannot read " + folder + "/" + name + ".json");
  const nlohmann::json j = nlohmann::json::parse(in);
  Reference r;
  r.name = name;
  r.center = {j["problem"]["center"][0], j["problem"]["center"][1]};
  const fictus::Expression radius(j["problem"]["boundary_radius"].get<std::string>(), {"t"}, "boundary_radius");
  r.radius = [radius](double theta) { return radius({theta}); };
  r.n_theta = j["interior"]["n_theta"];
  r.n_rho = j["interior"]["n_rho"];
  r.u = j["interior"]["u"].get<std::vector<double>>();
  r.ux = j["interior"]["ux"].get<std::vector<double>>();
  r.uy = j["interior"]["uy"].get<std::vector<double>>();
  r.trace_u = j["trace"]["u"].get<std::vector<double>>();
  r.trace_g = j["trace"]["g"].get<std::vector<double>>();
  r.ends = j["contact"]["ends"].get<std::vector<double>>();
  r.l2_omega = j["norms"]["l2_omega"];
  r.h1semi_omega = j["norms"]["h1semi_omega"];
  r.l2_gamma = j["norms"]["l2_gamma"];
  return r;
}

inline fictus::Point2 boundary_point(const Reference& r, double theta) {
  return r.center + r.radius(theta) * fictus::Point2{std::cos(theta), std::sin(theta)};
}

/// The polar rule about r's centre over ω: n_θ angles at the midpoints, n_ρ Gauss points in ρ ∈ (0, 1),
/// weights (2π/n_θ)·w_k·ρ_k·r_b(θ_j)²; calls visit(x, weight, n) at the n-th point (n = j·n_ρ + k). The
/// reference's samples lie at its own rule's points (n_θ = r.n_theta, n_ρ = r.n_rho).
template <class Visit>
void for_each_polar_point(const Reference& r, int n_theta, int n_rho, Visit&& visit) {
  const fictus::GaussRule& rule = fictus::gauss_legendre(n_rho);
  for (int j = 0; j < n_theta; ++j) {
    const double theta = two_pi * (j + 0.5) / n_theta, rb = r.radius(theta);
    for (int k = 0; k < n_rho; ++k) {
      const double rho = rule.nodes[std::size_t(k)];
      const double w = two_pi / n_theta * rule.weights[std::size_t(k)] * rho * rb * rb;
      visit(r.center + rho * rb * fictus::Point2{std::cos(theta), std::sin(theta)}, w,
            std::size_t(j) * std::size_t(n_rho) + std::size_t(k));
    }
  }
}

/// The polar angle of x about c, in [0, 2π).
inline double angle_about(const fictus::Point2& c, const fictus::Point2& x) {
  const double t = std::atan2(x.y - c.y, x.x - c.x);
  return t < 0 ? t + two_pi : t;
}

/// Whether θ lies in one of the contact intervals [ends[2k], ends[2k+1]] (cyclic; the reference's own ends
/// or moved ones).
inline bool in_contact(const std::vector<double>& ends, double theta) {
  for (std::size_t k = 0; k + 1 < ends.size(); k += 2) {
    const double a = ends[k], b = ends[k + 1];
    if (a < b ? (theta >= a && theta < b) : (theta >= a || theta < b)) return true;
  }
  return false;
}

/// The reference's contact measure on `curve` (γ as fictus parametrizes it): the length of the parts of γ
/// whose polar angle about r's centre lies in its contact intervals, by the midpoint rule over `samples`
/// pieces in the curve's parameter (exact to about the length of one piece at each end).
inline double contact_length(const Reference& r, const fictus::Curve& curve, int samples = 1 << 20) {
  double length = 0;
  for (int i = 0; i < samples; ++i) {
    const double t = two_pi * (i + 0.5) / samples;
    if (in_contact(r.ends, angle_about(r.center, curve.position(t)))) length += two_pi / samples * curve.speed(t);
  }
  return length;
}

struct Comparison {
  fictus::LevelResult level;               // relative errors against the reference
  double end_error_spacings = 0;           // largest distance of a reference contact end to fictus's, in s = L/m
  double resolved_end_error_spacings = 0;  // the same for the ends located inside the arcs (contact_boundary)
};

inline Comparison compare(const Reference& r, const fictus::Solution& s) {
  const fictus::Grid2& grid = s.grid;
  // ω: the reference's rule.
  double e0 = 0, e1 = 0;
  for_each_polar_point(r, r.n_theta, r.n_rho, [&](const fictus::Point2& x, double w, std::size_t n) {
    const auto q = fictus::sample_q1(grid, s.u, grid.cell_x(x.x), grid.cell_y(x.y), x.x, x.y);
    e0 += w * std::pow(q.value - r.u[n], 2);
    e1 += w * (std::pow(q.gradient.x - r.ux[n], 2) + std::pow(q.gradient.y - r.uy[n], 2));
  });
  // γ: trapezoid in θ with ds = √(r_b² + r_b′²) dθ.
  const int n = int(r.trace_u.size());
  double eg = 0;
  for (int j = 0; j < n; ++j) {
    const double theta = two_pi * j / n, d = 1e-6;
    const double rb = r.radius(theta), drb = (r.radius(theta + d) - r.radius(theta - d)) / (2 * d);
    eg += two_pi / n * std::hypot(rb, drb) *
          std::pow(fictus::evaluate_q1(grid, s.u, boundary_point(r, theta)) - r.trace_u[j], 2);
  }
  Comparison c;
  c.level = {grid.nx(),
             grid.n_nodes(),
             s.collocation.m,
             s.newton.iterations,
             s.fast_solves,
             s.timings.total,
             std::sqrt(e0) / r.l2_omega,
             std::sqrt(e0 + e1) / std::hypot(r.l2_omega, r.h1semi_omega),
             std::sqrt(eg) / r.l2_gamma};
  // Contact ends: fictus's lie between two collocation points of different status (the arc boundary),
  // both on the Signorini part (mixed conditions).
  std::vector<fictus::Point2> ends;
  const int m = s.collocation.m;
  const auto signorini = [&s](int i) { return s.condition(i) == fictus::PointCondition::signorini; };
  for (int i = 0; i < m; ++i)
    if (signorini(i) && signorini((i + 1) % m) && s.in_contact(i) != s.in_contact((i + 1) % m))
      ends.push_back(0.5 * (s.collocation.point[i] + s.collocation.point[(i + 1) % m]));
  const auto largest_distance = [&](const std::vector<fictus::Point2>& found) {
    double largest = 0;
    for (double theta : r.ends) {
      double best = 1e300;
      for (const fictus::Point2& e : found) best = std::min(best, fictus::norm(e - boundary_point(r, theta)));
      largest = std::max(largest, best / s.collocation.spacing);
    }
    return largest;
  };
  c.end_error_spacings = largest_distance(ends);
  c.resolved_end_error_spacings = largest_distance(s.contact_boundary);
  return c;
}

}  // namespace reference
