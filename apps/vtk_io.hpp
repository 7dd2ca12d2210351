#pragma once
// ParaView files: solution.vti (VTK XML ImageData, appended Float64/UInt8 arrays compressed with zlib in
// 1 MiB blocks, as VTK's vtkZLibDataCompressor writes them) and
// curves.vtp (VTK XML PolyData, γ and Γ as closed polylines with the point data of points.csv).
#include <ostream>

#include "fictus/fictitious_domain_solver.hpp"
#include "fictus/surface_solver.hpp"

namespace fictus::cli {

/// û at all (nx+1)(ny+1) nodes (x fastest; 0 on a Dirichlet boundary), "inside" (1 in ω), and,
/// with an exact solution, "u_exact" and "error" (û − u, 0 outside ω).
void write_vti(std::ostream& out, const Problem& problem, const Solution& solution);
void write_vtp(std::ostream& out, const Solution& solution);

/// 3-D: û at all (N+1)³ nodes, "inside" (1 in ω) and, with an exact solution, "u_exact" and "error"
/// (0 outside ω), zlib-compressed as above.
void write_vti(std::ostream& out, const SurfaceProblem& problem, const SurfaceSolution& solution);
/// 3-D: γ's triangles (and Γ's, in the smooth variant: "surface" 0 and 1) with the values of their patch as
/// cell data (patch, g, u, dudn, lambda, contact).
void write_vtp(std::ostream& out, const SurfaceSolution& solution);

}  // namespace fictus::cli
