#include "fictus/expression.hpp"

#include <muParser.h>

#include <atomic>
#include <stdexcept>
#include <unordered_map>

namespace fictus {

struct Expression::Shared {
  std::string text, key;
  std::vector<std::string> variables;
  std::uint64_t id;
};

namespace {

std::atomic<std::uint64_t> next_id{1};

struct Compiled {
  mu::Parser parser;
  std::vector<double> values;
};

std::unique_ptr<Compiled> compile(const std::string& text, const std::vector<std::string>& variables) {
  auto c = std::make_unique<Compiled>();
  c->values.assign(variables.size(), 0.0);
  for (std::size_t k = 0; k < variables.size(); ++k) c->parser.DefineVar(variables[k], &c->values[k]);
  c->parser.SetExpr(text);
  return c;
}

}  // namespace

Expression::Expression(std::string text, std::vector<std::string> variables, std::string key) {
  auto shared = std::make_shared<Shared>();
  shared->text = std::move(text);
  shared->key = std::move(key);
  shared->variables = std::move(variables);
  shared->id = next_id++;
  if (shared->text.find_first_not_of(" \t\n") == std::string::npos)
    throw std::invalid_argument(shared->key + ": empty expression");
  try {
    auto c = compile(shared->text, shared->variables);
    c->parser.Eval();  // reports syntax errors and unknown names
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument(shared->key + ": cannot parse \"" + shared->text + "\": " + e.GetMsg());
  }
  shared_ = std::move(shared);
}

double Expression::operator()(const double* values) const {
  thread_local std::unordered_map<std::uint64_t, std::unique_ptr<Compiled>> cache;
  auto& slot = cache[shared_->id];
  if (!slot) slot = compile(shared_->text, shared_->variables);
  for (std::size_t k = 0; k < slot->values.size(); ++k) slot->values[k] = values[k];
  try {
    return slot->parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw std::invalid_argument(shared_->key + ": cannot evaluate \"" + shared_->text + "\": " + e.GetMsg());
  }
}

double Expression::operator()(std::initializer_list<double> values) const {
  if (values.size() != shared_->variables.size()) throw std::invalid_argument(shared_->key + ": wrong number of values");
  return (*this)(values.begin());
}

const std::string& Expression::text() const { return shared_->text; }
const std::string& Expression::key() const { return shared_->key; }

}  // namespace fictus
