#pragma once
// 3-D: the Signorini problem −Δu + c·u = f in ω, u ≥ g, ∂u/∂n ≥ 0, (u − g)·∂u/∂n = 0 on γ = ∂ω, a
// closed surface in a box Ω ⊂ R³, by the fictitious domain method of the 2-D solver (docs/math.md,
// "Three dimensions"): trilinear elements on the box's uniform grid, A⁻¹ by 3-D sine (or real
// Fourier) transforms, λ piecewise constant on m patches of γ (non-smooth) or of its offset surface Γ
// at distance δ outside (smooth), one collocation point per patch, and the same Schur complement and
// semismooth Newton code as in 2-D (schur_complement.hpp, semismooth_newton.hpp).
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fictus/error_norms.hpp"
#include "fictus/execution.hpp"
#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/grid.hpp"
#include "fictus/load_vector.hpp"
#include "fictus/semismooth_newton.hpp"
#include "fictus/solver_options.hpp"
#include "fictus/surface_integrals.hpp"

namespace fictus {

using GradientField3 = std::function<Point3(double x, double y, double z)>;
/// A symmetric 3 × 3 matrix by rows.
using Matrix3 = std::array<Point3, 3>;

/// A closed surface γ = ∂ω given by a level-set function: level(x) < 0 in ω, > 0 outside, with a
/// triangulation split into patches on demand.
class Surface {
 public:
  virtual ~Surface() = default;
  virtual double level(const Point3& p) const = 0;
  virtual Point3 level_gradient(const Point3& p) const = 0;
  /// The Hessian of the level function (default: central differences of level_gradient).
  virtual Matrix3 level_hessian(const Point3& p) const;
  /// γ triangulated with edges of about `edge` or less, split into m patches of nearly equal area,
  /// with a point on γ and its outward normal per patch.
  virtual PatchedSurface patches(int m, double edge) const = 0;
  /// The area of γ (for the default m).
  virtual double area() const = 0;
  /// A box holding γ.
  virtual Box3 bounds() const = 0;
  /// The largest outward offset whose surface does not touch itself (infinite for a convex γ).
  virtual double reach() const { return std::numeric_limits<double>::infinity(); }
};

/// (x − c)ᵀ diag(a)⁻² (x − c) < 1, axis-aligned; a sphere when the semi-axes are equal.
class Ellipsoid final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.center or geometry.semi_axes.
  Ellipsoid(Point3 center, Point3 semi_axes);
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  double area() const override;
  Box3 bounds() const override;
  Point3 center() const { return center_; }
  Point3 semi_axes() const { return semi_axes_; }

 private:
  Point3 center_, semi_axes_;
};

/// ((x − c)_xy distance from the z-axis through c − R)² + (z − c_z)² < r², 0 < r < R: a torus
/// about the z-axis (genus one).
class Torus final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.center or geometry.radii.
  Torus(Point3 center, double R, double r);
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  double area() const override;
  Box3 bounds() const override;
  double reach() const override { return R_ - r_; }

 private:
  Point3 center_;
  double R_, r_;
};

using HessianField3 = std::function<Matrix3(const Point3& p)>;

/// level(x) < 0 in ω, any smooth function with a nonzero gradient on its zero set, inside a box that
/// holds γ: triangulated by marching tetrahedra on a lattice of cubes of side `edge` (the crossings on the
/// tetrahedra's edges by root finding), split into patches as the built-in shapes are. Derivatives from
/// `gradient` and `hessian` when given, else by central differences (steps 1e-5 and 1e-4 of the
/// largest side of γ's box).
class ImplicitSurface final : public Surface {
 public:
  /// Throws std::invalid_argument naming geometry.bounds (not a box, or γ reaches its faces) or
  /// geometry.level (not finite, no surface inside the box, or a vanishing gradient on γ).
  ImplicitSurface(ScalarField3 level, Box3 bounds, GradientField3 gradient = {}, HessianField3 hessian = {});
  double level(const Point3& p) const override;
  Point3 level_gradient(const Point3& p) const override;
  Matrix3 level_hessian(const Point3& p) const override;
  PatchedSurface patches(int m, double edge) const override;
  /// From a triangulation with cubes of 1/96 of the box's largest side (relative error O((edge·κ)²)).
  double area() const override { return area_; }
  /// The box of that triangulation's vertices grown by 1/20 of its cube side, within the given box.
  Box3 bounds() const override { return tight_; }
  /// 1/(the largest principal curvature of the concave side) on that triangulation's vertices: where
  /// outward offsets first fold. A neck between two distant parts of γ is not seen.
  double reach() const override { return reach_; }

 private:
  std::vector<Triangle3> triangulate(const Box3& box, double edge) const;
  ScalarField3 level_;
  GradientField3 gradient_;
  HessianField3 hessian_;
  Box3 bounds_, tight_;
  double scale_ = 1, area_ = 0, reach_ = 0;
};

struct SurfaceProblem {
  Box3 box;  // Ω
  int N = 64;
  Boundary boundary = Boundary::dirichlet;
  double c = 1.0;
  std::shared_ptr<const Surface> gamma;
  ScalarField3 f, g;
  ScalarField3 exact;             // optional: errors
  GradientField3 exact_gradient;  // optional with exact (else central differences)
  /// Optional batch forms (e.g. numpy callables), used instead of f, g and exact when set.
  VectorizedField3 f_vectorized, g_vectorized, exact_vectorized;
};

/// Default patch size s (the side of a square of the patch's area) in cells: m = area/(s·h)².
inline constexpr double default_patch_cells_smooth_3d = 8.0;
inline constexpr double default_patch_cells_nonsmooth_3d = 4.0;
/// The far field of the 3-D explicit assembly (solver.far_field), chosen by measurement (docs/math.md):
/// p = 6 where the columns are B_Γ's; p = 5 in the non-smooth variant, whose columns carry the kink
/// rows (about 270 entries each) and make the exact blocks dearer.
inline constexpr FarField default_far_field_3d{6, 2.0, 2};
inline constexpr FarField default_far_field_3d_nonsmooth{5, 2.0, 2};
/// Newton runs on S̃ until a step changes at most this fraction of the points (at least one), then
/// on the exact S.
inline constexpr double far_field_hand_on = 0.05;
/// GMRES's relative residual for the Newton steps on the exact S behind an interpolated far field.
inline constexpr double far_field_gmres_tolerance = 1e-13;
/// The nested start's coarse grid has at least this many cells along x (solver.nested_start).
inline constexpr int minimum_nested_grid = 8;
/// Default m for a surface of `area` on a grid of cell h.
int default_patches(double area, double h, Variant variant);

struct SurfaceSolution {
  explicit SurfaceSolution(const Grid3& g) : grid(g) {}
  Grid3 grid;
  SolverOptions options;              // in effect (m and the offset resolved)
  std::vector<std::string> warnings;  // what the solve changed to fit (one line each), for the user
  GridVector u;                       // û at the unknowns
  PatchedSurface gamma;               // γ's patches: points, normals, areas
  PatchedSurface Gamma;               // the surface carrying λ (γ itself in the non-smooth variant)
  double delta = 0;                   // distance of Γ from γ
  std::vector<double> lambda, g, trace, normal_derivative;  // per patch
  double lambda_total = 0;
  double alpha = 0;
  NewtonResult newton;
  std::size_t fast_solves = 0;
  int inner_iterations = 0;
  int factorizations = 0;  // dense LUs of Newton matrices (green; the others by updates, NewtonFactorization)
  /// With solver.far_field: what the assembly interpolated, and the Newton steps run on the exact S
  /// (preconditioned by S̃) after those on S̃ (all counted in newton.iterations).
  struct FarFieldUse {
    FarFieldReport assembly;
    int exact_steps = 0;
  };
  std::optional<FarFieldUse> far_field;
  /// With solver.nested_start (N at or above it): the solve of the same problem on the grid of N/2
  /// whose active set, taken at each point from the nearest coarse point, started Newton here; or,
  /// when that solve could not be made, why (`skipped`), and Newton started as solver.start says.
  struct NestedStart {
    int N = 0;             // the coarse grid's
    int multipliers = 0;   // the coarse m
    int newton_steps = 0;  // the coarse solve's (not counted in newton.iterations)
    int active = 0;        // its points in contact
    double seconds = 0;    // the whole coarse solve, its own nested start included
    std::string skipped;   // non-empty: no nested start, and why
  };
  std::optional<NestedStart> nested_start;
  /// With formulation.flux_balance (non-smooth): how far the kink-corrected readings missed the
  /// discrete flux balance before the correction (docs/math.md, "The flux balance of the patches").
  struct FluxBalanceUse {
    double scatter = 0;     // the standard deviation over the patches of β_j/a_j
    double mean = 0;        // μ: a constant layer's error of the mean reading, per unit λ
    double data_shift = 0;  // what every reading of the data's field u₀ moved by
  };
  std::optional<FluxBalanceUse> flux_balance;
  SignoriniCheck signorini;
  std::optional<ErrorNorms> errors;
  std::optional<PointErrors> point_errors;
  Timings timings;
  std::size_t peak_memory_bytes = 0;
};

/// One 3-D problem, one call, on options.threads threads; `progress` is called with each step's name
/// and seconds as it ends. Throws std::invalid_argument naming the field on bad input, and
/// Interrupted soon after `interrupt` (asked from the calling thread) returns true.
SurfaceSolution solve(const SurfaceProblem& problem, SolverOptions options,
                      std::function<void(const std::string& phase, double seconds)> progress = {},
                      std::function<bool()> interrupt = {});

/// ∫_ω w over the part of each voxel inside γ: full voxels by q³ Gauss points, voxels near γ split
/// in 8 and each cut half-voxel by a rule along the axis where γ is steepest (the segment of each
/// Gauss line inside ω found by root finding on the level set, then q Gauss points on it), exact up
/// to the quadrature's degree for integrands smooth in the voxel. `visit(thread, cell, x, weight)` is
/// called from `execution.threads()` threads at once, `thread` in [0, threads): keep sums per thread.
using OmegaVisitor = std::function<void(int thread, const Grid3::Index& cell, const Point3& x, double weight)>;
void for_each_omega_point(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                          const OmegaVisitor& visit);
/// The same points one voxel row (fixed y and z) at a time, for integrands evaluated in batches.
struct OmegaPoint {
  Grid3::Index cell;
  Point3 x;
  double weight;
};
using OmegaRowVisitor = std::function<void(int thread, const std::vector<OmegaPoint>& row)>;
void for_each_omega_row(const Grid3& grid, const Surface& gamma, int q, const Execution& execution,
                        const OmegaRowVisitor& visit);

/// May γ come within `radius` of `center`? (|level| ≤ 2·radius·|∇level| there: the distance is about
/// |level|/|∇level| near γ, with a factor 2 to spare.)
bool near_surface(const Surface& gamma, const Point3& center, double radius);

/// The points of that rule in one voxel (none for a voxel outside ω), on the calling thread.
/// `depth` > 0 splits the half-voxels where γ meets the faces across the line direction up to that many times more.
void for_each_omega_point_in_voxel(const Grid3& grid, const Surface& gamma, const Grid3::Index& cell, int q,
                                   const std::function<void(const Point3& x, double weight)>& visit, int depth = 0);

/// ∫_ω φ_k for every node with an unknown: h³/8 per corner of a voxel wholly inside γ, the rule above
/// on the voxels near γ (the load of f = 1_ω). γ must stay a cell away from the walls (solve checks
/// 2h), so that no two of the parallel voxel layers write one node plane of a periodic grid.
GridVector omega_load(const Grid3& grid, const Surface& gamma, int q = 3, const Execution& execution = Execution{});

/// ∫_ω f by that rule, f evaluated one voxel row at a time and the rows summed in order (the same
/// result on any number of threads).
double omega_integral(const Grid3& grid, const Surface& gamma, const VectorizedField3& f, int q = 3,
                      const Execution& execution = Execution{});

/// The volume of ω by that rule (a test of it).
double omega_volume(const Grid3& grid, const Surface& gamma, int q = 3, const Execution& execution = Execution{});

/// Errors of the trilinear û against `exact` in ω (L², H¹) and on γ from the points (Σ_p |patch p|·
/// (û − u)(x_p)²)^½, absolute and relative.
ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const ScalarField3& exact,
                          const GradientField3& exact_gradient, int q = 3, const Execution& execution = Execution{});
/// The same with `exact` in batches (∇u by central differences in batches when no gradient is given).
ErrorNorms compute_errors(const GridVector& u_h, const Grid3& grid, const Surface& gamma, const PatchedSurface& patches,
                          const std::vector<double>& trace, const VectorizedField3& exact,
                          const GradientField3& exact_gradient, int q = 3, const Execution& execution = Execution{});

}  // namespace fictus
