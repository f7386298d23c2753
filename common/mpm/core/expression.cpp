#include "mpm/core/expression.hpp"

#include <muParser.h>

#include <cmath>

namespace mpm {

struct Expression::Impl {
  mu::Parser parser;
};

Expression::Expression(const std::string& text, const std::vector<std::string>& names,
                       double* values)
    : impl_(std::make_unique<Impl>()) {
  try {
    mu::Parser& p = impl_->parser;
    p.DefineConst("pi", M_PI);
    p.DefineConst("e", M_E);
    for (std::size_t k = 0; k < names.size(); ++k) p.DefineVar(names[k], &values[k]);
    p.SetExpr(text);
    (void)p.Eval();  // compiles: syntax errors and unknown names are found here
  } catch (const mu::Parser::exception_type& e) {
    throw ExpressionError(e.GetMsg(), e.GetPos());
  }
}

Expression::~Expression() = default;

double Expression::eval() const {
  try {
    return impl_->parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw ExpressionError(e.GetMsg(), e.GetPos());
  }
}

std::string describe(const ExpressionError& e, const std::string& text) {
  std::string s =
      e.position() >= 0 ? "at position " + std::to_string(e.position() + 1) + " of '" : "in '";
  return s + text + "': " + e.what();
}

}  // namespace mpm
