// Random expression trees for the property tests, with an evaluator that is independent of qdot:
// a tree is generated over every function kind (arguments wrapped so domains stay valid: log and
// fractional powers of u^2+1 or exp(sin u), asin/acos of 0.9*tanh(u), tan of tanh(u)), converted to
// a qdot Expr through the public Context API, and evaluated here by plain recursion on the tree.
// The evaluator also records which branch every non-smooth site took, so callers can skip points
// where a finite-difference stencil would straddle a kink.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "symbolic/Expr.h"

namespace qdot::sym::testing {

enum class Op {
  Const, Var, Add, Sub, Mul, Div, Neg, Scale, PowInt, PowReal, PowGen, Sqrt,
  Sin, Cos, Tan, Asin, Acos, Atan, Sinh, Cosh, Tanh, Exp, Log, Abs, Sign,
  Atan2, Min, Max, Lt, Le, Eq, Ne, And, Or, Not, Select, Count
};

struct Tree {
  Op op = Op::Const;
  double c = 0;  // Const value, Scale factor, PowInt/PowReal exponent
  int var = 0;
  std::vector<std::shared_ptr<Tree>> kids;
};
using TreePtr = std::shared_ptr<Tree>;

/// Result of the reference evaluation: value, the largest magnitude of any intermediate value (for
/// round-off tolerances) and the branch taken at every non-smooth site in tree order.
struct RefEval {
  double value = 0;
  double maxAbs = 0;
  std::vector<int> branches;
  bool signedZeroSensitive = false;  ///< atan2 evaluated on its cut with a zero y (sign of 0 matters)
};

class TreeGen {
 public:
  explicit TreeGen(uint64_t seed, int numVars = 3) : rng_(seed), numVars_(numVars) {}

  TreePtr gen(int depth) {
    if (depth == 0 || uni() < 0.15) return leaf();
    Op op = static_cast<Op>(2 + pick(static_cast<int>(Op::Count) - 2));
    auto t = std::make_shared<Tree>();
    t->op = op;
    auto sub = [&] { return gen(depth - 1); };
    switch (op) {
      case Op::Add: case Op::Sub: case Op::Mul: case Op::Atan2: case Op::Min: case Op::Max:
      case Op::Lt: case Op::Le: case Op::Eq: case Op::Ne:
        t->kids = {sub(), uni() < 0.25 ? shared() : sub()};
        break;
      case Op::Div: t->kids = {sub(), positive(sub())}; break;
      case Op::Neg: case Op::Sin: case Op::Cos: case Op::Atan: case Op::Sinh: case Op::Cosh:
      case Op::Tanh: case Op::Exp: case Op::Abs: case Op::Sign:
        t->kids = {sub()};
        break;
      case Op::Scale: t->c = constant(); t->kids = {sub()}; break;
      case Op::PowInt: {
        static const double exps[] = {2, 3, -1, -2};
        t->c = exps[pick(4)];
        t->kids = {t->c < 0 ? positive(sub()) : sub()};
        break;
      }
      case Op::PowReal: {
        static const double exps[] = {0.5, 1.5, -0.5, 0.3};
        t->c = exps[pick(4)];
        t->kids = {positive(sub())};
        break;
      }
      case Op::PowGen: t->kids = {positive(sub()), make(Op::Sin, {sub()})}; break;
      case Op::Sqrt: case Op::Log: t->kids = {positive(sub())}; break;
      case Op::Tan: t->kids = {make(Op::Tanh, {sub()})}; break;
      case Op::Asin: case Op::Acos: {
        auto s = make(Op::Scale, {make(Op::Tanh, {sub()})});
        s->c = 0.9;
        t->kids = {s};
        break;
      }
      case Op::And: case Op::Or:
        t->kids = {make(Op::Lt, {sub(), sub()}), make(Op::Le, {sub(), sub()})};
        break;
      case Op::Not: t->kids = {make(Op::Lt, {sub(), sub()})}; break;
      case Op::Select: t->kids = {make(Op::Lt, {sub(), sub()}), sub(), sub()}; break;
      case Op::Const: case Op::Var: case Op::Count: break;
    }
    last_ = t;
    return t;
  }

  double uni() { return std::uniform_real_distribution<double>(0, 1)(rng_); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  double point() { return std::uniform_real_distribution<double>(-2, 2)(rng_); }

 private:
  static TreePtr make(Op op, std::vector<TreePtr> kids) {
    auto t = std::make_shared<Tree>();
    t->op = op;
    t->kids = std::move(kids);
    return t;
  }
  TreePtr leaf() {
    auto t = std::make_shared<Tree>();
    if (uni() < 0.75) {
      t->op = Op::Var;
      t->var = pick(numVars_);
    } else {
      t->c = constant();
    }
    return t;
  }
  double constant() {
    static const double nice[] = {-2, -1, 0, 0.5, 1, 2, 3};
    return uni() < 0.6 ? nice[pick(7)] : std::uniform_real_distribution<double>(-3, 3)(rng_);
  }
  // u^2 + 1 or exp(sin(u)): positive and well away from zero.
  TreePtr positive(TreePtr u) {
    if (uni() < 0.5) return make(Op::Exp, {make(Op::Sin, {u})});
    auto one = std::make_shared<Tree>();
    one->c = 1;
    return make(Op::Add, {make(Op::Mul, {u, u}), one});
  }
  // a recently generated subtree, to create sharing and cancellation (x - x, x*x, ...)
  TreePtr shared() { return last_ ? last_ : leaf(); }

  std::mt19937_64 rng_;
  int numVars_;
  TreePtr last_;
};

/// Builds the qdot expression of a tree with the public API only.
inline Expr toExpr(Context& ctx, const Tree& t, const std::vector<Expr>& vars) {
  auto k = [&](size_t i) { return toExpr(ctx, *t.kids[i], vars); };
  switch (t.op) {
    case Op::Const: return ctx.constant(t.c);
    case Op::Var: return vars[t.var];
    case Op::Add: return ctx.add(k(0), k(1));
    case Op::Sub: return ctx.sub(k(0), k(1));
    case Op::Mul: return ctx.mul(k(0), k(1));
    case Op::Div: return ctx.div(k(0), k(1));
    case Op::Neg: return ctx.neg(k(0));
    case Op::Scale: return ctx.scale(t.c, k(0));
    case Op::PowInt: case Op::PowReal: return ctx.pow(k(0), ctx.constant(t.c));
    case Op::PowGen: return ctx.pow(k(0), k(1));
    case Op::Sqrt: return ctx.pow(k(0), ctx.constant(0.5));
    case Op::Sin: return ctx.unary(Kind::Sin, k(0));
    case Op::Cos: return ctx.unary(Kind::Cos, k(0));
    case Op::Tan: return ctx.unary(Kind::Tan, k(0));
    case Op::Asin: return ctx.unary(Kind::Asin, k(0));
    case Op::Acos: return ctx.unary(Kind::Acos, k(0));
    case Op::Atan: return ctx.unary(Kind::Atan, k(0));
    case Op::Sinh: return ctx.unary(Kind::Sinh, k(0));
    case Op::Cosh: return ctx.unary(Kind::Cosh, k(0));
    case Op::Tanh: return ctx.unary(Kind::Tanh, k(0));
    case Op::Exp: return ctx.unary(Kind::Exp, k(0));
    case Op::Log: return ctx.unary(Kind::Log, k(0));
    case Op::Abs: return ctx.unary(Kind::Abs, k(0));
    case Op::Sign: return ctx.unary(Kind::Sign, k(0));
    case Op::Atan2: return ctx.binary(Kind::Atan2, k(0), k(1));
    case Op::Min: return ctx.binary(Kind::Min, k(0), k(1));
    case Op::Max: return ctx.binary(Kind::Max, k(0), k(1));
    case Op::Lt: return ctx.binary(Kind::Lt, k(0), k(1));
    case Op::Le: return ctx.binary(Kind::Le, k(0), k(1));
    case Op::Eq: return ctx.binary(Kind::Eq, k(0), k(1));
    case Op::Ne: return ctx.binary(Kind::Ne, k(0), k(1));
    case Op::And: return ctx.binary(Kind::And, k(0), k(1));
    case Op::Or: return ctx.binary(Kind::Or, k(0), k(1));
    case Op::Not: return ctx.unary(Kind::Not, k(0));
    case Op::Select: return ctx.select(k(0), k(1), k(2));
    case Op::Count: break;
  }
  return nullptr;
}

/// Text of a tree (for failure messages): op(kids...).
inline std::string treeString(const Tree& t) {
  static const char* names[] = {"const", "var", "add", "sub", "mul", "div", "neg", "scale", "powi", "powr",
                                "powg", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh",
                                "tanh", "exp", "log", "abs", "sign", "atan2", "min", "max", "lt", "le", "eq",
                                "ne", "and", "or", "not", "select"};
  if (t.op == Op::Const) return std::to_string(t.c);
  if (t.op == Op::Var) return std::string(1, char('x' + t.var));
  std::string s = names[static_cast<int>(t.op)];
  s += "(";
  if (t.op == Op::Scale || t.op == Op::PowInt || t.op == Op::PowReal) s += std::to_string(t.c) + "; ";
  for (size_t i = 0; i < t.kids.size(); ++i) s += (i ? ", " : "") + treeString(*t.kids[i]);
  return s + ")";
}

/// Plain recursive evaluation of the tree (the reference).
inline double refEval(const Tree& t, const std::vector<double>& x, RefEval& r) {
  auto k = [&](size_t i) { return refEval(*t.kids[i], x, r); };
  auto branch = [&](int b) { r.branches.push_back(b); };
  double v = 0;
  switch (t.op) {
    case Op::Const: v = t.c; break;
    case Op::Var: v = x[t.var]; break;
    case Op::Add: v = k(0) + k(1); break;
    case Op::Sub: v = k(0) - k(1); break;
    case Op::Mul: v = k(0) * k(1); break;
    case Op::Div: v = k(0) / k(1); break;
    case Op::Neg: v = -k(0); break;
    case Op::Scale: v = t.c * k(0); break;
    case Op::PowInt: case Op::PowReal: v = std::pow(k(0), t.c); break;
    case Op::PowGen: v = std::pow(k(0), k(1)); break;
    case Op::Sqrt: v = std::sqrt(k(0)); break;
    case Op::Sin: v = std::sin(k(0)); break;
    case Op::Cos: v = std::cos(k(0)); break;
    case Op::Tan: v = std::tan(k(0)); break;
    case Op::Asin: v = std::asin(k(0)); break;
    case Op::Acos: v = std::acos(k(0)); break;
    case Op::Atan: v = std::atan(k(0)); break;
    case Op::Sinh: v = std::sinh(k(0)); break;
    case Op::Cosh: v = std::cosh(k(0)); break;
    case Op::Tanh: v = std::tanh(k(0)); break;
    case Op::Exp: v = std::exp(k(0)); break;
    case Op::Log: v = std::log(k(0)); break;
    case Op::Abs: { double a = k(0); branch(a < 0); v = std::fabs(a); break; }
    case Op::Sign: { double a = k(0); branch(a < 0 ? -1 : a > 0); v = a < 0 ? -1 : (a > 0 ? 1 : 0); break; }
    case Op::Atan2: {
      double a = k(0), b = k(1);
      branch(b < 0 ? (a < 0 ? 2 : 1) : 0);  // the branch cut is y = 0, x < 0
      if (a == 0 && b <= 0) r.signedZeroSensitive = true;
      v = std::atan2(a, b);
      break;
    }
    case Op::Min: { double a = k(0), b = k(1); branch(a < b); v = a < b ? a : b; break; }
    case Op::Max: { double a = k(0), b = k(1); branch(a < b); v = a < b ? b : a; break; }
    case Op::Lt: { double a = k(0), b = k(1); branch(a < b); v = a < b; break; }
    case Op::Le: { double a = k(0), b = k(1); branch(a <= b); v = a <= b; break; }
    case Op::Eq: { double a = k(0), b = k(1); branch(a == b); v = a == b; break; }
    case Op::Ne: { double a = k(0), b = k(1); branch(a != b); v = a != b; break; }
    case Op::And: { double a = k(0), b = k(1); v = (a != 0 && b != 0); break; }
    case Op::Or: { double a = k(0), b = k(1); v = (a != 0 || b != 0); break; }
    case Op::Not: v = k(0) == 0; break;
    case Op::Select: {
      double c = k(0), a = k(1), b = k(2);
      v = c != 0 ? a : b;
      break;
    }
    case Op::Count: break;
  }
  r.maxAbs = std::max(r.maxAbs, std::fabs(v));
  return v;
}

inline RefEval refEval(const Tree& t, const std::vector<double>& x) {
  RefEval r;
  r.value = refEval(t, x, r);
  return r;
}

}  // namespace qdot::sym::testing
