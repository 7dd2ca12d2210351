#pragma once
// What the recorded-answer tests share: digests of a vector and the comparison of a case with its
// recording (1e-12 relative, or 1e-14 absolute for quantities formed by cancellation).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace fictus::regression {

/// Σ|v|, Σv², Σ(k+1)|v_k|/n: positive digests that also see a permutation.
template <class Vector>
nlohmann::json digest(const Vector& v) {
  double a = 0, s = 0, w = 0;
  const double n = double(v.size());
  for (std::size_t k = 0; k < std::size_t(v.size()); ++k) {
    const double x = double(v[k]);
    a += std::abs(x);
    s += x * x;
    w += double(k + 1) * std::abs(x) / n;
  }
  return nlohmann::json::array({a, s, w});
}

/// Every number of `expected` against `actual`, to `tolerance` relative, or 1e-14 absolute: the
/// round-off of quantities of order one or smaller that are formed by cancellation (the relative error
/// norms, u_h − u over |u| ≈ 1e-4 … 1e-7, move by ~1e-15 when u_h does; gaps at round-off).
inline void compare(const nlohmann::json& expected, const nlohmann::json& actual, const std::string& where,
                    double tolerance) {
  if (expected.is_number()) {
    ASSERT_TRUE(actual.is_number()) << where;
    const double a = expected.get<double>(), b = actual.get<double>();
    EXPECT_LE(std::abs(a - b), tolerance * std::max(std::abs(a), std::abs(b)) + 1e-14)
        << where << ": recorded " << a << ", now " << b;
  } else if (expected.is_array() || expected.is_object()) {
    ASSERT_EQ(expected.size(), actual.size()) << where;
    if (expected.is_array())
      for (std::size_t k = 0; k < expected.size(); ++k)
        compare(expected[k], actual[k], where + "[" + std::to_string(k) + "]", tolerance);
    else
      for (const auto& [key, value] : expected.items()) {
        ASSERT_TRUE(actual.contains(key)) << where << "." << key;
        compare(value, actual[key], where + "." + key, tolerance);
      }
  }
}

/// One case against its recording: every value to 1e-12 relative, with two refinements that keep the
/// criterion at round-off:
///  - a digest's second entry is a sum of squares (twice the relative change of its terms);
///  - the independent check's entries ("check") are differences of two ∂u/∂n stencils whose operands
///    are nodal values over h: compared to 1e-12·max|û|/h ("stencil_scale"), the round-off of such a stencil.
inline void compare_recorded(const nlohmann::json& recorded, const nlohmann::json& now, const std::string& name) {
  constexpr double tolerance = 1e-12;
  for (const auto& [key, value] : recorded.items()) {
    ASSERT_TRUE(now.contains(key)) << name << "." << key;
    const nlohmann::json& actual = now[key];
    if (key == "check") {
      const double scale = now["stencil_scale"].get<double>();
      for (std::size_t k = 0; k < value.size(); ++k)
        EXPECT_LE(std::abs(value[k].get<double>() - actual[k].get<double>()), tolerance * scale)
            << name << ".check[" << k << "]: recorded " << value[k] << ", now " << actual[k];
    } else if (value.is_array() && value.size() == 3) {
      for (std::size_t k = 0; k < 3; ++k)
        compare(value[k], actual[k], name + "." + key + "[" + std::to_string(k) + "]",
                k == 1 ? 2 * tolerance : tolerance);
    } else {
      compare(value, actual, name + "." + key, tolerance);
    }
  }
}

}  // namespace fictus::regression
