#pragma once
// ParaView files, VTK XML with appended binary arrays compressed by zlib in 1 MiB blocks (as VTK's
// vtkZLibDataCompressor writes them), streamed: each array is made and compressed block by block, in
// parallel, and written as it comes, so that no array is ever held whole (the stream must be seekable:
// the offsets are written last).
//   solution.vti         the grid field (ImageData);
//   curves.vtp           2-D: γ as a closed polyline through the points, their values as point data;
//   offset_curve.vtp     2-D, smooth variant: Γ behind the points, with λ;
//   surface.vtp          3-D: γ's triangles with shared points, the values of each patch as cell data
//                        and their area-weighted means at the points as point data;
//   offset_surface.vtp   3-D, smooth variant: Γ's triangles with λ;
//   contact_boundary.vtp where the contact ends on γ, one vertex per active–free pair of neighbouring
//                        points (the contact set resolved inside the points' parts, docs/math.md), and
//                        in 3-D the lines joining consecutive ones;
//   solution.vtm         a multiblock file naming the others: opens a whole run in ParaView.
#include <array>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "fictus/boundary/omega_quadrature.hpp"
#include "fictus/boundary/surface.hpp"
#include "fictus/solve/fictitious_domain_solver.hpp"
#include "fictus/solve/surface_discretization.hpp"

namespace fictus::cli {

/// A piece of the field, for a run on several MPI ranks: the node planes [first, last] of the slowest
/// axis (y in 2-D, z in 3-D), û from `values`, which holds `slab`'s layers and the next one
/// (Grid::slab_index). Neighbouring pieces share their last and first plane, as VTK's pieces do.
struct FieldPiece {
  int first = 0, last = 0;
  Slab slab;
  const GridVector* values = nullptr;
};

/// û at all (nx+1)(ny+1) nodes (x fastest; 0 on a Dirichlet boundary), "inside" (1 in ω), and,
/// with an exact solution, "u_exact" and "error" (û − u, 0 outside ω). With `piece`: that piece's nodes.
void write_vti(std::ostream& out, const Problem& problem, const Solution& solution, const FieldPiece* piece = nullptr);
/// γ through the collocation points with point data s, g, u, dudn, gap (u − g), contact, normal, the
/// independent check's dudn_check when there is one, and lambda in the non-smooth variant.
void write_curve_vtp(std::ostream& out, const Solution& solution);
/// Γ (smooth variant) through the points of Γ behind the collocation points, with lambda.
void write_offset_curve_vtp(std::ostream& out, const Solution& solution);

/// 3-D: û at all (N+1)³ nodes, "inside" (1 in ω) and, with an exact solution, "u_exact" and "error"
/// (0 outside ω). With `piece`: that piece's nodes.
void write_vti(std::ostream& out, const SurfaceProblem& problem, const SurfaceSolution& solution,
               const FieldPiece* piece = nullptr);
/// The parallel file (PImageData) naming the pieces' files, each with its node planes [first, last]
/// along the slowest axis: solution.pvti of a run on several ranks.
template <int dim>
void write_pvti(std::ostream& out, const BasicProblem<dim>& problem, const BasicSolution<dim>& solution,
                const std::vector<std::pair<std::array<int, 2>, std::string>>& pieces);
/// 3-D: γ's triangles (points shared), cell data patch, normal (the patch's outward normal), g, u,
/// dudn, gap, contact, condition (and dudn_check where the solve made the independent check, lambda in
/// the non-smooth variant), point data the area-weighted means of the same over the triangles at a point.
void write_surface_vtp(std::ostream& out, const SurfaceSolution& solution);
/// 3-D, smooth variant: Γ's triangles, cell data patch, normal and lambda, point data lambda.
void write_offset_surface_vtp(std::ostream& out, const SurfaceSolution& solution);

/// Both dimensions: the points of solution.contact_boundary as vertices and (3-D) the lines of
/// solution.contact_boundary_lines.
template <int dim>
void write_contact_boundary_vtp(std::ostream& out, const BasicSolution<dim>& solution);

/// A vtkMultiBlockDataSet file naming (block name, file name) pairs, the files beside it.
void write_vtm(std::ostream& out, const std::vector<std::pair<std::string, std::string>>& blocks);

}  // namespace fictus::cli
