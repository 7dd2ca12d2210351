#include "vtk_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "fictus/boundary/curve_grid_intersection.hpp"

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

/// One appended array: `count` values of `value_bytes` each (components flattened), made by `fill`
/// for values [first, first + n) into `out`; fill is called from several threads at once.
struct Appended {
  std::size_t value_bytes;
  std::size_t count;
  std::function<void(std::size_t first, std::size_t n, unsigned char* out)> fill;
};

template <class T>
Appended values_of(const std::vector<T>& v) {
  return {sizeof(T), v.size(), [&v](std::size_t first, std::size_t n, unsigned char* out) {
            std::memcpy(out, v.data() + first, n * sizeof(T));
          }};
}

/// A value per index, made by `value(k)`.
template <class T, class F>
Appended computed(std::size_t count, F value) {
  return {sizeof(T), count, [value](std::size_t first, std::size_t n, unsigned char* out) {
            T* values = reinterpret_cast<T*>(out);
            for (std::size_t k = 0; k < n; ++k) values[k] = value(first + k);
          }};
}

constexpr std::uint64_t block_bytes = 1 << 20;
constexpr char offset_mark[] = "@offset@";
constexpr int offset_digits = 20;

/// Writes one array in VTK's zlib layout (UInt64 block count, block size, size of the last block,
/// compressed size of each block, then the blocks): made and compressed `chunk` blocks at a time on
/// `threads` threads, written in order; the header is written last.
void write_array(std::ostream& out, const Appended& a, int threads) {
  const std::uint64_t bytes = a.count * a.value_bytes, per_block = block_bytes / a.value_bytes;
  const std::uint64_t blocks = bytes == 0 ? 0 : (bytes + block_bytes - 1) / block_bytes;
  std::vector<std::uint64_t> header{blocks, block_bytes, bytes == 0 ? 0 : bytes - (blocks - 1) * block_bytes};
  header.resize(3 + blocks, 0);
  const auto at = out.tellp();
  out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size() * sizeof(std::uint64_t)));
  const std::int64_t chunk = 8 * std::max(1, threads);
  std::vector<std::vector<unsigned char>> compressed(static_cast<std::size_t>(chunk));
  for (std::int64_t first = 0; first < std::int64_t(blocks); first += chunk) {
    const std::int64_t n = std::min<std::int64_t>(chunk, std::int64_t(blocks) - first);
    bool failed = false;
    std::exception_ptr error;  // a fill that throws (an exact solution's expression): rethrown here
#pragma omp parallel num_threads(threads) reduction(|| : failed)
    {
      std::vector<unsigned char> raw(block_bytes);
#pragma omp for schedule(dynamic)
      for (std::int64_t b = 0; b < n; ++b) {
        const std::uint64_t value = std::uint64_t(first + b) * per_block;
        const std::uint64_t values = std::min<std::uint64_t>(per_block, a.count - value);
        try {
          a.fill(value, values, raw.data());
          failed = failed || !deflate_block(raw.data(), values * a.value_bytes, compressed[std::size_t(b)]);
        } catch (...) {
#pragma omp critical(fictus_vtk_fill)
          if (!error) error = std::current_exception();
          failed = true;
        }
      }
    }
    if (error) std::rethrow_exception(error);
    if (failed) throw std::runtime_error("output: zlib could not compress an array");
    for (std::int64_t b = 0; b < n; ++b) {
      const auto& block = compressed[std::size_t(b)];
      header[3 + std::size_t(first + b)] = block.size();
      out.write(reinterpret_cast<const char*>(block.data()), std::streamsize(block.size()));
    }
  }
  const auto end = out.tellp();
  out.seekp(at);
  out.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size() * sizeof(std::uint64_t)));
  out.seekp(end);
}

/// A VTK XML file: `xml` is its text up to the appended data, with offset_mark where each array's
/// offset goes (in the order of `arrays`); the arrays follow, then the offsets are filled in.
void write_appended(std::ostream& out, std::string xml, const std::vector<Appended>& arrays, int threads) {
  const auto start = out.tellp();
  if (start == std::ostream::pos_type(-1)) throw std::runtime_error("output: VTK files are written to seekable files");
  std::vector<std::size_t> marks;
  for (std::size_t at = xml.find(offset_mark); at != std::string::npos; at = xml.find(offset_mark, at)) {
    xml.replace(at, sizeof offset_mark - 1, std::string(offset_digits, '0'));
    marks.push_back(at);
  }
  if (marks.size() != arrays.size()) throw std::logic_error("write_appended: one offset mark per array");
  out << xml << "  <AppendedData encoding=\"raw\">\n   _";
  const auto base = out.tellp();
  std::vector<std::uint64_t> offsets;
  for (const Appended& a : arrays) {
    offsets.push_back(std::uint64_t(out.tellp() - base));
    write_array(out, a, threads);
  }
  out << "\n  </AppendedData>\n</VTKFile>\n";
  const auto end = out.tellp();
  for (std::size_t k = 0; k < marks.size(); ++k) {
    std::string digits = std::to_string(offsets[k]);
    digits.insert(0, offset_digits - digits.size(), '0');  // leading zeros: the same width, the same number
    out.seekp(start + std::streamoff(marks[k]));
    out.write(digits.data(), std::streamsize(digits.size()));
  }
  out.seekp(end);
}

std::string header(const char* type) {
  return std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"") + type +
         "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
         "compressor=\"vtkZLibDataCompressor\">\n";
}

/// The XML of one appended data array.
std::string array_xml(const char* type, const std::string& name, int components = 1) {
  return "        <DataArray type=\"" + std::string(type) + "\" Name=\"" + name + "\"" +
         (components > 1 ? " NumberOfComponents=\"" + std::to_string(components) + "\"" : std::string()) +
         " format=\"appended\" offset=\"" + offset_mark + "\"/>\n";
}

/// Named arrays of one kind of data (point or cell data), their XML and their values.
struct DataArrays {
  std::string xml;
  std::vector<Appended> arrays;
  void add(const char* type, const std::string& name, Appended values, int components = 1) {
    xml += array_xml(type, name, components);
    arrays.push_back(std::move(values));
  }
};

/// The extent "0 n0 0 n1 0 n2", or with `planes` the planes [first, last] along `axis`.
std::string extent_of(std::array<int, 3> n, int axis = 0, std::array<int, 2> planes = {-1, -1}) {
  std::string text;
  for (int d = 0; d < 3; ++d) {
    const bool cut = d == axis && planes[0] >= 0;
    text += (d ? " " : "") + std::to_string(cut ? planes[0] : 0) + " " + std::to_string(cut ? planes[1] : n[d]);
  }
  return text;
}

/// ImageData of the nodes of extent [0, n_d] with the point data `data`; a piece (planes [first, last]
/// along `axis`) when planes are given.
void write_image(std::ostream& out, std::array<int, 3> n, Point3 origin, Point3 spacing, const DataArrays& data,
                 int threads, int axis = 0, std::array<int, 2> planes = {-1, -1}) {
  std::ostringstream xml;
  xml.precision(17);
  xml << header("ImageData") << "  <ImageData WholeExtent=\"" << extent_of(n) << "\" Origin=\"" << origin.x << ' '
      << origin.y << ' ' << origin.z << "\" Spacing=\"" << spacing.x << ' ' << spacing.y << ' ' << spacing.z
      << "\">\n    <Piece Extent=\"" << extent_of(n, axis, planes) << "\">\n      <PointData Scalars=\"u\">\n"
      << data.xml << "      </PointData>\n    </Piece>\n  </ImageData>\n";
  write_appended(out, xml.str(), data.arrays, threads);
}

/// The node planes [first, last] of the slowest axis that `piece` covers (all of them without one).
template <int dim>
std::array<int, 2> planes_of(const Grid<dim>& grid, const FieldPiece* piece) {
  return piece ? std::array<int, 2>{piece->first, piece->last} : std::array<int, 2>{0, grid.n(dim - 1)};
}

/// û at node i: the solution's whole field, or the piece's values (its slab and the next layer).
template <int dim>
double field_at(const Grid<dim>& grid, const GridVector& whole, const FieldPiece* piece,
                const typename Grid<dim>::Index& i) {
  if (!grid.has_unknown(i)) return 0.0;
  if (piece) return (*piece->values)[grid.slab_index(i, piece->slab)];
  return whole.empty() ? 0.0 : whole[grid.index(i)];
}

/// One kind of cells of a PolyData: "Verts", "Lines" or "Polys"; the points of cell k, by index, are
/// connectivity[offsets[k − 1] … offsets[k]].
struct PolyCells {
  const char* kind;
  std::vector<std::int64_t> connectivity, offsets;
};

/// PolyData of `points` (3 coordinates each) with the cells of `sections` (in VTK's order: verts,
/// lines, polys), and point and cell data.
void write_poly(std::ostream& out, const std::vector<double>& points, const std::vector<PolyCells>& sections,
                const DataArrays& point_data, const DataArrays& cell_data, int threads) {
  std::string counts, cells;
  for (const PolyCells& c : sections) {
    counts += std::string(" NumberOf") + c.kind + "=\"" + std::to_string(c.offsets.size()) + "\"";
    cells += std::string("      <") + c.kind + ">\n" + array_xml("Int64", "connectivity") +
             array_xml("Int64", "offsets") + "      </" + c.kind + ">\n";
  }
  std::string xml = header("PolyData") + "  <PolyData>\n    <Piece NumberOfPoints=\"" +
                    std::to_string(points.size() / 3) + "\"" + counts + ">\n      <PointData>\n" + point_data.xml +
                    "      </PointData>\n      <CellData>\n" + cell_data.xml + "      </CellData>\n      <Points>\n" +
                    array_xml("Float64", "points", 3) + "      </Points>\n" + cells + "    </Piece>\n  </PolyData>\n";
  std::vector<Appended> arrays = point_data.arrays;
  arrays.insert(arrays.end(), cell_data.arrays.begin(), cell_data.arrays.end());
  arrays.push_back(values_of(points));
  for (const PolyCells& c : sections) {
    arrays.push_back(values_of(c.connectivity));
    arrays.push_back(values_of(c.offsets));
  }
  write_appended(out, xml, arrays, threads);
}

}  // namespace

void write_vti(std::ostream& out, const Problem& problem, const Solution& s, const FieldPiece* piece) {
  const Grid2& grid = s.grid;
  const int nx = grid.nx(), ny = grid.ny();
  const std::array<int, 2> planes = planes_of(grid, piece);
  const std::size_t n = std::size_t(nx + 1) * std::size_t(planes[1] - planes[0] + 1);
  const CurveGridIntersection geometry(*problem.gamma, grid);
  const auto node = [nx, &planes](std::size_t k) {
    return std::pair<int, int>{int(k % (nx + 1)), planes[0] + int(k / (nx + 1))};
  };
  const auto u = [&](std::size_t k) {
    const auto [i, j] = node(k);
    return field_at(grid, s.u, piece, {i, j});
  };
  const auto exact = [&](std::size_t k) {
    const auto [i, j] = node(k);
    return geometry.node_inside(i, j) ? problem.exact(grid.x(i), grid.y(j)) : 0.0;
  };
  DataArrays data;
  data.add("Float64", "u", computed<double>(n, u));
  data.add("UInt8", "inside", computed<std::uint8_t>(n, [&](std::size_t k) {
             const auto [i, j] = node(k);
             return std::uint8_t(geometry.node_inside(i, j));
           }));
  if (problem.exact && (piece || !s.u.empty())) {
    data.add("Float64", "u_exact", computed<double>(n, exact));
    data.add("Float64", "error", computed<double>(n, [&](std::size_t k) {
               const auto [i, j] = node(k);
               return geometry.node_inside(i, j) ? u(k) - exact(k) : 0.0;
             }));
  }
  write_image(out, {nx, ny, 0}, Point3{grid.box().lower.x, grid.box().lower.y, 0.0}, {grid.h(), grid.h(), 1.0}, data,
              s.options.threads, 1, piece ? planes : std::array<int, 2>{-1, -1});
}

namespace {

/// A closed polyline through m points.
void write_closed_line(std::ostream& out, const std::vector<Point2>& p, const DataArrays& point_data, int threads) {
  const std::size_t m = p.size();
  std::vector<double> points;
  std::vector<std::int64_t> connectivity;
  for (std::size_t i = 0; i < m; ++i) {
    points.insert(points.end(), {p[i].x, p[i].y, 0.0});
    connectivity.push_back(std::int64_t(i));
  }
  connectivity.push_back(0);
  write_poly(out, points, {{"Lines", connectivity, {std::int64_t(m + 1)}}}, point_data, {}, threads);
}

}  // namespace

void write_curve_vtp(std::ostream& out, const Solution& s) {
  const std::size_t m = std::size_t(s.collocation.m);
  std::vector<double> normal, gap(m), contact(m), condition(m);
  for (std::size_t i = 0; i < m; ++i) {
    normal.insert(normal.end(), {s.collocation.normal[i].x, s.collocation.normal[i].y, 0.0});
    gap[i] = s.trace[i] - s.g[i];
    contact[i] = double(s.in_contact(int(i)));
    condition[i] = double(s.condition(int(i)));
  }
  DataArrays data;
  data.add("Float64", "s", values_of(s.collocation.s));
  data.add("Float64", "g", values_of(s.g));
  data.add("Float64", "u", values_of(s.trace));
  data.add("Float64", "dudn", values_of(s.normal_derivative));
  if (s.check && s.check->normal_derivative.size() == m)
    data.add("Float64", "dudn_check", values_of(s.check->normal_derivative));
  data.add("Float64", "gap", values_of(gap));
  data.add("Float64", "contact", values_of(contact));
  data.add("Float64", "condition", values_of(condition));
  if (s.options.variant == Variant::nonsmooth) data.add("Float64", "lambda", values_of(s.lambda));
  data.add("Float64", "normal", values_of(normal), 3);
  write_closed_line(out, s.collocation.point, data, s.options.threads);
}

void write_offset_curve_vtp(std::ostream& out, const Solution& s) {
  std::vector<Point2> points;
  for (int i = 0; i < s.collocation.m; ++i) points.push_back(s.Gamma->position(s.collocation.t[i]));
  DataArrays data;
  data.add("Float64", "lambda", values_of(s.lambda));
  write_closed_line(out, points, data, s.options.threads);
}

void write_vti(std::ostream& out, const SurfaceProblem& problem, const SurfaceSolution& s, const FieldPiece* piece) {
  const Grid3& grid = s.grid;
  const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
  const std::array<int, 2> planes = planes_of(grid, piece);
  const std::size_t n = std::size_t(nx + 1) * std::size_t(ny + 1) * std::size_t(planes[1] - planes[0] + 1);
  const auto node = [nx, ny, &planes](std::size_t k) {
    return Grid3::Index{int(k % (nx + 1)), int(k / (nx + 1) % (ny + 1)),
                        planes[0] + int(k / (std::size_t(nx + 1) * (ny + 1)))};
  };
  const auto x = [&](const Grid3::Index& i) { return Point3{grid.x(i[0]), grid.y(i[1]), grid.z(i[2])}; };
  std::vector<std::uint8_t> inside(n);  // a byte a node: the level function once per node
#pragma omp parallel for num_threads(s.options.threads) schedule(static)
  for (std::int64_t k = 0; k < std::int64_t(n); ++k) inside[std::size_t(k)] = problem.gamma->level(x(node(k))) < 0;
  const auto u = [&](std::size_t k) { return field_at(grid, s.u, piece, node(k)); };
  const auto exact = [&](std::size_t k) {
    const Point3 p = x(node(k));
    return inside[k] ? problem.exact(p.x, p.y, p.z) : 0.0;
  };
  DataArrays data;
  data.add("Float64", "u", computed<double>(n, u));
  data.add("UInt8", "inside", values_of(inside));
  if (problem.exact) {
    data.add("Float64", "u_exact", computed<double>(n, exact));
    data.add("Float64", "error", computed<double>(n, [&](std::size_t k) { return inside[k] ? u(k) - exact(k) : 0.0; }));
  }
  write_image(out, {nx, ny, nz}, grid.box().lower, {grid.h(), grid.h(), grid.h()}, data, s.options.threads, 2,
              piece ? planes : std::array<int, 2>{-1, -1});
}

template <int dim>
void write_pvti(std::ostream& out, const BasicProblem<dim>& problem, const BasicSolution<dim>& s,
                const std::vector<std::pair<std::array<int, 2>, std::string>>& pieces) {
  const Grid<dim>& grid = s.grid;
  const std::array<int, 3> n{grid.nx(), grid.n(1), dim == 3 ? grid.n(dim - 1) : 0};
  const Point3 origin{grid.box().lower[0], grid.box().lower[1], dim == 3 ? grid.box().lower[dim - 1] : 0.0};
  std::ostringstream xml;
  xml.precision(17);
  xml << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n  <PImageData WholeExtent=\""
      << extent_of(n) << "\" GhostLevel=\"0\" Origin=\"" << origin.x << ' ' << origin.y << ' ' << origin.z
      << "\" Spacing=\"" << grid.h() << ' ' << grid.h() << ' ' << (dim == 3 ? grid.h() : 1.0)
      << "\">\n    <PPointData Scalars=\"u\">\n      <PDataArray type=\"Float64\" Name=\"u\"/>\n"
         "      <PDataArray type=\"UInt8\" Name=\"inside\"/>\n";
  if (problem.exact)
    xml << "      <PDataArray type=\"Float64\" Name=\"u_exact\"/>\n      <PDataArray type=\"Float64\" "
           "Name=\"error\"/>\n";
  xml << "    </PPointData>\n";
  for (const auto& [planes, file] : pieces)
    xml << "    <Piece Extent=\"" << extent_of(n, dim - 1, planes) << "\" Source=\"" << file << "\"/>\n";
  xml << "  </PImageData>\n</VTKFile>\n";
  out << xml.str();
}

template void write_pvti(std::ostream&, const BasicProblem<2>&, const BasicSolution<2>&,
                         const std::vector<std::pair<std::array<int, 2>, std::string>>&);
template void write_pvti(std::ostream&, const BasicProblem<3>&, const BasicSolution<3>&,
                         const std::vector<std::pair<std::array<int, 2>, std::string>>&);

namespace {

/// The triangles of a patched surface with shared points (bitwise equal corners are one point),
/// cell data per patch (its outward normal among them) and, at the points, the area-weighted means of
/// the same over their triangles.
void write_patched(std::ostream& out, const PatchedSurface& surface,
                   const std::vector<std::pair<std::string, const std::vector<double>*>>& per_patch, int threads) {
  std::map<std::tuple<double, double, double>, std::int64_t> index;
  std::vector<double> points;
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<double> weight;                               // Σ area of a point's triangles
  std::vector<std::vector<double>> sums(per_patch.size());  // Σ area·value
  const std::size_t T = surface.triangles.size();
  std::vector<std::int32_t> patch(T);
  for (std::size_t t = 0; t < T; ++t) {
    const Triangle3& tri = surface.triangles[t];
    const double a = area(tri);
    patch[t] = surface.patch_of[t];
    for (const Point3& p : {tri.a, tri.b, tri.c}) {
      const auto [it, added] = index.try_emplace({p.x, p.y, p.z}, std::int64_t(points.size() / 3));
      if (added) {
        points.insert(points.end(), {p.x, p.y, p.z});
        weight.push_back(0.0);
        for (auto& s : sums) s.push_back(0.0);
      }
      connectivity.push_back(it->second);
      weight[std::size_t(it->second)] += a;
      for (std::size_t k = 0; k < per_patch.size(); ++k)
        sums[k][std::size_t(it->second)] += a * (*per_patch[k].second)[std::size_t(patch[t])];
    }
    offsets.push_back(std::int64_t(connectivity.size()));
  }
  for (auto& s : sums)
    for (std::size_t p = 0; p < s.size(); ++p) s[p] = weight[p] > 0 ? s[p] / weight[p] : 0.0;
  DataArrays point_data, cell_data;
  cell_data.add("Int32", "patch", values_of(patch));
  cell_data.add(
      "Float64", "normal",
      computed<double>(
          3 * T, [&surface, &patch](std::size_t k) { return surface.normal[std::size_t(patch[k / 3])][int(k % 3)]; }),
      3);
  for (std::size_t k = 0; k < per_patch.size(); ++k) {
    const std::vector<double>& v = *per_patch[k].second;
    point_data.add("Float64", per_patch[k].first, values_of(sums[k]));
    cell_data.add("Float64", per_patch[k].first,
                  computed<double>(T, [&v, &patch](std::size_t t) { return v[std::size_t(patch[t])]; }));
  }
  write_poly(out, points, {{"Polys", connectivity, offsets}}, point_data, cell_data, threads);
}

}  // namespace

void write_surface_vtp(std::ostream& out, const SurfaceSolution& s) {
  std::vector<double> gap(s.trace.size()), contact(s.trace.size()), condition(s.trace.size());
  for (std::size_t p = 0; p < gap.size(); ++p) {
    gap[p] = s.trace[p] - s.g[p];
    contact[p] = double(s.in_contact(int(p)));
    condition[p] = double(s.condition(int(p)));
  }
  std::vector<std::pair<std::string, const std::vector<double>*>> values = {
      {"g", &s.g},   {"u", &s.trace},       {"dudn", &s.normal_derivative},
      {"gap", &gap}, {"contact", &contact}, {"condition", &condition}};
  if (s.check && s.check->normal_derivative.size() == s.trace.size())
    values.push_back({"dudn_check", &s.check->normal_derivative});
  if (s.options.variant == Variant::nonsmooth) values.push_back({"lambda", &s.lambda});
  write_patched(out, s.gamma, values, s.options.threads);
}

void write_offset_surface_vtp(std::ostream& out, const SurfaceSolution& s) {
  write_patched(out, s.Gamma, {{"lambda", &s.lambda}}, s.options.threads);
}

template <int dim>
void write_contact_boundary_vtp(std::ostream& out, const BasicSolution<dim>& s) {
  std::vector<double> points;
  PolyCells verts{"Verts", {}, {}}, lines{"Lines", {}, {}};
  for (const Point<dim>& x : s.contact_boundary) {
    for (int d = 0; d < 3; ++d) points.push_back(d < dim ? x[d] : 0.0);
    verts.connectivity.push_back(std::int64_t(verts.offsets.size()));
    verts.offsets.push_back(std::int64_t(verts.offsets.size() + 1));
  }
  for (const auto& [a, b] : s.contact_boundary_lines) {
    lines.connectivity.insert(lines.connectivity.end(), {a, b});
    lines.offsets.push_back(std::int64_t(lines.connectivity.size()));
  }
  write_poly(out, points, {verts, lines}, {}, {}, s.options.threads);
}

template void write_contact_boundary_vtp(std::ostream&, const BasicSolution<2>&);
template void write_contact_boundary_vtp(std::ostream&, const BasicSolution<3>&);

void write_vtm(std::ostream& out, const std::vector<std::pair<std::string, std::string>>& blocks) {
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" "
         "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <vtkMultiBlockDataSet>\n";
  for (std::size_t k = 0; k < blocks.size(); ++k)
    out << "    <DataSet index=\"" << k << "\" name=\"" << blocks[k].first << "\" file=\"" << blocks[k].second
        << "\"/>\n";
  out << "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
}

}  // namespace fictus::cli
