// Flattener internals shared by Flatten.cpp (declarations and statements) and ExprLowering.cpp
// (AST expressions to arrays of symbolic expressions). Not part of the stage's interface.
#pragma once

#include <functional>
#include <initializer_list>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "flatten/Flatten.h"

namespace qdot::flat {

/// The elements of a Value. Expanding a loop lowers its body once per iteration, and almost every
/// value met there is a scalar: keeping a single element inline spares a heap block per scalar
/// (those blocks were most of flattening's allocations). More elements live in a std::vector.
class ExprList {
 public:
  ExprList() = default;
  ExprList(std::initializer_list<sym::Expr> init) {
    for (sym::Expr e : init) push_back(e);
  }
  ExprList(size_t n, sym::Expr fill) : size_(n) {
    if (n == 1) one_ = fill;
    if (n > 1) many_.assign(n, fill);
  }
  explicit ExprList(std::vector<sym::Expr> v) : size_(v.size()) {
    if (size_ == 1) one_ = v[0];
    if (size_ > 1) many_ = std::move(v);
  }
  ExprList(const ExprList&) = default;
  ExprList& operator=(const ExprList&) = default;
  ExprList(ExprList&& o) noexcept : many_(std::move(o.many_)), one_(o.one_), size_(std::exchange(o.size_, 0)) {}
  ExprList& operator=(ExprList&& o) noexcept {
    many_ = std::move(o.many_);
    one_ = o.one_;
    size_ = std::exchange(o.size_, 0);
    return *this;
  }

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  sym::Expr* begin() { return size_ > 1 ? many_.data() : &one_; }
  sym::Expr* end() { return begin() + size_; }
  const sym::Expr* begin() const { return size_ > 1 ? many_.data() : &one_; }
  const sym::Expr* end() const { return begin() + size_; }
  sym::Expr& operator[](size_t i) { return begin()[i]; }
  sym::Expr operator[](size_t i) const { return begin()[i]; }

  void reserve(size_t n) {
    if (n > 1) many_.reserve(n);
  }
  void push_back(sym::Expr e) {
    if (size_ == 0) one_ = e;
    if (size_ == 1) many_.assign({one_, e});  // the inline element moves to the heap
    if (size_ > 1) many_.push_back(e);
    ++size_;
  }
  void append(const ExprList& more) {
    for (sym::Expr e : more) push_back(e);  // geometric growth: stack() appends one part at a time
  }

 private:
  std::vector<sym::Expr> many_;  ///< the elements when there are two or more
  sym::Expr one_ = nullptr;      ///< the element when there is at most one
  size_t size_ = 0;
};

/// An array of symbolic expressions in row-major order; a scalar has an empty shape.
struct Value {
  std::vector<int> shape;
  ExprList elems;

  static Value scalar(sym::Expr e) { return {{}, {e}}; }
  bool isScalar() const { return shape.empty(); }
  size_t size() const { return elems.size(); }
};

std::string shapeText(const std::vector<int>& shape);

/// Thrown after an error has been reported, to abandon the current statement and go on with the next.
struct FlattenAbort {};

/// Thrown while lowering a declaration that uses `decl`, not yet resolved: resolve that one first.
struct NeedFirst {
  const ast::Declaration* decl;
};

class Flattener {
 public:
  Flattener(const sema::CheckedModel& m, sym::Context& ctx, DiagnosticEngine& diags, FlattenLimits limits,
            StructuralValues structural = {});
  std::optional<FlatModel> run();

  // --- expression lowering (ExprLowering.cpp) ---
  Value lower(const ast::Expr& e);
  sym::Expr lowerScalar(const ast::Expr& e, const char* what);
  long lowerInteger(const ast::Expr& e, const char* what);
  double lowerConstant(const ast::Expr& e, const char* what);
  long integerValue(double v, SourceRange r, const char* what);
  std::vector<sym::Expr> iterationValues(const ast::Expr& range);
  sym::Expr timeDerivative(sym::Expr e, SourceRange where);
  sym::Expr rateOf(sym::Expr symbol);

  [[noreturn]] void fail(SourceRange r, DiagCode code, std::string msg, std::string help = {});

 private:
  const sema::CheckedModel& m_;
  sym::Context& ctx_;
  DiagnosticEngine& diags_;
  FlattenLimits limits_;
  StructuralValues structural_;
  FlatModel out_;
  size_t scalars_ = 0;
  sym::DirectionalDerivative timeDerivative_{ctx_};  ///< der(): memo shared by all calls
  SourceRange derivativeSite_;                       ///< the der() being expanded (for E0311)

  std::unordered_map<const ast::Declaration*, Value> declValues_;
  std::unordered_map<const ast::Declaration*, Value> declVariables_;  ///< a declaration's variables, made once
  std::vector<const ast::Declaration*> pending_;  ///< declarations waiting for one another, innermost last
  std::unordered_set<const ast::Declaration*> inProgress_;  ///< the same, to find a cycle quickly
  std::unordered_set<const ast::Declaration*> failed_;  ///< already reported; later uses abort quietly
  std::vector<std::pair<std::string, sym::Expr>> iterators_;  ///< innermost last
  std::vector<std::pair<const Value*, int>> endContext_;      ///< (array, dimension) being subscripted, for `end`

  // Flatten.cpp
  const Value& valueOf(const ast::Declaration& d, SourceRange use);
  void resolveInnermost();
  Value createDeclaration(const ast::Declaration& d, const sema::ModelSymbol& s);
  std::vector<int> evaluateDims(const ast::Declaration& d);
  Value variablesFor(const ast::Declaration& d, const std::vector<int>& shape, VarRole role);
  void applyAttributes(const ast::Declaration& d, const Value& vars);
  Value bindingValue(const ast::Declaration& d, const std::vector<int>& shape);
  int addVariable(Variable v);
  void reserveVariables(size_t count);
  int derivativeVariable(int var, SourceRange where);
  void checkShape(const Value& v, const std::vector<int>& shape, SourceRange r, const std::string& what);
  void countScalars(size_t n, SourceRange r);
  void lowerEquation(const ast::Equation& eq, std::vector<Equation>& into, OriginKind kind);
  void lowerMechanics(const ast::MechanicsStmt& st);
  void addTerms(std::vector<Term>& into, const ast::MechanicsStmt& st);
  void lowerForce(const ast::MechanicsStmt& st);
  void lowerExperiment();
  void forEachIteration(const std::vector<ast::Iterator>& its, size_t k, const std::function<void()>& body);
  template <class F> void guarded(F&& body);

  // ExprLowering.cpp
  Value lowerName(const ast::NameExpr& n);
  Value lowerIndex(const ast::IndexExpr& e);
  const Value& subscriptBase(const ast::Expr& e, Value& holder);
  Value lowerUnary(const ast::UnaryExpr& e);
  Value lowerBinary(const ast::BinaryExpr& e);
  Value lowerArithmetic(ast::BinaryOp op, Value a, Value b, const ast::BinaryExpr& e);
  Value lowerProduct(Value a, Value b, const ast::BinaryExpr& e);
  Value lowerCall(const ast::CallExpr& e);
  Value lowerReduction(const ast::CallExpr& e, bool isSum);
  Value lowerArrayBuiltin(const std::string& name, const ast::CallExpr& e);
  Value lowerArray(const ast::ArrayExpr& e);
  Value lowerComprehension(const ast::ComprehensionExpr& e);
  Value lowerIf(const ast::IfExpr& e);
  Value lowerRange(const ast::RangeExpr& e);
  Value stack(std::vector<Value> parts, SourceRange r);
  class EndScope;
  std::vector<int> subscriptIndices(const ast::Expr& s, int dimSize);
  int subscriptIndex(const ast::Expr& s, int dimSize);
  void checkIndex(long i, int dimSize, const ast::Expr& s);
  size_t elementOffset(const ast::IndexExpr& e, const Value& base);
  Value mapUnary(const Value& v, sym::Kind k);

  friend struct IteratorScope;
};

}  // namespace qdot::flat
