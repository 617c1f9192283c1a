// Lowers AST expressions to Values (arrays of symbolic expressions): names, subscripts, operators
// with Modelica's array rules, built-in functions, reductions, comprehensions, der().
// Error codes E03xx (see compiler/flatten/README.md).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "flatten/Flattener.h"
#include "support/Assert.h"

namespace qdot::flat {

using namespace qdot::ast;
using sym::Expr;
using sym::Kind;

std::string shapeText(const std::vector<int>& shape) {
  if (shape.empty()) return "a scalar";
  std::string s = "[";
  for (size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

void Flattener::fail(SourceRange r, DiagCode code, std::string msg, std::string help) {
  diags_.error(r, code, std::move(msg), std::move(help));
  throw FlattenAbort{};
}

Expr Flattener::lowerScalar(const ast::Expr& e, const char* what) {
  Value v = lower(e);
  if (!v.isScalar())
    fail(e.range, DiagCode::E0302, std::string(what) + " must be a scalar, but this is an array of shape " + shapeText(v.shape));
  return v.elems[0];
}

double Flattener::lowerConstant(const ast::Expr& e, const char* what) {
  Expr x = lowerScalar(e, what);
  if (!x->isConstant())
    fail(e.range, DiagCode::E0303, std::string(what) + " must be known at compile time",
         "use literals, constants and Integer parameters here");
  return x->value;
}

long Flattener::lowerInteger(const ast::Expr& e, const char* what) {
  return integerValue(lowerConstant(e, what), e.range, what);
}

// Checked before the conversion: a double outside the range of `long` does not convert.
long Flattener::integerValue(double v, SourceRange r, const char* what) {
  if (v != std::floor(v) || std::fabs(v) > 1e9)
    fail(r, DiagCode::E0303, std::string(what) + " must be an Integer, but it is " + sym::toString(ctx_, ctx_.constant(v)));
  return static_cast<long>(v);
}

Value Flattener::lower(const ast::Expr& e) {
  switch (e.kind) {
    case ExprKind::Number: return Value::scalar(ctx_.constant(cast<NumberExpr>(&e)->value));
    case ExprKind::Bool: return Value::scalar(cast<BoolExpr>(&e)->value ? ctx_.one() : ctx_.zero());
    case ExprKind::Name: return lowerName(*cast<NameExpr>(&e));
    case ExprKind::Index: return lowerIndex(*cast<IndexExpr>(&e));
    case ExprKind::Unary: return lowerUnary(*cast<UnaryExpr>(&e));
    case ExprKind::Binary: return lowerBinary(*cast<BinaryExpr>(&e));
    case ExprKind::Call: return lowerCall(*cast<CallExpr>(&e));
    case ExprKind::Range: return lowerRange(*cast<RangeExpr>(&e));
    case ExprKind::Array: return lowerArray(*cast<ArrayExpr>(&e));
    case ExprKind::Comprehension: return lowerComprehension(*cast<ComprehensionExpr>(&e));
    case ExprKind::If: return lowerIf(*cast<IfExpr>(&e));
    case ExprKind::End:
      // The parser makes `end` only inside a subscript, and sema rejects it in array sizes.
      if (endContext_.empty()) QDOT_UNREACHABLE("'end' outside a subscript reached flattening");
      return Value::scalar(ctx_.constant(endContext_.back().first->shape[endContext_.back().second]));
    case ExprKind::String: fail(e.range, DiagCode::E0213, "a string is not allowed here");
    case ExprKind::Member: return lowerMember(*cast<MemberExpr>(&e));
  }
  QDOT_UNREACHABLE("lower: every expression kind is handled in the switch");
}

Value Flattener::lowerName(const NameExpr& n) {
  if (n.parts.size() > 1) return frames_.empty() ? lowerDotted(n) : lowerFunctionName(n);
  const std::string& name = n.parts[0];
  for (size_t k = templateIterators_.size(); k-- > 0;)  // a template's iterator as a number (innermost first)
    if (const TemplateIterator& it = templateIterators_[k]; it.name == name)
      return Value::scalar(it.alias < 0 ? out_.patterns->iteratorSymbol(ctx_, static_cast<int>(k))
                                        : ctx_.add(out_.patterns->iteratorSymbol(ctx_, it.alias), ctx_.constant(static_cast<double>(it.shift))));
  for (auto it = iterators_.rbegin(); it != iterators_.rend(); ++it)
    if (it->first == name) return Value::scalar(it->second);
  if (!frames_.empty()) return lowerFunctionName(n);
  if (const sema::ModelSymbol* s = cur_->cls->find(name)) {
    if (s->kind == sema::SymbolKind::Component) fail(n.range, DiagCode::E0224, "'" + name + "' is a component, not a value");
    return valueOf(*cur_, *s, n.range);
  }
  if (name == "time") return Value::scalar(out_.time());
  if (name == "pi") return Value::scalar(ctx_.constant(std::numbers::pi));
  fail(n.range, DiagCode::E0202, "unknown name '" + name + "'");
}

// `end` inside subscript `dim` of `base` means the size of that dimension while this lives.
class Flattener::EndScope {
 public:
  EndScope(Flattener& f, const Value& base, size_t dim) : f_(f) {
    f_.endContext_.push_back({&base, static_cast<int>(dim)});
  }
  ~EndScope() { f_.endContext_.pop_back(); }
  EndScope(const EndScope&) = delete;
  EndScope& operator=(const EndScope&) = delete;

 private:
  Flattener& f_;
};

void Flattener::checkIndex(long i, int dimSize, const ast::Expr& s) {
  if (i < 1 || i > dimSize)
    fail(s.range, DiagCode::E0301, "index " + std::to_string(i) + " is out of range 1:" + std::to_string(dimSize),
         "array indices start at 1 and end at the size of the dimension");
}

// A subscript that is a single index (not a range).
int Flattener::subscriptIndex(const ast::Expr& s, int dimSize) {
  long i = lowerInteger(s, "a subscript");
  checkIndex(i, dimSize, s);
  return static_cast<int>(i);
}

std::vector<int> Flattener::subscriptIndices(const ast::Expr& s, int dimSize) {
  auto* r = dyn_cast<RangeExpr>(&s);
  if (!r) return {subscriptIndex(s, dimSize)};
  std::vector<int> idx;
  if (!r->start && !r->stop) {  // `:`
    for (int i = 1; i <= dimSize; ++i) idx.push_back(i);
    return idx;
  }
  for (Expr v : iterationValues(s)) {  // the values of a range need not be Integers: x[1.5:2.5]
    long i = integerValue(v->value, s.range, "a subscript");
    checkIndex(i, dimSize, s);
    idx.push_back(static_cast<int>(i));
  }
  return idx;
}

// The array being subscripted, without copying it when it is a declared name (x[i] in a loop
// over a large array must not copy x each time).
const Value& Flattener::subscriptBase(const ast::Expr& e, Value& holder) {
  if (auto* n = dyn_cast<NameExpr>(&e); n && n->parts.size() == 1 && frames_.empty()) {
    bool isIterator = false;
    for (const auto& it : iterators_) isIterator |= it.first == n->parts[0];
    const sema::ModelSymbol* s = cur_->cls->find(n->parts[0]);
    if (!isIterator && s && s->kind != sema::SymbolKind::Component) return valueOf(*cur_, *s, n->range);
  }
  holder = lower(e);
  return holder;
}

Value Flattener::lowerIndex(const IndexExpr& e) {
  if (!templateIterators_.empty())
    if (std::optional<Value> relative = lowerRelativeIndex(e)) return std::move(*relative);
  Value holder;
  const Value& base = subscriptBase(*e.base, holder);
  if (e.subscripts.size() != base.shape.size())
    fail(e.range, DiagCode::E0305,
         std::to_string(e.subscripts.size()) + " subscript(s) given for an array of shape " + shapeText(base.shape),
         base.shape.empty() ? "this is a scalar: remove the subscript" : "give one subscript per dimension");
  auto isRange = [](const ExprPtr& s) { return dyn_cast<RangeExpr>(s.get()) != nullptr; };
  if (std::none_of(e.subscripts.begin(), e.subscripts.end(), isRange))
    return Value::scalar(base.elems[elementOffset(e, base)]);
  std::vector<std::vector<int>> picks;
  Value result;
  for (size_t d = 0; d < e.subscripts.size(); ++d) {
    EndScope end(*this, base, d);
    picks.push_back(subscriptIndices(*e.subscripts[d], base.shape[d]));
    if (isRange(e.subscripts[d])) result.shape.push_back(static_cast<int>(picks.back().size()));
  }
  // An empty range (x[3:2], x[inf:1]) selects nothing.
  if (std::any_of(picks.begin(), picks.end(), [](const std::vector<int>& p) { return p.empty(); })) return result;
  // Enumerate the cartesian product of picks in row-major order.
  std::vector<size_t> pos(picks.size(), 0);
  while (true) {
    size_t flat = 0;
    for (size_t d = 0; d < picks.size(); ++d) flat = flat * base.shape[d] + (picks[d][pos[d]] - 1);
    result.elems.push_back(base.elems[flat]);
    size_t d = picks.size();
    while (d > 0 && ++pos[d - 1] == picks[d - 1].size()) pos[--d] = 0;
    if (d == 0) break;
  }
  return result;
}

// The row-major offset of x[i, j, ...] when every subscript is a single index, the common case in
// loops: computed directly, without the index lists of the general case.
size_t Flattener::elementOffset(const IndexExpr& e, const Value& base) {
  size_t flat = 0;
  for (size_t d = 0; d < e.subscripts.size(); ++d) {
    EndScope end(*this, base, d);
    flat = flat * base.shape[d] + (subscriptIndex(*e.subscripts[d], base.shape[d]) - 1);
  }
  return flat;
}

Value Flattener::mapUnary(const Value& v, Kind k) {
  Value r{v.shape, {}};
  r.elems.reserve(v.size());
  for (Expr x : v.elems) r.elems.push_back(ctx_.unary(k, x));
  return r;
}

Value Flattener::lowerUnary(const UnaryExpr& e) {
  Value v = lower(*e.operand);
  switch (e.op) {
    case UnaryOp::Plus: return v;
    case UnaryOp::Not: return mapUnary(v, Kind::Not);
    case UnaryOp::Neg:
      for (Expr& x : v.elems) x = ctx_.neg(x);
      return v;
  }
  return v;
}

Value Flattener::lowerBinary(const BinaryExpr& e) {
  Value a = lower(*e.lhs);
  Value b = lower(*e.rhs);
  switch (e.op) {
    case BinaryOp::Add: case BinaryOp::Sub: case BinaryOp::Div: case BinaryOp::Pow:
      return lowerArithmetic(e.op, std::move(a), std::move(b), e);
    case BinaryOp::Mul: return lowerProduct(std::move(a), std::move(b), e);
    default: break;
  }
  if (!a.isScalar() || !b.isScalar())
    fail(e.opRange, DiagCode::E0306, std::string("'") + spelling(e.op) + "' needs scalar operands, but got " +
                                 shapeText(a.shape) + " and " + shapeText(b.shape));
  Expr x = a.elems[0], y = b.elems[0];
  switch (e.op) {
    case BinaryOp::Lt: return Value::scalar(ctx_.binary(Kind::Lt, x, y));
    case BinaryOp::Le: return Value::scalar(ctx_.binary(Kind::Le, x, y));
    case BinaryOp::Gt: return Value::scalar(ctx_.binary(Kind::Lt, y, x));
    case BinaryOp::Ge: return Value::scalar(ctx_.binary(Kind::Le, y, x));
    case BinaryOp::Eq: return Value::scalar(ctx_.binary(Kind::Eq, x, y));
    case BinaryOp::Ne: return Value::scalar(ctx_.binary(Kind::Ne, x, y));
    case BinaryOp::And: return Value::scalar(ctx_.binary(Kind::And, x, y));
    case BinaryOp::Or: return Value::scalar(ctx_.binary(Kind::Or, x, y));
    default: break;
  }
  QDOT_UNREACHABLE("lowerBinary: every binary operator is handled in the switches");
}

// + and - need equal shapes; / needs a scalar divisor; ^ needs scalars (Modelica's rules).
Value Flattener::lowerArithmetic(BinaryOp op, Value a, Value b, const BinaryExpr& e) {
  std::string opText = spelling(op);
  if ((op == BinaryOp::Div || op == BinaryOp::Pow) && !b.isScalar())
    fail(e.rhs->range, DiagCode::E0306, "the right operand of '" + opText + "' must be a scalar, but it has shape " + shapeText(b.shape));
  if (op == BinaryOp::Pow && !a.isScalar())
    fail(e.lhs->range, DiagCode::E0306, "'^' of an array is not supported", "raise each element: {x[i]^2 for i in 1:n}");
  if ((op == BinaryOp::Add || op == BinaryOp::Sub) && a.shape != b.shape)
    fail(e.opRange, DiagCode::E0307, "shape mismatch: " + shapeText(a.shape) + " " + opText + " " + shapeText(b.shape),
         "both operands of '" + opText + "' must have the same shape");
  for (size_t i = 0; i < a.size(); ++i) {
    Expr y = b.isScalar() ? b.elems[0] : b.elems[i];
    switch (op) {
      case BinaryOp::Add: a.elems[i] = ctx_.add(a.elems[i], y); break;
      case BinaryOp::Sub: a.elems[i] = ctx_.sub(a.elems[i], y); break;
      case BinaryOp::Div: a.elems[i] = ctx_.div(a.elems[i], y); break;
      default: a.elems[i] = ctx_.pow(a.elems[i], y); break;
    }
  }
  return a;
}

// scalar*array, vector*vector (dot), matrix*vector, vector*matrix, matrix*matrix.
Value Flattener::lowerProduct(Value a, Value b, const BinaryExpr& e) {
  if (a.isScalar() || b.isScalar()) {
    Value& arr = a.isScalar() ? b : a;
    Expr s = a.isScalar() ? a.elems[0] : b.elems[0];
    for (Expr& x : arr.elems) x = ctx_.mul(x, s);
    return arr;
  }
  auto rows = [](const Value& v) { return v.shape.size() == 1 ? 1 : v.shape[0]; };
  int inner = a.shape.back();
  int innerB = b.shape[0];
  if (a.shape.size() > 2 || b.shape.size() > 2 || inner != innerB)
    fail(e.opRange, DiagCode::E0307, "cannot multiply " + shapeText(a.shape) + " by " + shapeText(b.shape),
         "inner dimensions must agree (matrix*vector, vector*vector, matrix*matrix)");
  int n = a.shape.size() == 2 ? rows(a) : 1;
  int p = b.shape.size() == 2 ? b.shape[1] : 1;
  Value r;
  if (a.shape.size() == 2) r.shape.push_back(n);
  if (b.shape.size() == 2) r.shape.push_back(p);
  std::vector<Expr> terms(inner);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < p; ++j) {
      for (int k = 0; k < inner; ++k) terms[k] = ctx_.mul(a.elems[i * inner + k], b.elems[k * p + j]);
      r.elems.push_back(ctx_.add(terms));
    }
  return r;
}

Value Flattener::lowerRange(const RangeExpr& e) {
  Value v;
  v.elems = ExprList(iterationValues(e));
  v.shape = {static_cast<int>(v.elems.size())};
  return v;
}

std::vector<Expr> Flattener::iterationValues(const ast::Expr& range) {
  auto* r = dyn_cast<RangeExpr>(&range);
  if (!r) {
    Value v = lower(range);
    if (v.shape.size() != 1) fail(range.range, DiagCode::E0308, "a loop range must be a vector, e.g. 1:n");
    return {v.elems.begin(), v.elems.end()};
  }
  RangeBounds b = rangeBounds(*r);
  std::vector<Expr> out;
  out.reserve(b.count);
  ctx_.reserve(0, b.count);  // a large range's constants: the intern table grows once
  for (long i = 0; i < static_cast<long>(b.count); ++i) out.push_back(ctx_.constant(b.first + i * b.step));
  return out;
}

Flattener::RangeBounds Flattener::rangeBounds(const RangeExpr& r) {
  if (!r.start || !r.stop) fail(r.range, DiagCode::E0308, "a loop range needs a start and a stop, e.g. 1:n");
  double a = lowerConstant(*r.start, "a range bound");
  double step = r.step ? lowerConstant(*r.step, "a range step") : 1.0;
  double b = lowerConstant(*r.stop, "a range bound");
  if (step == 0) fail(r.step->range, DiagCode::E0308, "a range step cannot be 0");
  double count = std::floor((b - a) / step + 1e-9) + 1;
  if (!(count > 0)) return {a, step, 0};
  // Clamped to one past the limit, which countScalars refuses (E0310): a count like 1e300 does
  // not convert to size_t.
  countScalars(static_cast<size_t>(std::min(count, static_cast<double>(limits_.maxScalars) + 1)), r.range);
  return {a, step, static_cast<size_t>(count)};
}

namespace {

// What a symbolic constant holds: −0 is 0 and every NaN one NaN (sym::Context::constant).
double asConstant(double v) { return v == 0.0 ? 0.0 : std::isnan(v) ? std::numeric_limits<double>::quiet_NaN() : v; }

// A comprehension body compiled once into post-order steps over a stack of numbers, then run per
// element: numbers, the comprehension's own iterators, names that lower to a number (a constant, an
// Integer parameter such as n), + − · / ^, a sign, and the built-in functions of one number (sin,
// sqrt, …) — e.g. the start values {0.01*i for i in 1:n} or {sin(pi*i/(n + 1)) for i in 1:n}.
struct NumericStep {
  enum Op : uint8_t { Number, Iterator, Neg, Add, Sub, Mul, Div, Pow, Function } op;
  sym::Kind function = sym::Kind::Sin;  ///< Function
  size_t iterator = 0;                  ///< Iterator: its position among the comprehension's
  double value = 0;                     ///< Number
};

// The steps of e, or false where e is not of that form. `numberOf(name)` lowers a name that is
// not an iterator (nullopt: not one number); `userFunction(call)`: a call of the model's own.
template <class NumberOf, class UserFunction>
bool compileNumeric(const ast::Expr& e, const std::vector<Iterator>& iterators, std::vector<NumericStep>& out,
                    NumberOf&& numberOf, UserFunction&& userFunction) {
  auto operand = [&](const ast::Expr& x) { return compileNumeric(x, iterators, out, numberOf, userFunction); };
  switch (e.kind) {
    case ExprKind::Number: out.push_back({NumericStep::Number, {}, 0, asConstant(cast<NumberExpr>(&e)->value)}); return true;
    case ExprKind::Name: {
      auto& parts = cast<NameExpr>(&e)->parts;
      for (size_t k = iterators.size(); parts.size() == 1 && k-- > 0;)  // the innermost of a name wins
        if (iterators[k].name == parts[0]) return out.push_back({NumericStep::Iterator, {}, k, 0}), true;
      std::optional<double> v = numberOf(e);
      if (v) out.push_back({NumericStep::Number, {}, 0, *v});
      return v.has_value();
    }
    case ExprKind::Unary: {
      auto* u = cast<UnaryExpr>(&e);
      if (u->op == UnaryOp::Not || !operand(*u->operand)) return false;
      if (u->op == UnaryOp::Neg) out.push_back({NumericStep::Neg});
      return true;
    }
    case ExprKind::Binary: {
      auto* b = cast<BinaryExpr>(&e);
      NumericStep::Op op = b->op == BinaryOp::Add   ? NumericStep::Add
                           : b->op == BinaryOp::Sub ? NumericStep::Sub
                           : b->op == BinaryOp::Mul ? NumericStep::Mul
                           : b->op == BinaryOp::Div ? NumericStep::Div
                           : b->op == BinaryOp::Pow ? NumericStep::Pow
                                                    : NumericStep::Number;
      if (op == NumericStep::Number || !operand(*b->lhs) || !operand(*b->rhs)) return false;
      out.push_back({op});
      return true;
    }
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(&e);
      if (c->args.size() != 1 || !c->namedArgs.empty() || userFunction(*c)) return false;
      std::string name = c->callee->dotted();
      std::optional<sym::Kind> f = unaryMathKind(name);
      if (!f && name != "sqrt" && name != "log10") return false;
      if (!operand(*c->args[0])) return false;
      if (f) out.push_back({NumericStep::Function, *f});
      else if (name == "sqrt") out.push_back({NumericStep::Number, {}, 0, 0.5}), out.push_back({NumericStep::Pow});
      else out.push_back({NumericStep::Function, sym::Kind::Log}), out.push_back({NumericStep::Number, {}, 0, std::log(10.0)}),
           out.push_back({NumericStep::Div});
      return true;
    }
    default: return false;
  }
}

// The steps at iterator values `at` (by position), folded exactly as the symbolic constructors
// fold constants (symbolic/Arith.cpp, Functions.cpp): a + b, a − b (0 if the same constant), a·b,
// a·(1/b), powValue and unaryValue, each intermediate a constant; sqrt is x^0.5 and log10(x)
// log(x)/log(10), as Builtins.cpp lowers them.
double runNumeric(const std::vector<NumericStep>& steps, const std::vector<double>& at, std::vector<double>& stack) {
  stack.clear();
  auto same = [](double p, double q) { return p == q || (std::isnan(p) && std::isnan(q)); };
  for (const NumericStep& s : steps) {
    if (s.op == NumericStep::Number || s.op == NumericStep::Iterator) {
      stack.push_back(s.op == NumericStep::Number ? s.value : at[s.iterator]);
      continue;
    }
    if (s.op == NumericStep::Neg || s.op == NumericStep::Function) {
      double& v = stack.back();
      v = s.op == NumericStep::Neg ? asConstant(-1.0 * v) : asConstant(sym::unaryValue(s.function, v));
      continue;
    }
    double y = stack.back();
    stack.pop_back();
    double& x = stack.back();
    switch (s.op) {
      case NumericStep::Add: x = x == 0 ? y : y == 0 ? x : asConstant(x + y); break;
      case NumericStep::Sub: x = y == 0 ? x : same(x, y) ? 0.0 : asConstant(x - y); break;
      case NumericStep::Mul: x = x == 1 ? y : y == 1 ? x : asConstant(x * y); break;
      case NumericStep::Div: x = y == 1 ? x : asConstant(x * asConstant(1.0 / y)); break;
      default: x = asConstant(sym::powValue(x, y)); break;
    }
  }
  return stack.back();
}

}  // namespace

// The elements of a numeric comprehension (isNumericBody over ranges) as constants, without a
// symbolic constant per iterator value and per intermediate result: the start values of a
// 10⁶-element array made 2·10⁶ constants, most of the time of flattening it. The same values as
// lowering the body per element (foldNumeric), the same checks and counts; nullopt otherwise.
std::optional<Value> Flattener::numericComprehension(const ComprehensionExpr& e) {
  for (const auto& it : e.iterators)
    if (!dyn_cast<RangeExpr>(it.range.get())) return std::nullopt;
  // a name that is not an iterator is lowered once, as lowering the body per element would
  auto numberOf = [&](const ast::Expr& name) -> std::optional<double> {
    Value v = lower(name);
    if (!v.shape.empty() || v.elems.size() != 1 || !v.elems[0]->isConstant()) return std::nullopt;
    return v.elems[0]->value;
  };
  auto userFunction = [&](const CallExpr& c) { return m_.calls.count(&c) != 0; };
  std::vector<NumericStep> steps;
  if (!compileNumeric(*e.body, e.iterators, steps, numberOf, userFunction)) return std::nullopt;
  std::vector<RangeBounds> ranges;
  Value v;
  size_t count = 1;
  for (const auto& it : e.iterators) {
    ranges.push_back(rangeBounds(*cast<RangeExpr>(it.range.get())));
    v.shape.push_back(static_cast<int>(ranges.back().count));
    count *= ranges.back().count;
  }
  std::vector<double> values;
  values.reserve(count);
  std::vector<double> at(ranges.size()), stack;
  auto walk = [&](auto& self, size_t k) -> void {
    if (k == ranges.size()) return values.push_back(runNumeric(steps, at, stack));
    countScalars(ranges[k].count, e.iterators[k].range->range);  // as for a loop
    for (size_t i = 0; i < ranges[k].count; ++i) {
      at[k] = asConstant(ranges[k].first + static_cast<long>(i) * ranges[k].step);
      self(self, k + 1);
    }
  };
  walk(walk, 0);
  v.elems = ExprList(ctx_.constants(values));
  return v;
}

Value Flattener::stack(std::vector<Value> parts, SourceRange r) {
  Value v;
  v.shape.push_back(static_cast<int>(parts.size()));
  if (parts.empty()) return v;
  for (size_t i = 1; i < parts.size(); ++i)
    if (parts[i].shape != parts[0].shape)
      fail(r, DiagCode::E0307, "array elements have different shapes: " + shapeText(parts[0].shape) + " and " +
                           shapeText(parts[i].shape));
  v.shape.insert(v.shape.end(), parts[0].shape.begin(), parts[0].shape.end());
  for (auto& p : parts) v.elems.append(p.elems);
  return v;
}

Value Flattener::lowerArray(const ArrayExpr& e) {
  std::vector<Value> parts;
  for (const auto& el : e.elements) parts.push_back(lower(*el));
  return stack(std::move(parts), e.range);
}

// {body for i in r1, j in r2}: the first iterator is the first dimension. Each range is lowered
// once and the elements go straight into one list: a comprehension over a large array (the start
// values of x[n]) makes no Value per element. Checked as stack() checks array literals.
Value Flattener::lowerComprehension(const ComprehensionExpr& e) {
  if (std::optional<Value> numbers = numericComprehension(e)) return std::move(*numbers);
  std::vector<std::vector<Expr>> ranges;
  Value v;
  size_t count = 1;
  for (const auto& it : e.iterators) {
    ranges.push_back(iterationValues(*it.range));
    v.shape.push_back(static_cast<int>(ranges.back().size()));
    count *= ranges.back().size();
  }
  std::optional<std::vector<int>> elementShape, otherShape;
  auto element = [&] {
    Value part = lower(*e.body);
    if (!elementShape) {
      elementShape = part.shape;
      v.elems.reserve(count * part.size());
    } else if (!otherShape && part.shape != *elementShape) {
      otherShape = part.shape;
    }
    v.elems.append(part.elems);
  };
  auto walk = [&](auto& self, size_t k) -> void {
    if (k == ranges.size()) return element();
    const Iterator& it = e.iterators[k];
    if (dyn_cast<RangeExpr>(it.range.get())) countScalars(ranges[k].size(), it.range->range);  // as for a loop
    for (Expr value : ranges[k]) {
      iterators_.emplace_back(it.name, value);
      try {
        self(self, k + 1);
      } catch (...) {
        iterators_.pop_back();
        throw;
      }
      iterators_.pop_back();
    }
  };
  walk(walk, 0);
  if (otherShape)
    fail(e.range, DiagCode::E0307, "array elements have different shapes: " + shapeText(*elementShape) + " and " +
                                  shapeText(*otherShape));
  if (elementShape) v.shape.insert(v.shape.end(), elementShape->begin(), elementShape->end());
  return v;
}

Value Flattener::lowerIf(const IfExpr& e) {
  std::vector<Expr> conds;
  for (const auto& c : e.conditions) conds.push_back(lowerScalar(*c, "an if-condition"));
  // Branches known at compile time (Integer parameters) select without evaluating the others.
  for (size_t i = 0; i < conds.size(); ++i) {
    if (!conds[i]->isConstant()) break;
    if (conds[i]->value != 0) return lower(*e.values[i]);
    if (i + 1 == conds.size()) return lower(*e.elseValue);
  }
  Value result = lower(*e.elseValue);
  for (size_t i = conds.size(); i-- > 0;) {
    Value branch = lower(*e.values[i]);
    if (branch.shape != result.shape)
      fail(e.values[i]->range, DiagCode::E0307, "the branches of this if-expression have different shapes: " +
                                            shapeText(branch.shape) + " and " + shapeText(result.shape));
    for (size_t k = 0; k < result.size(); ++k)
      result.elems[k] = ctx_.select(conds[i], branch.elems[k], result.elems[k]);
  }
  return result;
}

}  // namespace qdot::flat
