#pragma once
// The Schur complement of the discrete problem (3) with respect to λ:
//   u(λ) = u₀ + A⁻¹ B_Γᵀ λ,   S_B = B_γ A⁻¹ B_Γᵀ,   S_C = C_γ A⁻¹ B_Γᵀ   (m × m).
// In the non-smooth variant the traces are those of the kink-corrected field (kink_correction.hpp):
// the load rows are B_Γ + R and sparse terms D_B, D_C act on λ directly:
//   S_B = B_γ A⁻¹ (B_Γ + R)ᵀ + D_B,   S_C = C_γ A⁻¹ (B_Γ + R)ᵀ + D_C.
// The Newton matrix for an active set 𝒜 takes row i of S_B if i ∈ 𝒜 and row i of S_C otherwise.
// Two implementations behind one interface:
//   ImplicitSchur  the paper's: never formed, one fast A⁻¹ per application, GMRES per step;
//   ExplicitSchur  ours: S_B and S_C assembled from the discrete Green's function, dense LU.
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "fictus/boundary/trace_operators.hpp"
#include "fictus/grid/distribution.hpp"
#include "fictus/grid/fast_solver.hpp"
#include "fictus/grid/green_table.hpp"
#include "fictus/solve/dense_lu.hpp"
#include "fictus/solve/gmres.hpp"

namespace fictus {

using ActiveSet = std::vector<char>;  // 1: contact row (B_γ u = g), 0: free row (C_γ u = 0)

/// Bordering for a singular A (periodic box, c = 0: constants in the null space), as in the
/// projected Schur complement method: unknowns (λ, α) with u = u₀ + A⁺B_Γᵀλ + α·1; Newton row i
/// gains α·(B_γ1)_i (contact) or α·(C_γ1)_i (free), and the solvability row ℓᵀλ = −F with
/// ℓ = B_Γ1, F = 1ᵀf (that is 1ᵀ(f + B_Γᵀλ) = 0) closes the system.
struct ConstantMode {
  Eigen::VectorXd trace_B, trace_C;  // B_γ·1, C_γ·1
  Eigen::VectorXd arc_weights;       // ℓ = B_Γ·1
  double load_total = 0.0;           // F = 1ᵀf
};

/// Trace terms that act on λ directly (m × m; empty matrices: none).
struct DirectTerms {
  Eigen::SparseMatrix<double> trace, normal_derivative;  // D_B, D_C
  bool empty() const { return trace.nonZeros() == 0 && normal_derivative.nonZeros() == 0; }
};

/// How the explicit assembly treats the far field (docs/math.md, "The far field of the 3-D Schur
/// complement").
/// The rows and the columns are split into binary cluster trees; a pair of clusters whose node boxes
/// lie apart, max(radius) ≤ eta·distance (the nearest image of the box counted), is interpolated:
///   G(a, b) ≈ Σ_k Σ_l L_k(a) G(p_k, p_l) L_l(b),
/// L tensor Lagrange polynomials on `order` grid nodes per axis at the grid nodes nearest the Chebyshev
/// points of each box (pushed apart where two round to one node), so the block is (R L) G(P, P') (Q L')ᵀ;
/// every other pair is exact. order = 0: all of it exact. The solver's setting: default_far_field_3d.
struct FarField {
  int order = 0;
  double eta = 2.0;
  int leaf = 2;  // rows per leaf cluster
};

/// The interpolation nodes of one axis of a box, lo ≤ hi: all of its nodes when there are at most
/// `order`, else `order` distinct nodes in [lo, hi], the nearest to the Chebyshev points of [lo, hi]
/// (pushed apart where two round to one), increasing.
std::vector<int> interpolation_nodes(int lo, int hi, int order);

/// What the assembly did: entries of the blocks computed exactly (near) and interpolated (far).
struct FarFieldReport {
  double near_pairs = 0, far_pairs = 0;
  int near_blocks = 0, far_blocks = 0;
  /// This rank's share: the near pairs it made, and the bytes of the table's whole planes it fetched for
  /// them. Distributed with a far field, each near block is one rank's where that pays; else (and
  /// serially) every rank reports every near pair and no bytes.
  double near_pairs_here = 0, whole_planes_bytes = 0;
};

/// What the storage of S_B and S_C took (results.json `schur_storage`; dense: the m × m blocks).
struct SchurStorage {
  std::string kind = "dense";  // "dense" or "hierarchical"
  double bytes = 0;            // both blocks (distributed: over all ranks, each holding its share)
  double dense_bytes = 0;      // both blocks dense: 2·m²·8
  double low_rank_blocks = 0, full_blocks = 0;
  int largest_rank = 0;                  // of the compressed block that takes the most memory
  double preconditioner_bytes = 0;       // distributed: of all ranks
  double preconditioner_bytes_here = 0;  // this rank's share
  double far_fraction = 0;               // of the pairs, interpolated
  double seconds_assembly = 0;
};

struct LinearSolveReport {
  int inner_iterations = 0;  // Krylov operator applications (0 for a direct solve)
  double relative_residual = 0.0;
  bool converged = true;
};

class SchurComplement {
 public:
  virtual ~SchurComplement() = default;
  virtual int size() const = 0;
  /// sb = S_B λ, sc = S_C λ.
  virtual void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const = 0;
  /// Solves S_𝒜 λ = d (bordered by `mode` when given, then α is the second unknown); λ and α hold
  /// the starting guess on entry.
  virtual LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                                  Eigen::VectorXd& lambda, double& alpha) const = 0;
  /// Applications of A⁻¹ so far (the paper's it₁).
  virtual std::size_t fast_solves() const = 0;
  /// κ₂ of S_𝒜 (bordered by `mode` when given), where it is available without extra fast solves.
  virtual std::optional<double> condition_number(const ActiveSet& active, const ConstantMode* mode) const = 0;
};

class ImplicitSchur final : public SchurComplement {
 public:
  /// `loads`: the rows whose transposes carry λ into the grid (B_Γ, or B_Γ + R). Any dimension. With a
  /// distribution, the solver's vectors are this rank's slab and the readings are added over the ranks
  /// (each product is then collective).
  template <int dim>
  ImplicitSchur(const FastSolver<dim>& solver, const SparseRows& B_gamma, const SparseRows& C_gamma,
                const SparseRows& loads, const GmresOptions& options, DirectTerms direct = {},
                const Distribution* distribution = nullptr)
      : ImplicitSchur([&solver, load = footprint(solver.grid(), {&loads}),
                       wanted = footprint(solver.grid(), {&B_gamma, &C_gamma})](
                          GridVector& r) { solver.solve_in_place_at(r, load, wanted); },
                      solver.make_vector(), B_gamma, C_gamma, loads, options, std::move(direct)) {
    if (distribution && distribution->distributed())
      distribution_ = distribution, offset_ = solver.grid().slab_offset(solver.slab());
  }
  /// With A⁻¹ as `solve_in_place` on vectors of `n_unknowns`.
  ImplicitSchur(std::function<void(GridVector&)> solve_in_place, std::size_t n_unknowns, const SparseRows& B_gamma,
                const SparseRows& C_gamma, const SparseRows& loads, const GmresOptions& options,
                DirectTerms direct = {})
      : ImplicitSchur(std::move(solve_in_place), GridVector(n_unknowns), B_gamma, C_gamma, loads, options,
                      std::move(direct)) {}
  int size() const override { return B_Gamma_.n_rows(); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return fast_solves_; }
  std::optional<double> condition_number(const ActiveSet&, const ConstantMode*) const override { return std::nullopt; }
  /// y = S_𝒜 x: the Newton matrix of `active` (bordered by `mode` when given: x = (λ, α)).
  void apply_newton(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                    Eigen::VectorXd& y) const;

 private:
  ImplicitSchur(std::function<void(GridVector&)> solve_in_place, GridVector work, const SparseRows& B_gamma,
                const SparseRows& C_gamma, const SparseRows& loads, const GmresOptions& options, DirectTerms direct);
  std::function<void(GridVector&)> solve_in_place_;
  const SparseRows &B_gamma_, &C_gamma_, &B_Gamma_;
  GmresOptions options_;
  DirectTerms direct_;
  const Distribution* distribution_ = nullptr;  // a distributed run's: work_ is this rank's slab
  std::size_t offset_ = 0;                      // where the slab begins in the whole vector
  mutable GridVector work_;
  mutable std::vector<double> lambda_, rows_;
  mutable std::size_t fast_solves_ = 0;
};

/// Solves with the Newton matrices S_𝒜 of one pair (S_B, S_C), keeping the LU of the last one factored.
/// S_𝒜 differs from the factored S_𝒜₀ in the k rows where 𝒜 and 𝒜₀ differ: S_𝒜 = S_𝒜₀ + E Vᵀ, E the
/// unit vectors of those rows, Vᵀ their differences (±(S_B − S_C) rows, and the bordering column). While
/// k ≤ update_fraction·m, S_𝒜⁻¹ comes from that LU by the Sherman–Morrison–Woodbury formula
///   S_𝒜⁻¹ r = y − Z (I + Vᵀ Z)⁻¹ Vᵀ y,   y = S_𝒜₀⁻¹ r,   Z = S_𝒜₀⁻¹ E,
/// at 2m²k + O(mk²) flops against the LU's 2m³/3 (Z's columns are kept for the rows that stay changed:
/// only the newly changed rows cost a solve); beyond, S_𝒜 is factored anew and becomes S_𝒜₀.
/// Newton's later steps change a few rows, so most of its solves avoid the LU (docs/math.md).
class NewtonFactorization {
 public:
  /// The fraction of rows an update may change (its setup costs 3k/m of an LU).
  static constexpr double update_fraction = 0.125;
  NewtonFactorization(const Eigen::MatrixXd& S_B, const Eigen::MatrixXd& S_C) : S_B_(S_B), S_C_(S_C) {}
  NewtonFactorization(Eigen::MatrixXd&&, const Eigen::MatrixXd&) = delete;  // keeps references to the blocks
  NewtonFactorization(const Eigen::MatrixXd&, Eigen::MatrixXd&&) = delete;
  NewtonFactorization(const NewtonFactorization&) = delete;
  NewtonFactorization& operator=(const NewtonFactorization&) = delete;
  /// Makes `solve` that of S_𝒜 (bordered by `mode` when given).
  void prepare(const ActiveSet& active, const ConstantMode* mode);
  /// S_𝒜⁻¹ r for the prepared 𝒜 (through an update: refined once, to the round-off of an LU).
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const;
  /// Whether the prepared S_𝒜 is solved through an update (else by its own LU).
  bool updated() const { return !rows_.empty(); }
  int factorizations() const { return factorizations_; }
  /// κ₂(S_𝒜) = σ_max/σ_min by Spectra's implicitly restarted Lanczos: σ_max² as the largest eigenvalue
  /// of S_𝒜ᵀS_𝒜 (products with the blocks), 1/σ_min² as that of S_𝒜⁻¹S_𝒜⁻ᵀ (solves with the LU; S_𝒜 is
  /// factored anew unless it is the one factored), each to `tolerance` relative in its residual, at most
  /// `max_restarts` restarts of 20 steps of O(m²). Empty where the solves are not finite (S_𝒜 singular to
  /// working precision) or Spectra does not converge. docs/math.md, "The condition number".
  std::optional<double> condition_number(const ActiveSet& active, const ConstantMode* mode, double tolerance = 1e-9,
                                         int max_restarts = 100);

 private:
  void factor(const ActiveSet& active, const ConstantMode* mode);
  Eigen::VectorXd update_solve(const Eigen::VectorXd& r) const;  // the formula alone
  const Eigen::MatrixXd &S_B_, &S_C_;
  DenseLu lu_;                                        // of S_𝒜₀ (in place: no second m × m)
  ActiveSet base_;                                    // 𝒜₀; empty: nothing factored
  ActiveSet active_;                                  // 𝒜 (with an update)
  std::optional<ConstantMode> mode_;                  // the bordering of S_𝒜₀
  std::vector<Eigen::Index> rows_;                    // where 𝒜 differs from 𝒜₀
  Eigen::MatrixXd Z_, V_;                             // S_𝒜₀⁻¹ E and V (columns per changed row)
  Eigen::PartialPivLU<Eigen::MatrixXd> capacitance_;  // I + Vᵀ Z
  int factorizations_ = 0;
};

class ExplicitSchur final : public SchurComplement {
 public:
  /// Assembles S_B and S_C from the Green's table (threaded over blocks of rows and columns; the far
  /// field interpolated when far_field.order > 0); `loads` as above.
  template <int dim>
  ExplicitSchur(const GreenTable<dim>& green, const SparseRows& B_gamma, const SparseRows& C_gamma,
                const SparseRows& loads, const Execution& execution = Execution{}, const DirectTerms& direct = {},
                const FarField& far_field = {}, FarFieldReport* report = nullptr);
  /// The blocks S_B, S_C of an earlier assembly with the rows and columns of the points `changed` made
  /// again from the Green's table (the contact fit moves the points near the contact ends only: the
  /// others keep their rows and so their entries). Exact entries only (no far field) and no direct
  /// terms; a distributed run sums the ranks' parts as the assembly above does.
  template <int dim>
  ExplicitSchur(Eigen::MatrixXd S_B, Eigen::MatrixXd S_C, const std::vector<int>& changed, const GreenTable<dim>& green,
                const SparseRows& B_gamma, const SparseRows& C_gamma, const SparseRows& loads,
                const Execution& execution = Execution{});
  /// From given blocks (tests).
  ExplicitSchur(Eigen::MatrixXd S_B, Eigen::MatrixXd S_C) : S_B_(std::move(S_B)), S_C_(std::move(S_C)) {}
  ExplicitSchur(const ExplicitSchur&) = delete;  // factorization_ refers to the blocks
  ExplicitSchur& operator=(const ExplicitSchur&) = delete;
  int size() const override { return int(S_B_.rows()); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override;
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return 0; }
  /// From the kept LU (NewtonFactorization::condition_number).
  std::optional<double> condition_number(const ActiveSet& active, const ConstantMode* mode) const override {
    return factorization_.condition_number(active, mode);
  }
  const Eigen::MatrixXd& S_B() const { return S_B_; }
  const Eigen::MatrixXd& S_C() const { return S_C_; }
  /// Hands the blocks over (to the next fitted solve's update, without a copy); the object is to be
  /// destroyed next.
  void release(Eigen::MatrixXd& S_B, Eigen::MatrixXd& S_C) { S_B.swap(S_B_), S_C.swap(S_C_); }
  /// S_𝒜: row i of S_B (i ∈ 𝒜) or of S_C, bordered by `mode` when given.
  Eigen::MatrixXd newton_matrix(const ActiveSet& active, const ConstantMode* mode = nullptr) const;
  /// y = S_𝒜 x without forming S_𝒜.
  void apply_newton(const ActiveSet& active, const ConstantMode* mode, const Eigen::VectorXd& x,
                    Eigen::VectorXd& y) const;
  /// Every rank takes rank 0's blocks (a distributed run: the ranks then run the same Newton steps on
  /// the same numbers, bit for bit, as their collective products need). Collective.
  void share(const Distribution& distribution);
  /// The solver of S_𝒜, kept between calls (NewtonFactorization); valid until the next call. `solve`
  /// and this change that kept state: one ExplicitSchur serves one thread.
  const NewtonFactorization& factorization(const ActiveSet& active, const ConstantMode* mode) const;
  /// LU factorizations so far.
  int factorizations() const { return factorization_.factorizations(); }

 private:
  Eigen::MatrixXd S_B_, S_C_;
  mutable NewtonFactorization factorization_{S_B_, S_C_};
};

/// The exact S with the interpolated one as its preconditioner: `apply` is the exact S (one fast
/// solve, ImplicitSchur), `solve` runs GMRES on the exact S_𝒜 right-preconditioned by the LU of
/// S̃_𝒜 (ExplicitSchur with a far field: its kept LU or an update of it), to `options`' tolerance. Newton runs first on
/// S̃ alone (no fast solve), then on this from where it ended: the answer is that of the exact S, the cost a few fast
/// solves.
class PreconditionedSchur final : public SchurComplement {
 public:
  PreconditionedSchur(const ExplicitSchur& approximate, const ImplicitSchur& exact, const GmresOptions& options)
      : approximate_(approximate), exact_(exact), options_(options) {}
  int size() const override { return exact_.size(); }
  void apply(const Eigen::VectorXd& lambda, Eigen::VectorXd& sb, Eigen::VectorXd& sc) const override {
    exact_.apply(lambda, sb, sc);
  }
  LinearSolveReport solve(const ActiveSet& active, const Eigen::VectorXd& d, const ConstantMode* mode,
                          Eigen::VectorXd& lambda, double& alpha) const override;
  std::size_t fast_solves() const override { return exact_.fast_solves(); }
  /// That of S̃_𝒜 (to the interpolation's accuracy).
  std::optional<double> condition_number(const ActiveSet& active, const ConstantMode* mode) const override {
    return approximate_.condition_number(active, mode);
  }

 private:
  const ExplicitSchur& approximate_;
  const ImplicitSchur& exact_;
  GmresOptions options_;
};

/// Dense (rows × cols) block R G Qᵀ from sparse rows and the Green's table (dim = 2 or 3).
template <int dim>
Eigen::MatrixXd green_block(const GreenTable<dim>& green, const SparseRows& R, const SparseRows& Q,
                            const Execution& execution = Execution{}, const FarField& far_field = {});
/// The blocks R_k G Qᵀ of several row sets with the same number of rows at once: (G Qᵀ) is evaluated
/// once per distinct node of the R_k (B_γ's nodes of x_i lie in C_γ's), so the exact cost is
/// (distinct nodes)·nnz(Q) lookups. With a partial table (a distributed run) each rank gets its part
/// of every entry (the ranks' parts add up to the entries), and the call is collective: every rank
/// calls it with the same rows.
template <int dim>
std::vector<Eigen::MatrixXd> green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                          const SparseRows& Q, const Execution& execution = Execution{},
                                          const FarField& far_field = {}, FarFieldReport* report = nullptr);

/// The blocks R_k G Qᵀ kept in a partition for memory (compressed_green_blocks): near pairs of clusters
/// dense (their entries as green_blocks makes them); far pairs (interpolated: U_x G(P_x, P_y) V_yᵀ) of
/// low rank, A Bᵀ by adaptive cross approximation on that product's rows and columns to
/// far_field_recompression, or dense where the rank is not low enough to save memory. No m × m array is
/// made.
struct CompressedBlocks {
  struct Cluster {
    int begin, end;  // items [begin, end) in tree order
  };
  struct Block {
    int x, y;                            // row and column clusters
    std::vector<Eigen::MatrixXd> dense;  // per row set (p × q), or empty: low rank
    std::vector<Eigen::MatrixXd> left;   // low rank, per row set: p × k
    std::vector<Eigen::MatrixXd> right;  // low rank, per row set: q × k
    bool held = true;                    // false: another rank's (none of the above here)
  };
  int n_rows = 0, n_cols = 0, n_sets = 0;
  std::vector<int> row_item, col_item;  // tree order → row (column) index
  std::vector<Cluster> row_clusters, col_clusters;
  std::vector<Block> blocks;
  std::vector<int> row_parent;  // the row tree's parents (−1: root)
  /// A distributed run: the ranks hold disjoint shares of the blocks (`held`), chosen for equal work, and
  /// a product is the sum over the ranks of each one's blocks' product. Null: every block is here.
  std::shared_ptr<const Distribution> distribution;
  /// What this rank's blocks take.
  double bytes() const;
  /// y[k] = (R_k G Qᵀ) x for every row set k; with `set_of_row`, row i is wanted of set set_of_row[i]
  /// only (the Newton matrix's rows) and the blocks whose rows want none of a set skip it, so the other
  /// entries of y are unspecified. Distributed: collective, the same bits on every rank.
  void multiply(const Eigen::VectorXd& x, std::vector<Eigen::VectorXd>& y, int threads,
                const std::vector<char>* set_of_row = nullptr) const;
  /// Groups of rows: the row clusters of at most `size` items nearest the root (items in tree order).
  std::vector<int> groups(int size) const;
  /// The block of set k over the rows × the columns of row cluster g, both in the cluster's tree order
  /// (the row sets and Q must number the same points, as S_B, S_C). Distributed: this rank's blocks'
  /// entries only (sum over the ranks for the whole).
  Eigen::MatrixXd diagonal_block(int k, int g) const;
};

/// An owner among `ranks` ranks for each piece of work: dearest first, each to the rank with the least so
/// far (all 0 on one rank). The same answer on every rank for the same work.
std::vector<int> share_out(const std::vector<double>& work, int ranks);

/// Matrix k ← its sum over the ranks on rank owners[k] only (a rank for each matrix, the same on every
/// rank); on the other ranks it is left as it was. In messages of about 32 MiB. Serial: unchanged.
/// Collective.
void sum_onto_owners(const Distribution& distribution, const std::vector<Eigen::MatrixXd*>& matrices,
                     const std::vector<int>& owners);

/// The relative accuracy of the far blocks' recompression: two orders below the interpolation's own
/// error (1e-3 … 1e-4), so S̃ steers Newton as well as with 1e-8 (the same steps and fast solves on the
/// sphere at N = 384 and 512), in 45 % less memory (bench/results/2026-11-28-newton-and-grid-phases.md).
inline constexpr double far_field_recompression = 1e-5;

/// green_blocks, kept compressed: the blocks of `storage`'s partition (pairs of clusters of up to
/// storage.leaf rows at the bottom; admissible where max radius ≤ storage.eta·distance), its far ones of
/// low rank. The entries come as in green_blocks with `far_field` (order > 0): the near blocks' mostly
/// interpolated, in pieces of far_field's partition.
template <int dim>
CompressedBlocks compressed_green_blocks(const GreenTable<dim>& green, const std::vector<const SparseRows*>& row_sets,
                                         const SparseRows& Q, const Execution& execution, const FarField& far_field,
                                         const FarField& storage, FarFieldReport* report = nullptr);

}  // namespace fictus
