#include "fictus/boundary/surface.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace fictus {

// ---------------------------------------------------------------------------------------------
// Surfaces

Matrix3 Surface::level_hessian(const Point3& p) const {
  const Box3 box = bounds();
  const double step = 1e-5 * std::max({box.width(0), box.width(1), box.width(2)});
  Matrix3 H;
  for (int d = 0; d < 3; ++d) {
    Point3 plus = p, minus = p;
    plus[d] += step;
    minus[d] -= step;
    const Point3 column = (0.5 / step) * (level_gradient(plus) - level_gradient(minus));
    for (int e = 0; e < 3; ++e) H[e][d] = column[e];
  }
  for (int d = 0; d < 3; ++d)  // symmetric
    for (int e = 0; e < d; ++e) H[d][e] = H[e][d] = 0.5 * (H[d][e] + H[e][d]);
  return H;
}

Ellipsoid::Ellipsoid(Point3 center, Point3 semi_axes) : center_(center), semi_axes_(semi_axes) {
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(center[d])) throw std::invalid_argument("geometry.center: must be finite");
    if (!(semi_axes[d] > 0) || !std::isfinite(semi_axes[d]))
      throw std::invalid_argument("geometry.semi_axes: must be positive and finite");
  }
}

double Ellipsoid::level(const Point3& p) const {
  double sum = -1.0;
  for (int d = 0; d < 3; ++d) {
    const double t = (p[d] - center_[d]) / semi_axes_[d];
    sum += t * t;
  }
  return sum;
}

Point3 Ellipsoid::level_gradient(const Point3& p) const {
  Point3 g;
  for (int d = 0; d < 3; ++d) g[d] = 2 * (p[d] - center_[d]) / (semi_axes_[d] * semi_axes_[d]);
  return g;
}

Matrix3 Ellipsoid::level_hessian(const Point3&) const {
  Matrix3 H{};
  for (int d = 0; d < 3; ++d) H[d][d] = 2 / (semi_axes_[d] * semi_axes_[d]);
  return H;
}

PatchedSurface Ellipsoid::patches(int m, double edge) const { return ellipsoid_patches(center_, semi_axes_, m, edge); }

double Ellipsoid::area() const {
  // Knud Thomsen's formula (within 1.1 %; exact for a sphere): enough for the default m.
  const double a = semi_axes_.x, b = semi_axes_.y, c = semi_axes_.z, p = 1.6075;
  return 4 * std::numbers::pi * std::pow((std::pow(a * b, p) + std::pow(a * c, p) + std::pow(b * c, p)) / 3, 1 / p);
}

Box3 Ellipsoid::bounds() const {
  Box3 box;
  box.lower = center_ - semi_axes_;
  box.upper = center_ + semi_axes_;
  return box;
}

Torus::Torus(Point3 center, double R, double r) : center_(center), R_(R), r_(r) {
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(center[d])) throw std::invalid_argument("geometry.center: must be finite");
  if (!(r > 0 && R > r && std::isfinite(R))) throw std::invalid_argument("geometry.radii: need 0 < r < R, finite");
}

double Torus::level(const Point3& p) const {
  const Point3 d = p - center_;
  const double planar = std::hypot(d.x, d.y) - R_;
  return (planar * planar + d.z * d.z - r_ * r_) / (2 * r_);  // ≈ the signed distance near γ
}

Point3 Torus::level_gradient(const Point3& p) const {
  const Point3 d = p - center_;
  const double rho = std::hypot(d.x, d.y);
  const double scale = rho > 0 ? (rho - R_) / rho : 0.0;  // the z-axis, far inside the hole: no radial part
  return (1.0 / r_) * Point3{scale * d.x, scale * d.y, d.z};
}

Matrix3 Torus::level_hessian(const Point3& p) const {
  const Point3 d = p - center_;
  const double rho = std::hypot(d.x, d.y);
  Matrix3 H{};
  H[2][2] = 1 / r_;
  if (rho == 0) return H;  // the axis, far inside the hole
  const double radial = (1 - R_ / rho) / r_, bend = R_ / (rho * rho * rho * r_);
  H[0][0] = radial + bend * d.x * d.x;
  H[1][1] = radial + bend * d.y * d.y;
  H[0][1] = H[1][0] = bend * d.x * d.y;
  return H;
}

PatchedSurface Torus::patches(int m, double edge) const { return torus_patches(center_, R_, r_, m, edge); }

double Torus::area() const { return 4 * std::numbers::pi * std::numbers::pi * R_ * r_; }

Box3 Torus::bounds() const {
  Box3 box;
  box.lower = center_ - Point3{R_ + r_, R_ + r_, r_};
  box.upper = center_ + Point3{R_ + r_, R_ + r_, r_};
  return box;
}

TransformedSurface::TransformedSurface(std::shared_ptr<const Surface> base, int axis, double angle, Point3 shift)
    : base_(std::move(base)), axis_(axis), cos_(std::cos(angle)), sin_(std::sin(angle)), shift_(shift) {
  if (!base_) throw std::invalid_argument("geometry: no surface given");
  if (axis < 0 || axis > 2) throw std::invalid_argument("TransformedSurface: the axis is 0 (x), 1 (y) or 2 (z)");
  const Box3 b = base_->bounds();
  center_ = 0.5 * (b.lower + b.upper);
}

Point3 TransformedSurface::rotate(const Point3& v) const {  // in the plane of the two other axes
  const int i = (axis_ + 1) % 3, j = (axis_ + 2) % 3;
  Point3 r = v;
  r[i] = cos_ * v[i] - sin_ * v[j];
  r[j] = sin_ * v[i] + cos_ * v[j];
  return r;
}

Point3 TransformedSurface::unrotate(const Point3& v) const {
  const int i = (axis_ + 1) % 3, j = (axis_ + 2) % 3;
  Point3 r = v;
  r[i] = cos_ * v[i] + sin_ * v[j];
  r[j] = -sin_ * v[i] + cos_ * v[j];
  return r;
}

Matrix3 TransformedSurface::level_hessian(const Point3& p) const {
  const Matrix3 H = base_->level_hessian(back(p));
  Matrix3 HRt, out;                                   // H Rᵀ by rows, then R (H Rᵀ) by columns
  for (int r = 0; r < 3; ++r) HRt[r] = rotate(H[r]);  // row r of H Rᵀ is R·(row r of H)
  for (int c = 0; c < 3; ++c) {
    const Point3 column = rotate({HRt[0][c], HRt[1][c], HRt[2][c]});
    for (int r = 0; r < 3; ++r) out[r][c] = column[r];
  }
  return out;
}

PatchedSurface TransformedSurface::patches(int m, double edge) const {
  PatchedSurface s = base_->patches(m, edge);
  for (Triangle3& t : s.triangles) t = {forward(t.a), forward(t.b), forward(t.c)};
  for (Point3& p : s.point) p = forward(p);
  for (Point3& n : s.normal) n = rotate(n);
  return s;
}

Box3 TransformedSurface::bounds() const {
  const Box3 b = base_->bounds();
  Box3 out{forward(b.lower), forward(b.lower)};
  for (int corner = 0; corner < 8; ++corner) {
    const Point3 p = forward(
        {corner & 1 ? b.upper.x : b.lower.x, corner & 2 ? b.upper.y : b.lower.y, corner & 4 ? b.upper.z : b.lower.z});
    for (int d = 0; d < 3; ++d)
      out.lower[d] = std::min(out.lower[d], p[d]), out.upper[d] = std::max(out.upper[d], p[d]);
  }
  return out;
}

}  // namespace fictus
