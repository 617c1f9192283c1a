// Lowers calls of the built-in functions (spec §6): elementwise math, der(), reductions,
// and the array constructors and operators (fill, zeros, cross, dot, transpose, diagonal, ...).
#include <cmath>

#include "flatten/Flattener.h"

namespace qdot::flat {

using namespace qdot::ast;
using sym::Expr;
using sym::Kind;

namespace {

struct UnaryMath {
  const char* name;
  Kind kind;
};
const UnaryMath kUnaryMath[] = {
    {"sin", Kind::Sin},   {"cos", Kind::Cos},   {"tan", Kind::Tan},   {"asin", Kind::Asin},
    {"acos", Kind::Acos}, {"atan", Kind::Atan}, {"sinh", Kind::Sinh}, {"cosh", Kind::Cosh},
    {"tanh", Kind::Tanh}, {"exp", Kind::Exp},   {"log", Kind::Log},   {"abs", Kind::Abs},
    {"sign", Kind::Sign},
};

}  // namespace

std::optional<Kind> unaryMathKind(std::string_view name) {
  for (const auto& u : kUnaryMath)
    if (name == u.name) return u.kind;
  return std::nullopt;
}

// d/dt with one memo for the whole model. A symbol's rate is asked once, when a derivative first
// reaches it: time → 1, parameters (and non-variables) → 0, any other variable → its der() variable,
// created on demand (an error at `where` if it cannot have one; it is then asked again next time).
Expr Flattener::timeDerivative(Expr e, SourceRange where) {
  derivativeSite_ = where;
  return timeDerivative_(e);
}

// The rate function of timeDerivative_, bound once (binding a new closure per der() call cost a heap
// block each); the current call's location comes from derivativeSite_.
Expr Flattener::rateOf(Expr s) {
  if (const RelativeElement* rel = out_.relativeElement(s)) return rateOfRelative(*rel);
  int var = out_.variableOf(s);
  if (var < 0 || out_.variables[var].role == VarRole::Parameter) return ctx_.zero();
  if (out_.variables[var].role == VarRole::Time) return ctx_.one();
  return out_.variables[derivativeVariable(var, derivativeSite_)].symbol;
}

Value Flattener::lowerCall(const CallExpr& e) {
  std::string name = e.callee->dotted();
  auto arg = [&](size_t i) { return lower(*e.args.at(i)); };
  if (name == "der") {  // first: the call met most often (in the energies, once per element)
    Value v = arg(0);
    for (Expr& x : v.elems) x = timeDerivative(x, e.range);
    return v;
  }
  if (auto call = m_.calls.find(&e); call != m_.calls.end()) return lowerFunctionCall(call->second);
  if (std::optional<Kind> k = unaryMathKind(name)) return mapUnary(arg(0), *k);
  if (name == "sqrt" || name == "log10") {
    Value v = arg(0);
    for (Expr& x : v.elems)
      x = name == "sqrt" ? ctx_.pow(x, ctx_.constant(0.5))
                         : ctx_.div(ctx_.unary(Kind::Log, x), ctx_.constant(std::log(10.0)));
    return v;
  }
  if (name == "sum" || name == "product") return lowerReduction(e, name == "sum");
  if ((name == "min" || name == "max") && e.args.size() == 1) {
    Value v = arg(0);
    if (v.elems.empty()) fail(e.range, DiagCode::E0309, "'" + name + "' of an empty array");
    Expr r = v.elems[0];
    for (size_t i = 1; i < v.size(); ++i) r = ctx_.binary(name == "min" ? Kind::Min : Kind::Max, r, v.elems[i]);
    return Value::scalar(r);
  }
  if (name == "min" || name == "max" || name == "atan2") {
    Kind k = name == "min" ? Kind::Min : name == "max" ? Kind::Max : Kind::Atan2;
    Value a = arg(0), b = arg(1);
    if (a.shape != b.shape)
      fail(e.range, DiagCode::E0307, "'" + name + "' needs arguments of the same shape, got " + shapeText(a.shape) +
                                 " and " + shapeText(b.shape));
    for (size_t i = 0; i < a.size(); ++i) a.elems[i] = ctx_.binary(k, a.elems[i], b.elems[i]);
    return a;
  }
  return lowerArrayBuiltin(name, e);
}

// sum(e for i in r) / product(...) over a comprehension, or over the elements of an array.
Value Flattener::lowerReduction(const CallExpr& e, bool isSum) {
  std::vector<Value> parts;
  if (auto* c = dyn_cast<ComprehensionExpr>(e.args[0].get())) {
    forEachIteration(c->iterators, 0, [&] { parts.push_back(lower(*c->body)); });
  } else {
    Value v = lower(*e.args[0]);
    for (Expr x : v.elems) parts.push_back(Value::scalar(x));
  }
  if (parts.empty()) return Value::scalar(isSum ? ctx_.zero() : ctx_.one());
  Value r{parts[0].shape, ExprList(parts[0].size(), nullptr)};
  std::vector<Expr> column(parts.size());
  for (size_t k = 0; k < r.size(); ++k) {
    for (size_t i = 0; i < parts.size(); ++i) {
      if (parts[i].shape != r.shape)
        fail(e.range, DiagCode::E0307, "the terms of this reduction have different shapes");
      column[i] = parts[i].elems[k];
    }
    r.elems[k] = isSum ? ctx_.add(column) : ctx_.mul(column);
  }
  return r;
}

Value Flattener::lowerArrayBuiltin(const std::string& name, const CallExpr& e) {
  auto arg = [&](size_t i) { return lower(*e.args.at(i)); };
  auto dimsFrom = [&](size_t first) {
    std::vector<int> dims;
    for (size_t i = first; i < e.args.size(); ++i) {
      long n = lowerInteger(*e.args[i], "an array size");
      if (n < 0) fail(e.args[i]->range, DiagCode::E0303, "an array size cannot be negative");
      dims.push_back(static_cast<int>(n));
    }
    return dims;
  };
  auto filled = [&](std::vector<int> dims, Expr v) {
    size_t n = 1;
    for (int d : dims) n *= static_cast<size_t>(d);
    countScalars(n, e.range);
    return Value{std::move(dims), ExprList(n, v)};
  };
  if (name == "fill") return filled(dimsFrom(1), lowerScalar(*e.args[0], "the value of fill()"));
  if (name == "zeros") return filled(dimsFrom(0), ctx_.zero());
  if (name == "ones") return filled(dimsFrom(0), ctx_.one());
  if (name == "identity") {
    int n = static_cast<int>(lowerInteger(*e.args[0], "the size of identity()"));
    Value v = filled({n, n}, ctx_.zero());
    for (int i = 0; i < n; ++i) v.elems[i * n + i] = ctx_.one();
    return v;
  }
  if (name == "diagonal") {
    Value d = arg(0);
    if (d.shape.size() != 1) fail(e.args[0]->range, DiagCode::E0307, "diagonal() takes a vector");
    int n = d.shape[0];
    Value v = filled({n, n}, ctx_.zero());
    for (int i = 0; i < n; ++i) v.elems[i * n + i] = d.elems[i];
    return v;
  }
  if (name == "transpose") {
    Value m = arg(0);
    if (m.shape.size() != 2) fail(e.args[0]->range, DiagCode::E0307, "transpose() takes a matrix, got " + shapeText(m.shape));
    Value t{{m.shape[1], m.shape[0]}, ExprList(m.size(), nullptr)};
    for (int i = 0; i < m.shape[0]; ++i)
      for (int j = 0; j < m.shape[1]; ++j) t.elems[j * m.shape[0] + i] = m.elems[i * m.shape[1] + j];
    return t;
  }
  if (name == "cross" || name == "dot") {
    Value a = arg(0), b = arg(1);
    bool ok = a.shape.size() == 1 && a.shape == b.shape && (name == "dot" || a.shape[0] == 3);
    if (!ok)
      fail(e.range, DiagCode::E0307, name + "() needs two vectors of " + (name == "dot" ? "equal length" : "length 3") +
                                 ", got " + shapeText(a.shape) + " and " + shapeText(b.shape));
    if (name == "dot") {
      std::vector<Expr> t;
      for (size_t i = 0; i < a.size(); ++i) t.push_back(ctx_.mul(a.elems[i], b.elems[i]));
      return Value::scalar(ctx_.add(t));
    }
    auto c = [&](int i, int j) { return ctx_.sub(ctx_.mul(a.elems[i], b.elems[j]), ctx_.mul(a.elems[j], b.elems[i])); };
    return Value{{3}, {c(1, 2), c(2, 0), c(0, 1)}};
  }
  if (name == "eulerZXZ") return eulerZXZ(e);
  if (name == "size") {
    Value a = arg(0);
    if (e.args.size() == 2) {
      long d = lowerInteger(*e.args[1], "the dimension of size()");
      if (d < 1 || d > static_cast<long>(a.shape.size()))
        fail(e.args[1]->range, DiagCode::E0301, "dimension " + std::to_string(d) + " is out of range for " + shapeText(a.shape));
      return Value::scalar(ctx_.constant(a.shape[d - 1]));
    }
    Value v{{static_cast<int>(a.shape.size())}, {}};
    for (int d : a.shape) v.elems.push_back(ctx_.constant(d));
    return v;
  }
  fail(e.callee->range, DiagCode::E0210, "unknown function '" + name + "'");
}

// eulerZXZ(psi, theta, phi): the unit quaternion (scalar first) of the rotation Rz(psi) Rx(theta)
// Rz(phi), the textbook's Euler angles (precession, nutation, spin), for a body's q(start = …).
Value Flattener::eulerZXZ(const CallExpr& e) {
  Expr psi = lowerScalar(*e.args[0], "psi of eulerZXZ()"), theta = lowerScalar(*e.args[1], "theta of eulerZXZ()"),
       phi = lowerScalar(*e.args[2], "phi of eulerZXZ()");
  Expr half = ctx_.constant(0.5);
  Expr sum = ctx_.mul(half, ctx_.add(psi, phi)), diff = ctx_.mul(half, ctx_.sub(psi, phi)), t = ctx_.mul(half, theta);
  Expr ct = ctx_.unary(Kind::Cos, t), st = ctx_.unary(Kind::Sin, t);
  return Value{{4},
               {ctx_.mul(ct, ctx_.unary(Kind::Cos, sum)), ctx_.mul(st, ctx_.unary(Kind::Cos, diff)),
                ctx_.mul(st, ctx_.unary(Kind::Sin, diff)), ctx_.mul(ct, ctx_.unary(Kind::Sin, sum))}};
}

}  // namespace qdot::flat
