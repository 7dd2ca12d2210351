#pragma once
// Points (and vectors) in R^dim and axis-aligned boxes: the geometry every grid-level type is
// written in. Point<2> has x, y; Point<3> has x, y, z; p[d] reads coordinate d of either.
#include <array>
#include <cmath>
#include <cstddef>

namespace fictus {

template <int dim>
struct Point;

template <>
struct Point<2> {
  double x = 0.0, y = 0.0;
  double& operator[](int d) { return d == 0 ? x : y; }
  double operator[](int d) const { return d == 0 ? x : y; }
};

template <>
struct Point<3> {
  double x = 0.0, y = 0.0, z = 0.0;
  double& operator[](int d) { return d == 0 ? x : d == 1 ? y : z; }
  double operator[](int d) const { return d == 0 ? x : d == 1 ? y : z; }
};

using Point2 = Point<2>;
using Point3 = Point<3>;

template <int dim>
Point<dim> operator+(Point<dim> a, const Point<dim>& b) {
  for (int d = 0; d < dim; ++d) a[d] = a[d] + b[d];
  return a;
}
template <int dim>
Point<dim> operator-(Point<dim> a, const Point<dim>& b) {
  for (int d = 0; d < dim; ++d) a[d] = a[d] - b[d];
  return a;
}
template <int dim>
Point<dim> operator*(double s, Point<dim> a) {
  for (int d = 0; d < dim; ++d) a[d] = s * a[d];
  return a;
}
template <int dim>
double dot(const Point<dim>& a, const Point<dim>& b) {
  double sum = a[0] * b[0];
  for (int d = 1; d < dim; ++d) sum += a[d] * b[d];
  return sum;
}
// 2-D written out: these sit in the innermost loops of every 2-D solve.
inline Point<2> operator+(Point<2> a, const Point<2>& b) { return {a.x + b.x, a.y + b.y}; }
inline Point<2> operator-(Point<2> a, const Point<2>& b) { return {a.x - b.x, a.y - b.y}; }
inline Point<2> operator*(double s, Point<2> a) { return {s * a.x, s * a.y}; }
inline double dot(const Point<2>& a, const Point<2>& b) { return a.x * b.x + a.y * b.y; }
inline double norm(const Point<2>& a) { return std::hypot(a.x, a.y); }
inline double norm(const Point<3>& a) { return std::hypot(a.x, a.y, a.z); }
inline Point<3> cross(const Point<3>& u, const Point<3>& v) {
  return {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
}

/// Ω = [lower[0], upper[0]] × … × [lower[dim−1], upper[dim−1]].
template <int dim>
struct Box {
  Point<dim> lower = filled(0.0), upper = filled(1.0);
  double width(int d) const { return upper[d] - lower[d]; }

 private:
  static Point<dim> filled(double v) {
    Point<dim> p;
    for (int d = 0; d < dim; ++d) p[d] = v;
    return p;
  }
};

using Box2 = Box<2>;
using Box3 = Box<3>;

}  // namespace fictus
