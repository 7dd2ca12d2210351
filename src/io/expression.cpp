#include "fictus/io/expression.hpp"

#include <muParser.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <deque>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include "fictus/solve/options.hpp"

namespace fictus {

struct Expression::Shared {
  std::string text, key;
  std::string evaluated;  // the text as evaluated: text with its squares as products (squares_as_products)
  std::vector<std::string> variables;
  std::vector<std::pair<std::string, double>> constants;
  std::uint64_t id;
  std::optional<double> constant;  // the value, where the text names no variable and no local
};

namespace {
/// An expression as an error message shows it: at most 60 characters, one line.
std::string shown(const std::string& text) {
  std::string s = text.size() > 60 ? text.substr(0, 57) + "..." : text;
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  return s;
}
}  // namespace

namespace {

std::atomic<std::uint64_t> next_id{1};

struct Compiled {
  mu::Parser parser;
  std::vector<double> values;
  std::deque<double> locals;  // storage of the names assigned inside the expression ("a = …, a^2")
  std::vector<std::string> local_names;
};

/// muParser's variable factory: an unknown name becomes a local of the expression.
double* make_local(const char* name, void* data) {
  auto* c = static_cast<Compiled*>(data);
  c->local_names.emplace_back(name);
  return &c->locals.emplace_back(0.0);
}

/// The function squares_as_products calls: one product, the exact square correctly rounded (glibc's
/// std::pow(v, 2) is one unit in the last place off it for about 1 in 1200 values).
constexpr const char* square_function = "__fictus_square";
double square(double v) { return v * v; }

bool is_blank(char ch) { return static_cast<unsigned char>(ch) <= 0x20; }  // muParser's blanks
bool is_name_char(char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; }

}  // namespace

/// `text` with every "(…)^2" and "name(…)^2" written "__fictus_square((…))": muParser makes a square
/// of a variable ("x^2") a product itself but calls std::pow for any other base, and pow was a third
/// of the time of evaluating a level function such as "((x - 0.49)^2 + (y - 0.51)^2)/0.19^2 - 1".
/// The exponent must be the integer literal 2, not followed by another "^" ("(a)^2^3" is (a)^8: "^" is
/// right-associative); "^" binds tighter than every other operator, the sign included ("-(2)^2" is
/// −4), so a parenthesised base or a call is its whole left operand. Anything else is left as written.
std::string squares_as_products(std::string text) {
  for (std::size_t from = 0;;) {
    const std::size_t caret = text.find('^', from);
    if (caret == std::string::npos) return text;
    from = caret + 1;
    std::size_t e = caret + 1;  // the exponent: "2", then neither a name, a number nor another "^"
    while (e < text.size() && is_blank(text[e])) ++e;
    if (e >= text.size() || text[e] != '2') continue;
    std::size_t after = e + 1;
    if (after < text.size() && (is_name_char(text[after]) || text[after] == '.')) continue;
    while (after < text.size() && is_blank(text[after])) ++after;
    if (after < text.size() && text[after] == '^') continue;
    std::size_t close = caret;  // the base: "( … )", after a function's name if one stands there
    while (close > 0 && is_blank(text[close - 1])) --close;
    if (close == 0 || text[close - 1] != ')') continue;
    --close;
    std::size_t open = close;
    int depth = 0;
    for (;; --open) {
      depth += text[open] == ')' ? 1 : text[open] == '(' ? -1 : 0;
      if (depth == 0 || open == 0) break;
    }
    if (depth != 0) continue;
    while (open > 0 && is_name_char(text[open - 1])) --open;
    const std::string base = text.substr(open, close + 1 - open);
    const std::string square_of = std::string(square_function) + "(" + base + ")";
    text.replace(open, e + 1 - open, square_of);
    from = open + square_of.size();
  }
}

namespace {

std::unique_ptr<Compiled> compile(const std::string& text, const std::vector<std::string>& variables,
                                  const std::vector<std::pair<std::string, double>>& constants,
                                  bool with_square = false) {
  auto c = std::make_unique<Compiled>();
  if (with_square) c->parser.DefineFun(square_function, square);
  // muParser's own _pi and _e stop at 13 digits (3.141592653589): the full doubles instead.
  c->parser.DefineConst("_pi", std::numbers::pi);
  c->parser.DefineConst("_e", std::numbers::e);
  for (const auto& [name, value] : constants) c->parser.DefineConst(name, value);
  c->values.assign(variables.size(), 0.0);
  for (std::size_t k = 0; k < variables.size(); ++k) c->parser.DefineVar(variables[k], &c->values[k]);
  c->parser.SetVarFactory(make_local, c.get());
  c->parser.SetExpr(text);
  return c;
}

/// This thread's compiled parser of expression `id` (made on first use).
Compiled& compiled(std::uint64_t id, const std::string& text, const std::vector<std::string>& variables,
                   const std::vector<std::pair<std::string, double>>& constants) {
  thread_local std::unordered_map<std::uint64_t, std::unique_ptr<Compiled>> cache;
  auto& slot = cache[id];
  if (!slot) slot = compile(text, variables, constants, true);
  return *slot;
}

/// One evaluation at the values set. Locals start as NaN on every evaluation: one read before it is
/// assigned (on some branch) gives NaN, which the callers' finiteness checks report, never a value left
/// from an earlier call.
double evaluate_once(Compiled& c) {
  std::fill(c.locals.begin(), c.locals.end(), std::numeric_limits<double>::quiet_NaN());
  return c.parser.Eval();
}

/// Where `name` first appears in `text` as a whole word, or npos.
std::size_t find_word(const std::string& text, const std::string& name) {
  std::size_t at = 0;
  while ((at = text.find(name, at)) != std::string::npos) {
    const bool starts = at == 0 || !is_name_char(text[at - 1]);
    const std::size_t end = at + name.size();
    if (starts && (end == text.size() || !is_name_char(text[end]))) return at;
    at = end;
  }
  return std::string::npos;
}

/// A local must be assigned where it first appears ("a = …, … a …"); otherwise it is a misspelt
/// or unknown variable. Returns the first offending name, or "". (A read before the assignment on
/// some branch, e.g. "a = a + x", passes here and evaluates to NaN: locals start as NaN.)
std::string unassigned_local(const std::string& text, const std::vector<std::string>& locals) {
  for (const std::string& name : locals) {
    const std::size_t at = find_word(text, name);
    std::size_t next = at == std::string::npos ? at : at + name.size();
    while (next < text.size() && is_blank(text[next])) ++next;
    if (next == text.size()) next = std::string::npos;
    const bool assigned =
        next != std::string::npos && text[next] == '=' && (next + 1 == text.size() || text[next + 1] != '=');
    if (!assigned) return name;
  }
  return "";
}

}  // namespace

Expression::Expression(std::string text, std::vector<std::string> variables, std::string key,
                       std::vector<std::pair<std::string, double>> constants) {
  auto shared = std::make_shared<Shared>();
  shared->text = std::move(text);
  shared->key = std::move(key);
  shared->variables = std::move(variables);
  shared->constants = std::move(constants);
  shared->id = next_id++;
  if (shared->text.find_first_not_of(" \t\n") == std::string::npos)
    throw std::invalid_argument(shared->key + ": empty expression");
  try {
    auto c = compile(shared->text, shared->variables, shared->constants);
    c->parser.Eval();  // reports syntax errors
    const std::string unknown = unassigned_local(shared->text, c->local_names).substr(0, 40);
    if (!unknown.empty()) {
      std::vector<std::string> known = shared->variables;  // the variables, parameters, constants and functions
      for (const auto& [name, value] : shared->constants) known.push_back(name);
      for (const auto& [name, value] : c->parser.GetConst()) known.push_back(name);
      for (const auto& [name, value] : c->parser.GetFunDef()) known.push_back(name);
      std::string hint = did_you_mean(unknown, known);
      if (hint.empty()) hint = " (a local name must be assigned first: \"" + unknown + " = …, …\")";
      throw std::invalid_argument(shared->key + ": cannot parse \"" + shown(shared->text) + "\": unknown variable \"" +
                                  unknown + "\"" + hint);
    }
    // The text as evaluated: its squares as products, or the text as given where that does not compile
    // (past muParser's length limit, or a muParser that refuses a form the given text uses).
    shared->evaluated = squares_as_products(shared->text);
    std::unique_ptr<Compiled> evaluated;
    try {
      evaluated = compile(shared->evaluated, shared->variables, shared->constants, true);
      evaluated->parser.Eval();
    } catch (const mu::Parser::exception_type&) {
      shared->evaluated = shared->text;
      evaluated = compile(shared->text, shared->variables, shared->constants, true);
    }
    bool constant = c->local_names.empty();
    for (const std::string& name : shared->variables)
      constant = constant && find_word(shared->text, name) == std::string::npos;
    if (constant) shared->constant = evaluated->parser.Eval();  // the value evaluate() and operator() give
  } catch (const mu::Parser::exception_type& e) {
    for (const auto& [name, value] : shared->constants) {  // "a = …" where a is a parameter
      const std::size_t at = find_word(shared->text, name);
      std::size_t next = at == std::string::npos ? at : shared->text.find_first_not_of(" \t", at + name.size());
      if (next != std::string::npos && shared->text[next] == '=' &&
          (next + 1 == shared->text.size() || shared->text[next + 1] != '='))
        throw std::invalid_argument(
            shared->key + ": \"" + name.substr(0, 40) +
            "\" is a parameter ([parameters]) and cannot be assigned; name the local otherwise");
    }
    throw std::invalid_argument(shared->key + ": cannot parse \"" + shown(shared->text) +
                                "\": " + e.GetMsg().substr(0, 80));
  }
  shared_ = std::move(shared);
}

double Expression::operator()(const double* values) const {
  Compiled& c = compiled(shared_->id, shared_->evaluated, shared_->variables, shared_->constants);
  std::copy(values, values + c.values.size(), c.values.begin());
  try {
    return evaluate_once(c);
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument(shared_->key + ": cannot evaluate \"" + shared_->text + "\": " + e.GetMsg());
  }
}

void Expression::evaluate(std::size_t n, std::initializer_list<const double*> columns, double* out) const {
  if (columns.size() != shared_->variables.size())
    throw std::invalid_argument(shared_->key + ": wrong number of columns");
  if (shared_->constant) {
    std::fill(out, out + n, *shared_->constant);
    return;
  }
  Compiled& c = compiled(shared_->id, shared_->evaluated, shared_->variables, shared_->constants);
  const double* const* column = columns.begin();
  try {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < c.values.size(); ++k) c.values[k] = column[k][i];
      out[i] = evaluate_once(c);
    }
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument(shared_->key + ": cannot evaluate \"" + shared_->text + "\": " + e.GetMsg());
  }
}

double Expression::operator()(std::initializer_list<double> values) const {
  if (values.size() != shared_->variables.size())
    throw std::invalid_argument(shared_->key + ": wrong number of values");
  return (*this)(values.begin());
}

const std::string& Expression::text() const { return shared_->text; }
const std::string& Expression::key() const { return shared_->key; }
bool is_builtin_name(const std::string& name) {
  const mu::Parser parser;
  return parser.GetFunDef().count(name) > 0 || parser.GetConst().count(name) > 0;
}

bool Expression::mentions(const std::string& name) const { return find_word(shared_->text, name) != std::string::npos; }

}  // namespace fictus
