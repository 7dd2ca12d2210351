#pragma once
// ParaView files: solution.vti (VTK XML ImageData, appended Float64/UInt8 arrays compressed with zlib in
// 1 MiB blocks, as VTK's vtkZLibDataCompressor writes them) and
// curves.vtp (VTK XML PolyData, γ and Γ as closed polylines with the point data of points.csv).
#include <ostream>

#include "fictus/fictitious_domain_solver.hpp"

namespace fictus::cli {

/// û at all (nx+1)(ny+1) nodes (x fastest; 0 on a Dirichlet boundary), "inside" (1 in ω), and,
/// with an exact solution, "u_exact" and "error" (û − u, 0 outside ω).
void write_vti(std::ostream& out, const Problem& problem, const Solution& solution);
void write_vtp(std::ostream& out, const Solution& solution);

}  // namespace fictus::cli
