#pragma once
// User expressions (muParser syntax: + - * / ^, sin, cos, exp, sqrt, abs, min, max, a ? b : c, _pi …)
// in named variables, e.g. "x^2 + sin(y)" in (x, y). Comma-separated parts may name intermediate
// values, and the last part is the value: "r2 = (x - 0.5)^2 + y^2, exp(-r2) * r2" (a local must be
// assigned where it first appears). Parsed and checked once at construction; evaluation is
// thread-safe (one compiled parser per thread, made on first use).
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace fictus {

class Expression {
 public:
  /// Throws std::invalid_argument("<key>: cannot parse \"<text>\": <reason>") on a syntax error or
  /// an unknown variable.
  /// `constants` are named numbers the text may use (a problem file's [parameters]).
  Expression(std::string text, std::vector<std::string> variables, std::string key,
             std::vector<std::pair<std::string, double>> constants = {});

  /// Value for the variables in the order given at construction.
  double operator()(std::initializer_list<double> values) const;
  double operator()(const double* values) const;
  /// Values at n points: columns[k][i] is variable k at point i (one array per variable, in the order
  /// given at construction). One parser lookup for all of them; an expression that names none of its
  /// variables is evaluated once.
  void evaluate(std::size_t n, std::initializer_list<const double*> columns, double* out) const;

  const std::string& text() const;
  /// Whether the text names `name` as a whole word (a variable, constant or local of that name).
  bool mentions(const std::string& name) const;
  const std::string& key() const;

 private:
  struct Shared;
  std::shared_ptr<const Shared> shared_;
};

/// A function or constant of the expression language (sin, atan2, _pi, …): not a name for a parameter.
bool is_builtin_name(const std::string& name);

/// The text an Expression evaluates: every "(…)^2" and "name(…)^2" written as a call of a square
/// function ("__fictus_square((…))"): one product, the square correctly rounded, at a fraction of
/// std::pow's cost (whose value is one unit in the last place off it for about 1 in 1200 values). Other
/// powers and "x^2" of a name (a product already) are left as written.
std::string squares_as_products(std::string text);

}  // namespace fictus
