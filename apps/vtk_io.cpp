#include "vtk_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "fictus/curve_grid_intersection.hpp"

namespace fictus::cli {

namespace {
/// Deflates `size` bytes into `out` (a zlib stream, as VTK's reader inflates it). Run-length
/// strategy at level 1: it takes the long runs of zeros outside ω at a fraction of the default's time.
bool deflate_block(const unsigned char* data, std::uint64_t size, std::vector<unsigned char>& out) {
  z_stream z{};
  if (deflateInit2(&z, 1, Z_DEFLATED, 15, 8, Z_RLE) != Z_OK) return false;
  out.resize(deflateBound(&z, uLong(size)));
  z.next_in = const_cast<unsigned char*>(data);
  z.avail_in = uInt(size);
  z.next_out = out.data();
  z.avail_out = uInt(out.size());
  const bool done = deflate(&z, Z_FINISH) == Z_STREAM_END;
  out.resize(z.total_out);
  deflateEnd(&z);
  return done;
}

/// One array of the appended section in VTK's zlib layout: a UInt64 header (number of blocks, block
/// size, size of the last block, compressed size of each block), then the compressed blocks.
/// One array of the appended section in VTK's zlib layout: a UInt64 header (number of blocks, block
/// size, size of the last block, compressed size of each block), then the compressed blocks.
struct ZlibArray {
  std::vector<std::uint64_t> header;
  std::vector<std::vector<unsigned char>> blocks;
  std::uint64_t bytes() const {
    std::uint64_t total = header.size() * sizeof(std::uint64_t);
    for (const auto& block : blocks) total += block.size();
    return total;
  }
  void write(std::ostream& out) const {  // straight from the blocks: no joined copy of the array
    out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size() * sizeof(std::uint64_t)));
    for (const auto& block : blocks)
      out.write(reinterpret_cast<const char*>(block.data()), std::streamsize(block.size()));
  }
};

template <class T>
ZlibArray zlib_array(const std::vector<T>& values) {
  constexpr std::uint64_t block = 1 << 20;
  const auto* data = reinterpret_cast<const unsigned char*>(values.data());
  const std::uint64_t bytes = values.size() * sizeof(T);
  const std::uint64_t blocks = bytes == 0 ? 0 : (bytes + block - 1) / block;
  ZlibArray array{{blocks, block, bytes == 0 ? 0 : bytes - (blocks - 1) * block},
                  std::vector<std::vector<unsigned char>>(blocks)};
  // Blocks are independent: compressed in parallel, kept in order.
  bool failed = false;
#pragma omp parallel for schedule(dynamic) reduction(|| : failed)
  for (std::int64_t b = 0; b < std::int64_t(blocks); ++b)
    failed = failed || !deflate_block(data + b * block, std::min(block, bytes - b * block), array.blocks[b]);
  if (failed) throw std::runtime_error("output: zlib could not compress solution.vti");
  for (const auto& part : array.blocks) array.header.push_back(part.size());
  return array;
}
struct ImageArray {
  const char* type;
  const char* name;
  ZlibArray data;
};

/// VTK XML ImageData with appended zlib arrays at the nodes of extent [0, n_d].
void write_image(std::ostream& out, std::array<int, 3> n, Point3 origin, Point3 spacing,
                 const std::vector<ImageArray>& arrays) {
  out.precision(17);
  const std::string extent = "0 " + std::to_string(n[0]) + " 0 " + std::to_string(n[1]) + " 0 " + std::to_string(n[2]);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
         "compressor=\"vtkZLibDataCompressor\">\n"
      << "  <ImageData WholeExtent=\"" << extent << "\" Origin=\"" << origin.x << ' ' << origin.y << ' ' << origin.z
      << "\" Spacing=\"" << spacing.x << ' ' << spacing.y << ' ' << spacing.z << "\">\n"
      << "    <Piece Extent=\"" << extent << "\">\n"
      << "      <PointData Scalars=\"u\">\n";
  std::uint64_t offset = 0;
  for (const ImageArray& a : arrays) {
    out << "        <DataArray type=\"" << a.type << "\" Name=\"" << a.name << "\" format=\"appended\" offset=\""
        << offset << "\"/>\n";
    offset += a.data.bytes();
  }
  out << "      </PointData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";
  for (const ImageArray& a : arrays) a.data.write(out);
  out << "\n  </AppendedData>\n</VTKFile>\n";
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
  std::vector<ImageArray> arrays = {{"Float64", "u", zlib_array(u)}, {"UInt8", "inside", zlib_array(inside)}};
  if (with_exact) {
    arrays.push_back({"Float64", "u_exact", zlib_array(exact)});
    arrays.push_back({"Float64", "error", zlib_array(error)});
  }
  write_image(out, {nx, ny, 0}, Point3{grid.box().lower.x, grid.box().lower.y, 0.0}, {grid.h(), grid.h(), 1.0}, arrays);
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

void write_vti(std::ostream& out, const SurfaceProblem& problem, const SurfaceSolution& s) {
  const Grid3& grid = s.grid;
  const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
  const std::size_t n = std::size_t(nx + 1) * std::size_t(ny + 1) * std::size_t(nz + 1);
  std::vector<double> u(n, 0.0), exact, error;
  std::vector<std::uint8_t> inside(n, 0);
  const bool with_exact = bool(problem.exact);
  if (with_exact) exact.assign(n, 0.0), error.assign(n, 0.0);
#pragma omp parallel for schedule(static)
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const std::size_t at = (std::size_t(k) * (ny + 1) + j) * (nx + 1) + i;
        const Grid3::Index node{i, j, k};
        if (grid.has_unknown(node)) u[at] = s.u[grid.index(node)];
        const Point3 x{grid.x(i), grid.y(j), grid.z(k)};
        inside[at] = problem.gamma->level(x) < 0;
        if (with_exact && inside[at]) {
          exact[at] = problem.exact(x.x, x.y, x.z);
          error[at] = u[at] - exact[at];
        }
      }
  std::vector<ImageArray> arrays = {{"Float64", "u", zlib_array(u)}, {"UInt8", "inside", zlib_array(inside)}};
  if (with_exact) {
    arrays.push_back({"Float64", "u_exact", zlib_array(exact)});
    arrays.push_back({"Float64", "error", zlib_array(error)});
  }
  write_image(out, {nx, ny, nz}, grid.box().lower, {grid.h(), grid.h(), grid.h()}, arrays);
}

void write_vtp(std::ostream& out, const SurfaceSolution& s) {
  const bool two = s.delta > 0;
  const std::vector<const PatchedSurface*> surfaces =
      two ? std::vector<const PatchedSurface*>{&s.gamma, &s.Gamma} : std::vector<const PatchedSurface*>{&s.gamma};
  std::size_t triangles = 0;
  for (const PatchedSurface* surface : surfaces) triangles += surface->triangles.size();
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      << "  <PolyData>\n    <Piece NumberOfPoints=\"" << 3 * triangles << "\" NumberOfPolys=\"" << triangles << "\">\n"
      << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const PatchedSurface* surface : surfaces)
    for (const Triangle3& t : surface->triangles)
      for (const Point3& p : {t.a, t.b, t.c}) out << p.x << ' ' << p.y << ' ' << p.z << '\n';
  out << "        </DataArray>\n      </Points>\n      <Polys>\n"
      << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < triangles; ++t) out << 3 * t << ' ' << 3 * t + 1 << ' ' << 3 * t + 2 << '\n';
  out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < triangles; ++t) out << 3 * (t + 1) << '\n';
  out << "        </DataArray>\n      </Polys>\n      <CellData Scalars=\"lambda\">\n";
  auto cells = [&](const char* type, const char* name, auto value) {
    out << "        <DataArray type=\"" << type << "\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (std::size_t c = 0; c < surfaces.size(); ++c)
      for (int patch : surfaces[c]->patch_of) out << value(int(c), patch) << '\n';
    out << "        </DataArray>\n";
  };
  cells("Int32", "surface", [](int c, int) { return c; });
  cells("Int32", "patch", [](int, int p) { return p; });
  cells("Float64", "g", [&](int, int p) { return s.g[p]; });
  cells("Float64", "u", [&](int, int p) { return s.trace[p]; });
  cells("Float64", "dudn", [&](int, int p) { return s.normal_derivative[p]; });
  cells("Float64", "lambda", [&](int, int p) { return s.lambda[p]; });
  cells("Int32", "contact", [&](int, int p) { return int(s.newton.active[p]); });
  out << "      </CellData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
}

}  // namespace fictus::cli
