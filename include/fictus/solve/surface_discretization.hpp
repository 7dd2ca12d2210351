#pragma once
// The boundary of a 3-D problem: a closed surface γ in a box, m patches of nearly equal area with a
// point and an outward normal each, and the surface Γ that carries λ (γ itself in the non-smooth
// variant, γ moved by δ along its normals in the smooth one), with the trace rows of the chosen rule
// (docs/math.md, "Three dimensions"): B_γ trilinear, C_γ triquadratic (reconstructed) or the shifted
// voxel gradient, B_Γ the exact patch integrals; in the non-smooth variant the kink correction
// (surface_kink.hpp) and the flux balance of the patches.
#include <memory>
#include <optional>

#include "fictus/boundary/surface.hpp"
#include "fictus/boundary/surface_integrals.hpp"
#include "fictus/solve/boundary_discretization.hpp"

namespace fictus {

/// Default patch size s (the side of a square of the patch's area) in cells: m = area/(s·h)².
inline constexpr double default_patch_cells_smooth_3d = 5.0;
inline constexpr double default_patch_cells_nonsmooth_3d = 4.0;
/// Default m for a surface of `area` on a grid of cell h.
int default_patches(double area, double h, Variant variant);

/// The far field of the 3-D explicit assembly (solver.far_field), chosen by measurement
/// (docs/notes/3d-far-field-and-newton.md):
/// p = 6 where the columns are B_Γ's; p = 5 in the non-smooth variant, whose columns carry the kink
/// rows (about 270 entries each) and make the exact blocks dearer.
inline constexpr FarField default_far_field_3d{6, 2.0, 2};
inline constexpr FarField default_far_field_3d_nonsmooth{5, 2.0, 2};

class SurfaceDiscretization final : public BoundaryDiscretization<3> {
 public:
  /// Steps 1–2 of the solve for surface γ on `grid`:
  ///   1. geometry: γ 2h inside the box, m and δ by the rules of spacing_rule.hpp (the room of Γ: the
  ///      box's margin and the surface's reach), the patches, Γ;
  ///   2. trace rows: B_γ, C_γ, B_Γ; in the non-smooth variant with reconstructed traces, the kink
  ///      correction (its rows join B_Γ as the loads; D_B, D_C act on λ directly).
  /// `mark` is told "geometry" and "kink_correction" as they end. Throws std::invalid_argument naming
  /// the option or "geometry" on bad input. `execution` must outlive the object. With mixed conditions
  /// (`parts`), each patch takes triangles of one part only, so the patch borders follow the junctions
  /// of the parts to within a triangle.
  SurfaceDiscretization(std::shared_ptr<const Surface> gamma, const Grid3& grid, const SolverOptions& options, double c,
                        const Execution& execution, const MarkPhase& mark, const PartConditions<3>& parts = {});
  ~SurfaceDiscretization() override;

  const std::vector<Point3>& points() const override { return gamma_patches_.point; }
  const std::vector<Point3>& normals() const override { return gamma_patches_.normal; }
  const SpacingPlan& spacing() const override { return plan_; }
  double delta() const override { return delta_; }
  const SparseRows& B_gamma() const override { return B_gamma_; }
  const SparseRows& C_gamma() const override { return C_gamma_; }
  const SparseRows& B_Gamma() const override { return B_Gamma_; }
  const SparseRows& loads() const override { return loads_; }
  const DirectTerms& direct() const override { return direct_; }
  /// With solver.far_field: default_far_field_3d (non-smooth: default_far_field_3d_nonsmooth).
  FarField far_field(const SolverOptions& options) const override;
  /// The flux balance (formulation.flux_balance, non-smooth with the kink correction; not where A is
  /// singular): X joins D_C (surface_kink.hpp); "flux_balance" is marked.
  std::size_t finish_setup(const FastSolver<3>& fast, const MarkPhase& mark) override;
  /// With the flux balance: (c∫_ω u₀ − ∫_ω f − Σ a_i (C_γu₀)_i)/Σ a_i, so that the data's readings
  /// keep the discrete field's flux balance.
  double reading_shift(const GridVector& u0, const VectorizedField3& f, int load_quadrature) const override;
  std::optional<FluxBalanceUse> flux_balance(double data_shift) const override;
  std::vector<double> obstacle(const Data& data) const override;
  void finish_field(const std::vector<double>& lambda, GridVector& u) const override;
  /// + Xλ with the flux balance.
  void finish_readings(const std::vector<double>& lambda, std::vector<double>& normal_derivative) const override;
  /// ∂u/∂n from the one-sided cubic fit through the nodes of ω (one_sided_rows), both variants.
  std::optional<std::vector<double>> independent_normal_derivative(const GridVector& u,
                                                                   std::string& rule) const override;
  void for_each_omega_sample(const GridVector& u, int quadrature, const OmegaSampleVisitor<3>& visit) const override;
  ErrorNorms errors(const GridVector& u, const std::vector<double>& trace, const Data& data,
                    int quadrature) const override;
  /// ∂u/∂n of the exact solution from its gradient when given, else central differences (step 1e-6·box width).
  PointErrors point_errors(const std::vector<double>& trace, const std::vector<double>& normal_derivative,
                           const Data& data) const override;
  void describe(SolutionBoundary<3>& out) const override;
  /// The same surface with its patches made for `parts` (the contact fit's); m, δ and the triangulation of
  /// γ before it is cut into patches are shared, not made again.
  std::unique_ptr<BoundaryDiscretization<3>> placed_for(const PartConditions<3>& parts, const SolverOptions& options,
                                                        double c, const MarkPhase& mark) const override;

 private:
  SurfaceDiscretization(const SurfaceDiscretization& base, const SolverOptions& options, const MarkPhase& mark,
                        const PartConditions<3>& parts);
  /// Step 1 without the patches: γ inside the box, m, δ, γ's triangulation.
  void make_shape(const SolverOptions& options);
  /// The patches for `parts` (each in one part), their points and Γ's triangles, from gamma_patches_ holding
  /// γ's triangulation before any cut. Where the parts cut it, a copy of that is kept if `keep_unsplit` (for
  /// placed_for: the solver's own setup, not a fitted copy, is the base of the fits).
  void place_points(const SolverOptions& options, const PartConditions<3>& parts, bool keep_unsplit);
  /// The labels at the centroids of γ's triangles.
  std::vector<int> part_layout(const PartConditions<3>& parts) const override;
  void make_trace_rows(const SolverOptions& options, const MarkPhase& mark);

  Grid3 grid_;
  std::shared_ptr<const Surface> gamma_;
  const Execution& execution_;
  double c_;
  bool balance_wanted_;
  SpacingPlan plan_;
  double delta_ = 0;
  // γ.patches(m, h) before the parts cut it: kept only where they did (split_) and the copy was asked for;
  // where they did not, gamma_patches_ is it.
  std::shared_ptr<const PatchedSurface> unsplit_;
  bool split_ = false;
  PatchedSurface gamma_patches_, Gamma_patches_;
  SparseRows B_gamma_, C_gamma_, B_Gamma_, loads_;
  DirectTerms direct_;
  struct Kink;
  std::unique_ptr<Kink> kink_;  // the kink correction and the flux balance (non-smooth, reconstructed)
  // ℓ_k = ∫_ω φ_k (c ≠ 0), made by finish_setup and kept for the first reading_shift only (one grid
  // array; a later load makes it again).
  mutable GridVector load_of_omega_;
};

}  // namespace fictus
