#pragma once
// A Signorini problem on ω ⊂ Ω and the options of the fictitious domain solver.
//   −Δu + c·u = f in ω,  u ≥ g, ∂u/∂n ≥ 0, (∂u/∂n)(u − g) = 0 on γ = ∂ω.
#include <memory>
#include <string>

#include "fictus/curve.hpp"
#include "fictus/error_norms.hpp"
#include "fictus/load_vector.hpp"

namespace fictus {

struct Problem {
  std::string name = "problem";
  Box box;                              // Ω
  Boundary boundary = Boundary::dirichlet;  // conditions on ∂Ω (periodic: c = 0 is allowed)
  int N = 128;                          // cells along x (h = (x1 − x0)/N)
  std::shared_ptr<const Curve> gamma;   // γ, counter-clockwise, strictly inside Ω
  double c = 1.0;                       // c ≥ 0
  ScalarField f;                        // load, on all of Ω
  ScalarField g;                        // obstacle, sampled at the collocation points on γ
  /// Optional obstacle that also depends on the arc length s along γ (used instead of g when set).
  std::function<double(double x, double y, double s)> g_along_curve;
  /// Optional batch forms (e.g. numpy callables), used instead of f, g, exact when set.
  VectorizedField f_vectorized, g_vectorized, exact_vectorized;
  ScalarField exact;                    // optional exact solution on ω (errors are computed if set)
  GradientField exact_gradient;         // optional ∇u (central differences of `exact` if unset)
};

enum class Variant { nonsmooth, smooth };
enum class InnerSolver { green, krylov };
/// How the traces B_γ u and C_γ u are taken (docs/math.md, "Trace matrices"):
///   reconstructed  consistent at x_i: smooth variant, the gradient of the biquadratic interpolant
///                  (O(h²)); non-smooth variant, the traces of the kink-corrected field;
///   shifted        C_γ = the cell gradient at x_i − normal_shift·h·n_i (first order at best).
enum class NormalDerivative { reconstructed, shifted };

const char* to_string(Variant v);
const char* to_string(InnerSolver s);
const char* to_string(NormalDerivative d);
Variant parse_variant(const std::string& text);          // throws naming "formulation.variant"
InnerSolver parse_inner_solver(const std::string& text);  // throws naming "solver.schur"
NormalDerivative parse_normal_derivative(const std::string& text);  // throws naming "formulation.normal_derivative"

struct SolverOptions {
  Variant variant = Variant::smooth;
  int multipliers = 0;            // m; 0: default_multipliers()
  double offset = 1.5;            // smooth variant: δ = offset · s, s = L/m (spacing of the points)
  double rho = 1.0;               // ρ > 0
  NormalDerivative normal_derivative = NormalDerivative::reconstructed;
  double normal_shift = 1.0;      // shifted rule only: C_γ taken at x_i − normal_shift·h·n_i
  bool start_all_active = true;   // Newton start: all points active, else λ = 0
  InnerSolver inner = InnerSolver::green;
  double krylov_tolerance = 1e-10;  // relative GMRES residual
  int krylov_max_iterations = 5000;
  double newton_tolerance = 1e-9;   // relative ‖F‖∞
  int max_newton = 50;
  int load_quadrature = 2;        // Gauss points per direction per cell for the load vector
  int error_quadrature = 3;       // Gauss points per direction for the error integrals (exact for |∇e|²)
  bool condition_number = true;   // of the final Newton matrix (green path only)
  int threads = 1;

  /// Throws std::invalid_argument naming the option when a value is out of range.
  void validate() const;
};

}  // namespace fictus
