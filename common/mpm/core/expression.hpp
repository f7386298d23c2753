#pragma once
/// Formulas written by users (a body's initial velocity or stress as a function of position),
/// compiled once by muparser and evaluated many times. muparser stays inside expression.cpp.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mpm {

/// A formula that does not compile: what is wrong and where (0-based character position in
/// the formula's text, -1 when muparser gives none).
class ExpressionError : public std::runtime_error {
 public:
  ExpressionError(const std::string& message, int position)
      : std::runtime_error(message), position_(position) {}
  int position() const { return position_; }

 private:
  int position_;
};

/// A compiled formula over named variables, with the constants pi and e and muparser's
/// functions (sin, cos, tan, exp, log, sqrt, abs, min, max, sum, sign, rint, ...).
/// Not copyable; one object per thread (evaluation uses the object's stack).
class Expression {
 public:
  /// Compiles `text` over the variables `names`, bound to `values` (values[k] is names[k]),
  /// which the caller sets before each eval() and which must outlive the object. Throws
  /// ExpressionError for a syntax error or an unknown name.
  Expression(const std::string& text, const std::vector<std::string>& names, double* values);
  ~Expression();
  Expression(const Expression&) = delete;
  Expression& operator=(const Expression&) = delete;
  /// The formula's value at the variables' current values.
  double eval() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// "at position 5 of 'cos(pi*x': missing parenthesis": an ExpressionError for messages.
std::string describe(const ExpressionError& e, const std::string& text);

}  // namespace mpm
