#pragma once
// The options of the fictitious domain solver, with their defaults (written here only; the rules
// their values obey, their meaning and their names in files, flags and results: options.hpp).
namespace fictus {

/// automatic: smooth where γ has a continuous normal, nonsmooth where it has corners (a polygon).
enum class Variant { nonsmooth, smooth, automatic };
enum class InnerSolver { green, krylov };
/// How the green solver stores S_B and S_C: dense, hierarchical (hierarchical_schur.hpp), or automatic
/// (hierarchical from hierarchical_from_points(dim) points on, where A is regular).
enum class SchurStorageKind { automatic, dense, hierarchical };
/// solver.schur_storage = auto: hierarchical from this many points on. 3-D: where the compressed blocks
/// were the faster on the sphere (bench/results, "compressed Schur"); both paths refine on the exact S
/// there. 2-D: where the dense blocks pass 6 GB; its dense blocks are exact, so Newton makes no fast
/// solve and the dense path stays the faster while it fits.
inline constexpr int hierarchical_from_points_3d = 5000;
inline constexpr int hierarchical_from_points_2d = 20000;
inline constexpr int hierarchical_from_points(int dim) {
  return dim == 2 ? hierarchical_from_points_2d : hierarchical_from_points_3d;
}
/// Whether a green solve keeps S_B and S_C compressed: `kind`, auto by m; never with a singular A (a
/// periodic box with c = 0: the bordering is dense only).
inline constexpr bool compressed_schur(SchurStorageKind kind, int dim, double m, bool singular) {
  return !singular && (kind == SchurStorageKind::hierarchical ||
                       (kind == SchurStorageKind::automatic && m >= hierarchical_from_points(dim)));
}
/// How the traces B_γ u and C_γ u are taken (docs/math.md, "Trace matrices"):
///   reconstructed  consistent at x_i: smooth variant, the gradient of the biquadratic interpolant
///                  (O(h²)); non-smooth variant, the traces of the kink-corrected field;
///   shifted        C_γ = the cell gradient at x_i − normal_shift·h·n_i (first order at best).
enum class NormalDerivative { reconstructed, shifted };

const char* to_string(Variant v);
/// The variant a solve uses: `v`, or for automatic the one the boundary allows.
inline Variant resolved_variant(Variant v, bool smooth_boundary) {
  return v != Variant::automatic ? v : smooth_boundary ? Variant::smooth : Variant::nonsmooth;
}
const char* to_string(InnerSolver s);
const char* to_string(NormalDerivative d);
const char* to_string(SchurStorageKind k);

struct SolverOptions {
  Variant variant = Variant::automatic;
  int multipliers = 0;  // m; 0: default_multipliers()
  double offset = 0;    // smooth variant: δ = offset · s (s: the spacing of the points); 0: the default rule
  double rho = 1.0;     // ρ > 0
  NormalDerivative normal_derivative = NormalDerivative::reconstructed;
  double normal_shift = 1.0;     // shifted rule only: C_γ taken at x_i − normal_shift·h·n_i
  bool start_all_active = true;  // Newton start: all points active, else λ = 0
  InnerSolver inner = InnerSolver::green;
  double krylov_tolerance = 1e-10;  // relative GMRES residual
  SchurStorageKind schur_storage = SchurStorageKind::automatic;
  int krylov_max_iterations = 5000;
  double newton_tolerance = 1e-9;  // relative ‖F‖∞
  int max_newton = 50;
  int load_quadrature = 2;       // Gauss points per direction per cell for the load vector
  int error_quadrature = 3;      // Gauss points per direction for the error integrals (exact for |∇e|²)
  bool flux_balance = true;      // 3-D non-smooth: readings that keep the discrete flux balance (surface_kink.hpp)
  bool far_field = true;         // 3-D green: interpolate the far pairs of S, then Newton on the exact S from there
  int nested_start = 160;        // 3-D: from this N on, Newton starts from the active set of a solve on the N/2 grid
  bool condition_number = true;  // cond₂ of the final Newton matrix (dense Schur complement)
  bool error_estimate = true;    // estimate the errors from the same problem solved on the grid of N/2
  int fit_contact = -1;          // solves more, the points placed to the contact boundary the one before located;
                                 // −1: automatic (2 with the smooth variant in 2-D, else 0; docs/math.md)
  int threads = 0;               // 0: the machine's (default_threads(), execution.hpp)
  double max_memory = 0;         // GiB a solve may use; 0: the memory available when it starts

  /// Throws std::invalid_argument naming the option when a value breaks its rule (options.hpp).
  void validate() const;
};

}  // namespace fictus
