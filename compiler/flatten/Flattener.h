// Flattener internals shared by Flatten.cpp (declarations and statements) and ExprLowering.cpp
// (AST expressions to arrays of symbolic expressions). Not part of the stage's interface.
#pragma once

#include <deque>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "flatten/Flatten.h"
#include "structural/AliasElimination.h"

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

struct Instance;

/// A modification that applies to an instance's elements (`Mass m1(m = 2, s(start = 0.1))`),
/// with the instance whose scope its values are written in.
struct ModEntry {
  const ast::Modification* mod = nullptr;
  Instance* scope = nullptr;
  int element = -1;         ///< for an array of components: this element (row-major) ...
  std::vector<int> shape;   ///< ... of an array of this shape: an array value gives one element each
};

/// The instances of one component declaration (one, or an array of them).
struct ComponentArray {
  std::vector<int> shape;
  std::vector<Instance*> elems;
};

/// One instance of a class: the model compiled, or a component inside it (`m1`, `ms[2]`, `m1.a`).
/// Its variables are named by its path (`ms[2].s`).
struct Instance {
  const sema::CheckedClass* cls = nullptr;
  Instance* parent = nullptr;
  const ast::Declaration* decl = nullptr;  ///< the component declaration (null for the model)
  std::string path;                        ///< "ms[2]"; "" for the model
  int index = 0;                           ///< in FlatModel::components
  std::vector<ModEntry> mods;              ///< outer modifications first (they win)
  std::vector<std::string> promoted;       ///< a connector's potentials that are coordinates
  std::unordered_map<const ast::Declaration*, ComponentArray> children;
  std::vector<std::pair<int, int>> aliasPairs;  ///< its equations `x = y` between variables
  /// By declaration (sema::ModelSymbol::index): its value once resolved, its variables once made.
  struct Slot {
    Value value, variables;
    enum : uint8_t { Empty, Pending, Resolved, Failed } state = Empty;
    bool hasVariables = false;
  };
  std::vector<Slot> slots;

  std::string prefix() const { return path.empty() ? "" : path + "."; }
};

/// A declaration of one instance: what the work list of definitions resolves.
struct DeclKey {
  Instance* inst = nullptr;
  const sema::ModelSymbol* symbol = nullptr;
  Instance::Slot& slot() const { return inst->slots[symbol->index]; }
};

/// Thrown while lowering a declaration that uses `key`, not yet resolved: resolve that one first.
struct NeedFirst {
  DeclKey key;
};

/// One `connect(a, b)`: the two connector instances, each inside (a component's connector) or
/// outside (the connector of the instance whose equation it is).
struct ConnectorEnd {
  Instance* connector = nullptr;
  bool outside = false;
};
struct Connection {
  ConnectorEnd a, b;
  SourceRange range;
};

class ValueKeys;  // Connections.cpp
struct FunctionFrame;  // Functions.cpp

/// An equation that makes variable x another variable (x = sign * y) or a known value (y < 0:
/// x = value, an expression of parameters, and of time for a connector potential).
struct AliasEquation {
  int x = -1, y = -1, sign = 1;
  sym::Expr value = nullptr;
  bool ofPotential = false;  ///< a connector's potential's (spec §7), not between plain unknowns
};

/// An iterator of a sum lowered as a template (IndexedSums.cpp) and its range.
struct TemplateIterator {
  std::string name;
  long first = 0, last = 0;
  /// The iterator of an array definition's comprehension read inside a template (`px[i+1]` with
  /// `Real px[n] = {l*sin(th[j]) for j in 1:n}`): the name stands for template iterator `alias`
  /// plus `shift` (-1: a template iterator of its own, which the template's box has).
  int alias = -1;
  long shift = 0;
};

/// A top-level summand of an energy statement or an output, its sign, and the factors it is
/// multiplied by (`0.5*m*sum(…)`: the summand `sum(…)` with the factor `0.5*m`; divide: 1/factor),
/// outermost first.
struct Summand {
  struct Factor {
    const ast::Expr* expr;
    bool divide;
  };
  const ast::Expr* expr;
  bool negated;
  std::vector<Factor> factors;
};

/// The kind of a built-in math function of one argument (sin … sign; Builtins.cpp), or nullopt.
std::optional<sym::Kind> unaryMathKind(std::string_view name);

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
  /// A range's first value, step and number of values (checked as every range is).
  struct RangeBounds {
    double first = 0, step = 1;
    size_t count = 0;
  };
  RangeBounds rangeBounds(const ast::RangeExpr& r);
  sym::Expr timeDerivative(sym::Expr e, SourceRange where);
  sym::Expr rateOf(sym::Expr symbol);
  Value eulerZXZ(const ast::CallExpr& e);
  OutputKind outputKind(const ast::Declaration& d);

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
  std::string derivativeName_;                       ///< derivativeVariable's buffer for "der(x[1])"

  std::deque<Instance> instances_;  ///< [0] is the model; then components in creation order
  Instance* cur_ = nullptr;         ///< whose names the expressions being lowered use
  std::vector<DeclKey> pending_;  ///< declarations waiting for one another, innermost last (Slot::Pending)
  const sema::ModelSymbol* creating_ = nullptr;  ///< the declaration createDeclaration is making
  std::map<std::pair<const ast::Modification*, Instance*>, Value> modValues_;  ///< each modifier lowered once
  std::map<std::pair<const ast::Modification*, const Instance*>, ModEntry> extendsEntries_;
  std::unordered_set<const ast::Modification*> badModifiers_;  ///< reported once, not per element
  std::vector<Instance*> varOwner_;       ///< by variable: the instance that declared it
  /// The attribute record of a declaration's description alone (FlatModel::attributes), by the
  /// description's text in the AST: shared by every instance of the declaration's class (a
  /// component array's members), as by an array's elements; setAttribute copies before it changes one.
  std::unordered_map<const char*, int> descriptionRecords_;
  std::vector<char> connectorPotential_;  ///< by variable: a potential of a connector
  std::vector<Connection> connections_;
  std::vector<size_t> aliasCandidates_;   ///< equations that may be aliases (`x = ±y`, `x = known`)
  std::vector<std::pair<std::string, sym::Expr>> iterators_;  ///< innermost last
  std::vector<std::pair<const Value*, int>> endContext_;      ///< (array, dimension) being subscripted, for `end`
  std::vector<FunctionFrame*> frames_;  ///< function calls being inlined, innermost last

  // Flatten.cpp
  const Value& valueOf(Instance& inst, const sema::ModelSymbol& s, SourceRange use);
  void resolveInnermost();
  Value createDeclaration(const ast::Declaration& d, const sema::ModelSymbol& s);
  std::vector<int> evaluateDims(const ast::Declaration& d);
  Value variablesFor(const ast::Declaration& d, const std::vector<int>& shape, VarRole role);
  void applyAttributes(const ast::Declaration& d, const Value& vars);
  void applyAttributeList(const std::vector<ast::Modification>& mods, const std::string& name, const Value& vars,
                          const ModEntry* outer = nullptr);
  void setAttribute(const Value& vars, bool sameForAll, const std::function<void(VariableAttributes&, size_t)>& set);
  Value bindingValue(const ast::Declaration& d, const std::vector<int>& shape);
  bool hasBinding(const ast::Declaration& d);
  void declareInstance(Instance& inst);
  void lowerInstance(Instance& inst);

  // Instances.cpp
  class ScopeGuard;
  Instance& newInstance(const sema::CheckedClass& cls, Instance* parent, const ast::Declaration* decl, std::string path);
  void instantiate(Instance& inst);
  const ModEntry* modifierOf(const Instance& inst, const ast::Declaration& d);
  Value modifierValue(const ModEntry& entry, SourceRange where);
  static Value elementOf(const ModEntry& entry, const Value& v);
  static ModEntry nestedEntry(const ModEntry& outer, const ast::Modification& m, const std::vector<int>& shape, size_t k);
  void checkArrayModifier(const ModEntry& entry, const Value& v, const ast::Modification& written);
  const sema::ModelSymbol& symbolIn(const Instance& inst, const std::string& name, SourceRange where);
  Instance& instanceOf(const ast::Expr& e);
  const ComponentArray& componentArrayOf(const ast::Expr& e);
  const ComponentArray& childArray(Instance& inst, const std::string& name, SourceRange where);
  Value lowerMember(const ast::MemberExpr& e);
  Value lowerDotted(const ast::NameExpr& n);

  // Connections.cpp
  void lowerConnect(const ast::Equation& eq);
  void recordAlias(size_t equation);
  void connectAll();
  void addFlowBalances(const std::vector<std::vector<ConnectorEnd>>& sets, const std::vector<SourceRange>& ranges);
  void eliminateAliases(const std::vector<std::vector<ConnectorEnd>>& sets, const std::vector<SourceRange>& ranges);
  std::optional<AliasEquation> aliasEquation(const Equation& e);
  bool plainUnknown(int var) const;
  bool overParameters(sym::Expr e, bool timeToo);
  void applyAliases(const structural::AliasResult& r, const ValueKeys& keys);
  void reportRejectedAlias(const AliasEquation& a, const Equation& e, const structural::RelationOutcome& outcome,
                           SourceRange earlier, const std::unordered_map<int, SourceRange>& connectedAt);
  void reportUnusedStart(const structural::AliasConflict& c, const structural::AliasResult& r);
  void setAlias(int var, sym::Expr value, SourceRange where);
  void eliminateFlow(int var, sym::Expr value, SourceRange where);
  void attachFlows();
  int coordinateOfPotential(const Instance& inst, int x);
  bool fixedPotential(int var);
  int addVariable(Variable v);
  void reserveVariables(size_t count);
  void reserveSymbolSlots(std::span<const sym::Expr> symbols);
  int derivativeVariable(int var, SourceRange where);
  /// The der() symbols of variables (coordinates, velocities or unknowns, in order): those not made
  /// yet as derivativeVariable makes them, in the same order, their names a batch at a time.
  std::vector<sym::Expr> derivativeSymbols(std::span<const sym::Expr> elements, SourceRange where);
  int addDerivative(int var, VarRole role, sym::Expr symbol);
  void addCoordinateDerivatives(const Value& coordinates);
  bool addCoordinateDerivativeArrays(const Value& coordinates);
  void checkShape(const Value& v, const std::vector<int>& shape, SourceRange r, const std::string& what);
  void countScalars(size_t n, SourceRange r);
  void lowerEquation(const ast::Equation& eq, std::vector<Equation>& into, OriginKind kind);
  void lowerMechanics(const ast::MechanicsStmt& st);
  void addTerms(std::vector<Term>& into, const ast::MechanicsStmt& st);
  void lowerForce(const ast::MechanicsStmt& st);
  void lowerExperiment();

  // IndexedSums.cpp (FlattenLimits::keepLoops)
  void addTermsKeepingLoops(std::vector<Term>& into, const ast::MechanicsStmt& st, const char* what);
  void collectSummands(const ast::Expr& e, std::vector<Summand>& out, const ast::Declaration* own);
  void collectSummands(const ast::Expr& e, bool negated, std::vector<Summand::Factor>& factors,
                       std::vector<Summand>& out, std::vector<const ast::Declaration*>& through);
  bool hasSumSummand(const ast::Expr& e, std::vector<const ast::Declaration*>& through);
  bool mayContainSum(const ast::Expr& e);
  bool lowerSummand(const Summand& t, const char* what, IndexedSum& sum, sym::Expr& value);
  sym::Expr withFactors(sym::Expr v, const Summand& t);
  const ast::Declaration* substitutedDefinition(const ast::Expr& e);
  bool readsOnlyCoordinatesAndData(const ast::Expr& e, std::vector<std::string>& its, int declaredBefore);
  bool defersDefinition(Instance& inst, const sema::ModelSymbol& s);
  void resolveDeferred();
  std::vector<DeclKey> deferred_;                    ///< definitions waiting to be inlined (defersDefinition)
  std::set<const Instance::Slot*> inlined_;          ///< definitions whose bindings statements inlined
  bool lowerIndexedSum(const ast::CallExpr& call, bool negated, IndexedSum& sum);
  std::optional<sym::Expr> lowerTemplated(const ast::Expr& e, const std::vector<TemplateIterator>& its, const char* what,
                                          bool unknownRates = false);
  bool lowerOutputKeepingSums(Instance& inst, const sema::ModelSymbol& s);
  bool lowerEquationKeepingSums(const ast::Equation& eq, std::vector<Equation>& into);
  /// The outputs lowered with their sums kept (lowerOutputKeepingSums), by declaration: a later use
  /// of the definition resolves it as usual, and its output then takes the expanded value.
  std::map<const Instance::Slot*, size_t> keptOutputs_;
  std::optional<Value> lowerRelativeIndex(const ast::IndexExpr& e);
  const ast::ComprehensionExpr* elementwiseDefinition(const ast::IndexExpr& e);
  std::optional<Value> lowerDefinitionElement(const ast::IndexExpr& e, const ast::ComprehensionExpr& binding);
  sym::Expr relativeSymbol(const RelativeElement& rel);
  int arrayOf(const Value& declared, const std::string& name);
  long plainInteger(const ast::Expr& e);
  sym::Expr rateOfRelative(const RelativeElement& rel);
  bool addTemplateIterator(const ast::Iterator& it, std::vector<TemplateIterator>& its);
  bool lowerEquationTemplates(const ast::Equation& loop);
  bool lowerMechanicsLoop(const ast::MechanicsStmt& loop);
  std::optional<IndexedForce> lowerForceTemplate(const ast::MechanicsStmt& st, const std::vector<TemplateIterator>& its);
  std::optional<IndexedSum> lowerEnergyTemplate(const ast::MechanicsStmt& st, const std::vector<TemplateIterator>& its);
  std::optional<std::vector<TemplateIterator>> equationTemplateIterators(const ast::Equation*& innermost);
  std::optional<EquationTemplate> lowerEquationTemplate(const ast::Equation& eq, const std::vector<TemplateIterator>& its);
  bool ratesOfUnknowns_ = false;  ///< lowering an equation template: der() of an array of unknowns is an array
  std::vector<TemplateIterator> templateIterators_;  ///< of the sum being lowered as a template
  std::map<const Value*, int> arrayIds_;             ///< declared arrays met in templates

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
  std::optional<Value> numericComprehension(const ast::ComprehensionExpr& e);
  Value lowerIf(const ast::IfExpr& e);
  Value lowerRange(const ast::RangeExpr& e);
  Value stack(std::vector<Value> parts, SourceRange r);
  class EndScope;
  std::vector<int> subscriptIndices(const ast::Expr& s, int dimSize);
  int subscriptIndex(const ast::Expr& s, int dimSize);
  void checkIndex(long i, int dimSize, const ast::Expr& s);
  size_t elementOffset(const ast::IndexExpr& e, const Value& base);
  Value mapUnary(const Value& v, sym::Kind k);

  // Functions.cpp
  class FrameGuard;
  Value lowerFunctionCall(const sema::FunctionCall& call);
  Value functionVariable(const sema::ModelSymbol& s, SourceRange use);
  Value lowerFunctionName(const ast::NameExpr& n);

  friend struct IteratorScope;
  friend class TemplateCheck;
  friend class ScopeGuard;
  friend class FrameGuard;
};

// Lowering in another instance's scope (a declaration resolved from anywhere, a modifier written
// in the enclosing model): its names, no loop iterators, no `end` context; restored on exit.
class Flattener::ScopeGuard {
 public:
  ScopeGuard(Flattener& f, Instance& inst)
      : f_(f), cur_(f.cur_), iterators_(std::move(f.iterators_)), end_(std::move(f.endContext_)) {
    f_.cur_ = &inst;
    f_.iterators_.clear();
    f_.endContext_.clear();
  }
  ~ScopeGuard() {
    f_.cur_ = cur_;
    f_.iterators_ = std::move(iterators_);
    f_.endContext_ = std::move(end_);
  }
  ScopeGuard(const ScopeGuard&) = delete;
  ScopeGuard& operator=(const ScopeGuard&) = delete;

 private:
  Flattener& f_;
  Instance* cur_;
  std::vector<std::pair<std::string, sym::Expr>> iterators_;
  std::vector<std::pair<const Value*, int>> end_;
};

}  // namespace qdot::flat
