#include "vtk_io.hpp"

#include <cstdint>
#include <limits>
#include <vector>

#include "fictus/curve_grid_intersection.hpp"

namespace fictus::cli {

namespace {
template <class T>
void append_raw(std::ostream& out, const std::vector<T>& values) {
  const std::uint64_t bytes = values.size() * sizeof(T);
  out.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(bytes));
}
}  // namespace

void write_vti(std::ostream& out, const Problem& problem, const Solution& s) {
  const Grid2& grid = s.grid;
  const int nx = grid.nx(), ny = grid.ny();
  const std::size_t n = std::size_t(nx + 1) * std::size_t(ny + 1);
  const CurveGridIntersection geometry(*problem.gamma, grid);
  std::vector<double> u(n, 0.0), exact, error;
  std::vector<std::uint8_t> inside(n, 0);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const std::size_t k = std::size_t(j) * (nx + 1) + i;
      if (grid.has_unknown(i, j) && !s.u.empty()) u[k] = s.u[grid.index(i, j)];
      inside[k] = geometry.node_inside(i, j);
    }
  const bool with_exact = bool(problem.exact) && !s.u.empty();
  if (with_exact) {
    exact.assign(n, 0.0);
    error.assign(n, 0.0);
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const std::size_t k = std::size_t(j) * (nx + 1) + i;
        if (!inside[k]) continue;
        exact[k] = problem.exact(grid.x(i), grid.y(j));
        error[k] = u[k] - exact[k];
      }
  }
  const std::uint64_t header = sizeof(std::uint64_t);
  std::uint64_t offset = 0;
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <ImageData WholeExtent=\"0 " << nx << " 0 " << ny << " 0 0\" Origin=\"" << grid.box().lower.x << ' '
      << grid.box().lower.y << " 0\" Spacing=\"" << grid.h() << ' ' << grid.h() << " 1\">\n"
      << "    <Piece Extent=\"0 " << nx << " 0 " << ny << " 0 0\">\n"
      << "      <PointData Scalars=\"u\">\n";
  auto array = [&](const char* type, const char* name, std::uint64_t bytes) {
    out << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" format=\"appended\" offset=\"" << offset
        << "\"/>\n";
    offset += header + bytes;
  };
  array("Float64", "u", n * 8);
  array("UInt8", "inside", n);
  if (with_exact) {
    array("Float64", "u_exact", n * 8);
    array("Float64", "error", n * 8);
  }
  out << "      </PointData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";
  append_raw(out, u);
  append_raw(out, inside);
  if (with_exact) {
    append_raw(out, exact);
    append_raw(out, error);
  }
  out << "\n  </AppendedData>\n</VTKFile>\n";
}

void write_vtp(std::ostream& out, const Solution& s) {
  const int m = s.collocation.m;
  const bool two_curves = s.delta > 0;
  const int n_points = two_curves ? 2 * m : m;
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      << "  <PolyData>\n    <Piece NumberOfPoints=\"" << n_points << "\" NumberOfLines=\"" << (two_curves ? 2 : 1)
      << "\">\n"
      << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int i = 0; i < m; ++i) out << s.collocation.point[i].x << ' ' << s.collocation.point[i].y << " 0\n";
  if (two_curves)
    for (int i = 0; i < m; ++i) {
      const Point2 p = s.Gamma->position(s.collocation.t[i]);
      out << p.x << ' ' << p.y << " 0\n";
    }
  out << "        </DataArray>\n      </Points>\n      <Lines>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int c = 0; c < (two_curves ? 2 : 1); ++c) {
    for (int i = 0; i < m; ++i) out << c * m + i << ' ';
    out << c * m << '\n';
  }
  out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n"
      << m + 1 << (two_curves ? " " + std::to_string(2 * (m + 1)) : std::string()) << "\n        </DataArray>\n"
      << "      </Lines>\n      <PointData Scalars=\"lambda\">\n";
  auto scalars = [&](const char* name, auto value) {
    out << "        <DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (int c = 0; c < (two_curves ? 2 : 1); ++c)
      for (int i = 0; i < m; ++i) out << value(i) << '\n';
    out << "        </DataArray>\n";
  };
  scalars("g", [&](int i) { return s.g[i]; });
  scalars("u", [&](int i) { return s.trace[i]; });
  scalars("dudn", [&](int i) { return s.normal_derivative[i]; });
  scalars("lambda", [&](int i) { return s.lambda[i]; });
  scalars("contact", [&](int i) { return double(s.newton.active[i]); });
  scalars("s", [&](int i) { return s.collocation.s[i]; });
  out << "        <DataArray type=\"Int32\" Name=\"curve\" format=\"ascii\">\n";
  for (int c = 0; c < (two_curves ? 2 : 1); ++c)
    for (int i = 0; i < m; ++i) out << c << '\n';
  out << "        </DataArray>\n        <DataArray type=\"Float64\" Name=\"normal\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (int c = 0; c < (two_curves ? 2 : 1); ++c)
    for (int i = 0; i < m; ++i) out << s.collocation.normal[i].x << ' ' << s.collocation.normal[i].y << " 0\n";
  out << "        </DataArray>\n      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
}

}  // namespace fictus::cli
