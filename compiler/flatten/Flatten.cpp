// Flatten: declarations to scalar variables (lazily, so declaration order does not matter),
// equations and mechanics statements expanded over for-loops, the experiment annotation read.
#include "flatten/Flatten.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "flatten/Flattener.h"
#include "qdot/two_halves.hpp"
#include "support/Assert.h"

namespace qdot::flat {

using namespace qdot::ast;
using sema::SymbolKind;
using sym::Expr;

// f(name) for each scalar name in row-major order: x, x[1], M[1,2]. One buffer is rewritten in
// place, so a large array's names cost no allocation each.
template <class F>
static void forEachScalarName(const std::string& base, const std::vector<int>& shape, F&& f) {
  size_t n = 1;
  for (int s : shape) n *= static_cast<size_t>(s);
  std::vector<int> idx(shape.size(), 1);
  std::string name;
  char digits[16];
  for (size_t k = 0; k < n; ++k) {
    name.assign(base);
    for (size_t i = 0; i < idx.size(); ++i) {
      name += i ? ',' : '[';
      name.append(digits, std::to_chars(digits, digits + sizeof digits, idx[i]).ptr);
    }
    if (!idx.empty()) name += ']';
    f(std::string_view(name));
    for (size_t i = idx.size(); i-- > 0;) {
      if (++idx[i] <= shape[i]) break;
      idx[i] = 1;
    }
  }
}

namespace {

// Many names in one buffer instead of a string each; viewed once all are written (the buffer moves
// while it grows). A large array's names go through it in batches (full(), then clear()): the
// buffers stay small and in cache instead of growing to tens of bytes per element.
struct NameBuffer {
  static constexpr size_t kBatch = 4096;
  std::string chars;
  std::vector<size_t> ends;
  /// The characters appended since the previous name are a name.
  void finish() { ends.push_back(chars.size()); }
  bool full() const { return ends.size() >= kBatch; }
  void clear() { chars.clear(), ends.clear(); }
  std::vector<std::string_view> views() const {
    std::vector<std::string_view> out;
    out.reserve(ends.size());
    size_t begin = 0;
    for (size_t end : ends) out.emplace_back(chars.data() + begin, end - begin), begin = end;
    return out;
  }
};

}  // namespace

static std::vector<std::string> scalarNames(const std::string& base, const std::vector<int>& shape) {
  std::vector<std::string> names;
  forEachScalarName(base, shape, [&](std::string_view name) { names.emplace_back(name); });
  return names;
}

const char* roleName(VarRole r) {
  switch (r) {
    case VarRole::Time: return "time";
    case VarRole::Parameter: return "parameter";
    case VarRole::Coordinate: return "coordinate";
    case VarRole::Velocity: return "velocity";
    case VarRole::Acceleration: return "acceleration";
    case VarRole::Unknown: return "unknown";
    case VarRole::Derivative: return "derivative";
    case VarRole::Multiplier: return "multiplier";
  }
  return "?";
}

std::optional<FlatModel> flatten(const sema::CheckedModel& model, sym::Context& ctx, DiagnosticEngine& diags,
                                 FlattenLimits limits, const StructuralValues& structural) {
  return Flattener(model, ctx, diags, limits, structural).run();
}

Flattener::Flattener(const sema::CheckedModel& m, sym::Context& ctx, DiagnosticEngine& diags, FlattenLimits limits,
                     StructuralValues structural)
    : m_(m), ctx_(ctx), diags_(diags), limits_(limits), structural_(std::move(structural)) {
  timeDerivative_.setRateFunction([this](Expr s) { return rateOf(s); });
}

template <class F> void Flattener::guarded(F&& body) {
  try {
    body();
  } catch (FlattenAbort&) {
  }
}

void Flattener::forEachIteration(const std::vector<Iterator>& its, size_t k, const std::function<void()>& body) {
  if (k == its.size()) return body();
  for (Expr v : iterationValues(*its[k].range)) {
    iterators_.emplace_back(its[k].name, v);
    try {
      forEachIteration(its, k + 1, body);
    } catch (...) {
      iterators_.pop_back();
      throw;
    }
    iterators_.pop_back();
  }
}

// The model's instance tree first (every component, with its modifiers), then each instance's
// declarations, equations and mechanics, then the connections.
std::optional<FlatModel> Flattener::run() {
  size_t errorsBefore = diags_.errorCount();
  const ast::ClassDef& cls = *m_.root->cls;
  out_.name = cls.name;
  out_.description = cls.description;
  out_.range = cls.nameRange;
  addVariable({.role = VarRole::Time, .symbol = ctx_.symbol("time")});
  Instance& root = newInstance(*m_.root, nullptr, nullptr, "");
  cur_ = &root;
  guarded([&] { instantiate(root); });
  for (Instance& inst : instances_) declareInstance(inst);  // variables in instance order
  for (Instance& inst : instances_) lowerInstance(inst);
  resolveDeferred();
  cur_ = &root;
  if (diags_.errorCount() == errorsBefore) guarded([&] { connectAll(); });
  guarded([&] { lowerExperiment(); });
  if (diags_.errorCount() > errorsBefore) return std::nullopt;
  return std::move(out_);
}

void Flattener::declareInstance(Instance& inst) {
  cur_ = &inst;
  for (const auto* d : inst.cls->declarations) {
    const sema::ModelSymbol& s = inst.cls->symbols.at(d->name);
    if (s.kind != sema::SymbolKind::Component)
      guarded([&] {
        if (!limits_.keepLoops || (!lowerOutputKeepingSums(inst, s) && !defersDefinition(inst, s)))
          valueOf(inst, s, d->nameRange);
      });
  }
}

// The deferred definitions no statement inlined, resolved as at their declarations (their
// diagnostics); those inlined were lowered there, summand by summand, with theirs.
void Flattener::resolveDeferred() {
  for (const DeclKey& key : deferred_) {
    if (inlined_.count(&key.slot()) || key.slot().state != Instance::Slot::Empty) continue;
    cur_ = key.inst;
    guarded([&] { valueOf(*key.inst, *key.symbol, key.symbol->decl->nameRange); });
  }
}

void Flattener::lowerInstance(Instance& inst) {
  cur_ = &inst;
  for (const auto* eq : inst.cls->equations) guarded([&] { lowerEquation(*eq, out_.equations, OriginKind::Equation); });
  for (const auto* eq : inst.cls->initialEquations)
    guarded([&] { lowerEquation(*eq, out_.initialEquations, OriginKind::InitialEquation); });
  for (const auto* st : inst.cls->mechanics) guarded([&] { lowerMechanics(*st); });
}

void Flattener::countScalars(size_t n, SourceRange r) {
  scalars_ += n;
  if (scalars_ > limits_.maxScalars)
    fail(r, DiagCode::E0310, "the model expands to more than " + std::to_string(limits_.maxScalars) + " scalars",
         "reduce the array sizes or loop ranges");
}

std::vector<int> FlatModel::variablesWithRole(VarRole r) const {
  std::vector<int> halves[2];
  inTwoHalves(variables.size(), [&](size_t first, size_t last) {
    std::vector<int>& out = halves[first == 0 ? 0 : 1];
    for (size_t i = first; i < last; ++i)
      if (variables[i].role == r) out.push_back(static_cast<int>(i));
  });
  halves[0].insert(halves[0].end(), halves[1].begin(), halves[1].end());
  return std::move(halves[0]);
}

// The variable's name is its symbol's.
int Flattener::addVariable(Variable v) {
  int index = static_cast<int>(out_.variables.size());
  v.name = ctx_.symbolName(v.symbol);
  uint32_t id = v.symbol->symbolId;
  if (out_.symbolToVariable.size() <= id) out_.symbolToVariable.resize(id + 1, -1);
  out_.symbolToVariable[id] = index;
  out_.variables.push_back(std::move(v));
  varOwner_.push_back(cur_);
  connectorPotential_.push_back(0);
  return index;
}

// der(x) of a variable: created on first use. A coordinate's velocity and a velocity's
// acceleration have their own roles; a second derivative of any other unknown is refused.
// The role of der(v) for a variable of role r: Time where v has none.
static VarRole derivativeRole(VarRole r) {
  return r == VarRole::Coordinate ? VarRole::Velocity
         : r == VarRole::Velocity ? VarRole::Acceleration
         : r == VarRole::Unknown  ? VarRole::Derivative
                                  : VarRole::Time;
}

int Flattener::derivativeVariable(int var, SourceRange where) {
  if (out_.variables[var].derivative >= 0) return out_.variables[var].derivative;
  VarRole role = out_.variables[var].role;
  VarRole derRole = derivativeRole(role);
  if (derRole == VarRole::Time)
    fail(where, DiagCode::E0311,
         "cannot take the derivative of '" + std::string(out_.variables[var].name) + "' (a " + roleName(role) + ")",
         "higher derivatives are only available for coordinates: declare the variable as 'coordinate Real'");
  derivativeName_.assign("der(").append(out_.variables[var].name) += ')';
  return addDerivative(var, derRole, ctx_.symbol(derivativeName_));
}

// derivativeVariable for every element, with the symbols of a batch made by one Context::symbols
// (the name table reserved and probed ahead): a template's der(T[i]) over 10⁶ unknowns made them
// one name at a time, 0.24 s of the heat rod's flatten. Same names, ids and variable indices.
std::vector<Expr> Flattener::derivativeSymbols(std::span<const Expr> elements, SourceRange where) {
  constexpr int kQueued = -2;  ///< a variable's `derivative` while its name waits in the batch
  std::vector<int> vars(elements.size()), queued;
  NameBuffer names;
  auto make = [&] {
    std::vector<Expr> symbols = ctx_.symbols(names.views());
    for (size_t k = 0; k < queued.size(); ++k) {
      out_.variables[queued[k]].derivative = -1;
      addDerivative(queued[k], derivativeRole(out_.variables[queued[k]].role), symbols[k]);
    }
    queued.clear();
    names.clear();
  };
  for (size_t k = 0; k < elements.size(); ++k) {
    int var = vars[k] = out_.variableOf(elements[k]);
    if (out_.variables[var].derivative != -1) continue;  // made, or queued already
    if (derivativeRole(out_.variables[var].role) == VarRole::Time) {
      make();
      derivativeVariable(var, where);  // reports why it has none
      continue;
    }
    out_.variables[var].derivative = kQueued;
    queued.push_back(var);
    names.chars.append("der(").append(out_.variables[var].name) += ')';
    names.finish();
    if (names.full()) make();
  }
  make();
  std::vector<Expr> rates(elements.size());
  for (size_t k = 0; k < elements.size(); ++k) rates[k] = out_.variables[out_.variables[vars[k]].derivative].symbol;
  return rates;
}

int Flattener::addDerivative(int var, VarRole role, Expr symbol) {
  Variable d{.role = role, .symbol = symbol, .declRange = out_.variables[var].declRange};
  d.derivativeOf = var;
  int index = addVariable(std::move(d));
  out_.variables[var].derivative = index;
  return index;
}

// Every coordinate has a velocity and an acceleration, used or not: der(x[1]), der(der(x[1])),
// der(x[2]), … in the order derivativeVariable would make them, with their symbols made a batch at
// a time (Context::symbols). A declaration lowered again after a dependency already has them.
void Flattener::addCoordinateDerivatives(const Value& coordinates) {
  if (addCoordinateDerivativeArrays(coordinates)) return;
  std::vector<int> vars;
  NameBuffer names;
  auto make = [&] {
    std::vector<Expr> symbols = ctx_.symbols(names.views());
    for (size_t k = 0; k < vars.size(); ++k)
      addDerivative(addDerivative(vars[k], VarRole::Velocity, symbols[2 * k]), VarRole::Acceleration, symbols[2 * k + 1]);
    vars.clear();
    names.clear();
  };
  for (Expr x : coordinates.elems) {
    int var = out_.variableOf(x);
    if (out_.variables[var].derivative >= 0) continue;
    vars.push_back(var);
    names.chars.append("der(").append(out_.variables[var].name) += ')';
    names.finish();
    names.chars.append("der(der(").append(out_.variables[var].name) += "))";
    names.finish();
    if (names.full()) make();
  }
  make();
}

// The coordinates are a whole array of symbols (Context::symbolArray), none with a velocity yet:
// their velocities and accelerations are two such arrays, der(x[i]) and der(der(x[i])).
bool Flattener::addCoordinateDerivativeArrays(const Value& coordinates) {
  size_t count = ctx_.wholeSymbolArrayAt(coordinates.elems);
  if (count == 0 || count != coordinates.elems.size()) return false;
  for (Expr x : coordinates.elems)
    if (out_.variables[out_.variableOf(x)].derivative >= 0) return false;
  std::vector<Expr> velocities = ctx_.symbolArrayAround(coordinates.elems[0], "der(", ")");
  std::vector<Expr> accelerations = ctx_.symbolArrayAround(coordinates.elems[0], "der(der(", "))");
  reserveSymbolSlots(accelerations);  // made last: the largest ids
  reserveVariables(2 * count);
  for (size_t k = 0; k < count; ++k) {
    int var = out_.variableOf(coordinates.elems[k]);
    addDerivative(addDerivative(var, VarRole::Velocity, velocities[k]), VarRole::Acceleration, accelerations[k]);
  }
  return true;
}

// A declaration's value, created on first use. Declarations may use each other in any order, and a
// chain of them (a0 = a1 + 1, a1 = a2 + 1, …) may be as long as the model: resolving them by
// recursion would let the model decide the depth of the stack. So the first use runs a work list
// instead: `pending_` holds the declarations waiting for one another, innermost last. Lowering the
// innermost one that meets a declaration not yet resolved abandons it (NeedFirst), resolves that
// one first and then lowers it again; declarations already resolved are looked up, so every
// declaration is lowered at most once more than it has unresolved dependencies, in the order (and
// with the side effects in the order) that the recursion had. A use of a pending declaration
// closes a cycle. (The price: a binding naming k declarations not yet resolved is lowered k + 1
// times, so a literal array of 10⁴ forward references takes seconds; models name a few.)
const Value& Flattener::valueOf(Instance& inst, const sema::ModelSymbol& s, SourceRange use) {
  DeclKey key{&inst, &s};
  Instance::Slot& slot = key.slot();
  if (slot.state == Instance::Slot::Resolved) return slot.value;
  if (slot.state == Instance::Slot::Failed) throw FlattenAbort{};
  if (slot.state == Instance::Slot::Pending)
    fail(use, DiagCode::E0312, "the definition of '" + inst.prefix() + s.decl->name + "' depends on itself",
         "break the cycle: a definition or parameter cannot refer to itself, directly or through others");
  if (!pending_.empty()) throw NeedFirst{key};
  pending_.push_back(key);
  slot.state = Instance::Slot::Pending;
  while (!pending_.empty()) resolveInnermost();
  return slot.value;
}

void Flattener::resolveInnermost() {
  DeclKey key = pending_.back();
  size_t scalarsBefore = scalars_;  // the retry counts this declaration's scalars again
  try {
    ScopeGuard scope(*this, *key.inst);
    creating_ = key.symbol;
    Value v = createDeclaration(*key.symbol->decl, *key.symbol);
    key.slot().value = std::move(v);
    key.slot().state = Instance::Slot::Resolved;
    pending_.pop_back();
  } catch (const NeedFirst& first) {
    scalars_ = scalarsBefore;
    pending_.push_back(first.key);
    first.key.slot().state = Instance::Slot::Pending;
  } catch (...) {  // an error: every declaration waiting for this one fails with it
    for (const DeclKey& k : pending_) k.slot().state = Instance::Slot::Failed;
    pending_.clear();
    throw;
  }
}

std::vector<int> Flattener::evaluateDims(const Declaration& d) {
  std::vector<int> shape;
  size_t total = 1;
  for (const auto* dims : {&d.typeDims, &d.dims})
    for (const auto& e : *dims) {
      long n = lowerInteger(*e, "an array size");
      if (n < 0) fail(e->range, DiagCode::E0303, "array size " + std::to_string(n) + " is negative");
      shape.push_back(static_cast<int>(n));
      total *= static_cast<size_t>(n);
      countScalars(static_cast<size_t>(n), e->range);
    }
  if (shape.size() > 1) countScalars(total, d.nameRange);
  return shape;
}

// The kind a declaration has in this instance: a component's input or unknown that a modifier
// binds (`Force f(F = 10*sin(time))`) is a definition; a component's unbound input an unknown.
static SymbolKind kindInInstance(SymbolKind kind, bool root, bool bound) {
  if (kind == SymbolKind::Input && root) return kind;
  if (kind == SymbolKind::Input || kind == SymbolKind::Unknown) return bound ? SymbolKind::Definition : SymbolKind::Unknown;
  return kind;
}

// `annotation(unwrap = true)` on an output: an angle; `unwrap = "psi"|"theta"|"phi"`: one of a
// z-x-z Euler-angle triple (written in that order). Anything else is an error at the value.
OutputKind Flattener::outputKind(const Declaration& d) {
  if (!d.annotation) return OutputKind::Plain;
  for (const auto& m : d.annotation->mods) {
    if (m.name != "unwrap" || !m.value) continue;
    if (auto* b = dyn_cast<BoolExpr>(m.value.get())) return b->value ? OutputKind::Angle : OutputKind::Plain;
    if (auto* s = dyn_cast<StringExpr>(m.value.get())) {
      if (s->value == "psi") return OutputKind::EulerPsi;
      if (s->value == "theta") return OutputKind::EulerTheta;
      if (s->value == "phi") return OutputKind::EulerPhi;
    }
    fail(m.value->range, DiagCode::E0312, "unwrap takes true, false, \"psi\", \"theta\" or \"phi\"",
         "annotation(unwrap = true) makes an angle output continuous (no jumps of 2 pi)");
  }
  return OutputKind::Plain;
}

Value Flattener::createDeclaration(const Declaration& d, const sema::ModelSymbol& s) {
  std::vector<int> shape = evaluateDims(d);
  bool root = cur_ == &instances_.front();
  const ModEntry* mod = modifierOf(*cur_, d);
  SourceRange valueRange = mod && mod->mod->value ? mod->mod->value->range : d.binding ? d.binding->range : d.nameRange;
  std::string name = cur_->prefix() + d.name;
  switch (kindInInstance(s.kind, root, mod && mod->mod->value)) {
    case SymbolKind::Constant:
    case SymbolKind::IntegerParameter: {
      if (auto given = structural_.find(name); given != structural_.end()) {  // -p n=3, -p str.n=40
        QDOT_ASSERT(s.kind == SymbolKind::IntegerParameter && shape.empty(), "a structural value for a non-scalar or non-Integer");
        out_.structuralParameters.push_back(name + " = " + std::to_string(given->second));
        return Value::scalar(ctx_.constant(static_cast<double>(given->second)));
      }
      Value v = bindingValue(d, shape);
      if (root && s.kind == SymbolKind::IntegerParameter && shape.empty() && v.elems[0]->isConstant() &&
          std::isfinite(v.elems[0]->value))
        out_.structuralParameters.push_back(d.name + " = " + sym::toString(ctx_, v.elems[0]));
      for (size_t i = 0; i < v.size(); ++i)
        if (!v.elems[i]->isConstant())
          fail(valueRange, DiagCode::E0313, "the value of '" + name + "' must be known at compile time",
               "constants and Integer parameters may only depend on literals and other constants");
        else if (!std::isfinite(v.elems[i]->value))  // here, where it is folded: later it is only an `inf` in an equation
          fail(valueRange, DiagCode::E0314,
               "the value of '" + name + "' is not a finite number (it evaluates to " +
                   sym::toString(ctx_, v.elems[i]) + ")",
               "look for a division by zero or an overflow in this expression");
        else if (s.kind == SymbolKind::IntegerParameter && v.elems[i]->value != std::floor(v.elems[i]->value))
          fail(valueRange, DiagCode::E0313, "Integer parameter '" + name + "' has a non-integer value");
      return v;
    }
    case SymbolKind::Definition: {
      Value v = bindingValue(d, shape);
      if (d.causality == Causality::Output) {
        std::vector<std::string> names = scalarNames(name, shape);
        OutputKind kind = outputKind(d);
        if (auto kept = keptOutputs_.find(&cur_->slots[s.index]); kept != keptOutputs_.end()) {
          out_.outputs[kept->second].value = v.elems[0];  // used elsewhere as well: expanded after all
          out_.outputs[kept->second].sums.clear();
          return v;
        }
        for (size_t i = 0; i < v.size(); ++i) out_.outputs.push_back({names[i], v.elems[i], d.nameRange, kind});
      }
      return v;
    }
    case SymbolKind::Parameter: {
      Value vars = variablesFor(d, shape, VarRole::Parameter);
      Value values = bindingValue(d, shape);
      for (size_t i = 0; i < vars.size(); ++i) out_.variables[out_.variableOf(vars.elems[i])].value = values.elems[i];
      return vars;
    }
    case SymbolKind::Input: {  // of the model compiled: a run-time input, 0 unless set (-p u=1)
      Value vars = variablesFor(d, shape, VarRole::Parameter);
      for (Expr x : vars.elems) {
        Variable& var = out_.variables[out_.variableOf(x)];
        var.value = ctx_.zero();
        var.input = true;
      }
      applyAttributes(d, vars);
      return vars;
    }
    case SymbolKind::Coordinate:
    case SymbolKind::Unknown: {
      // A connector potential that the component's energies use is one of its coordinates.
      bool promoted = std::find(cur_->promoted.begin(), cur_->promoted.end(), d.name) != cur_->promoted.end();
      bool coord = s.kind == SymbolKind::Coordinate || promoted;
      Value vars = variablesFor(d, shape, coord ? VarRole::Coordinate : VarRole::Unknown);
      for (Expr x : vars.elems) {
        int var = out_.variableOf(x);
        out_.variables[var].fixed = coord && !promoted;
        connectorPotential_[var] = cur_->cls->isConnector() && !d.isFlow;
      }
      if (coord) addCoordinateDerivatives(vars);
      applyAttributes(d, vars);
      return vars;
    }
    case SymbolKind::Component: break;
  }
  QDOT_UNREACHABLE("createDeclaration: components are instances, not values");
}

// Room for `count` more variables, growing geometrically (reserving exactly per declaration would
// copy the whole vector for every declaration); a large array then fills it without regrowing.
void Flattener::reserveVariables(size_t count) {
  std::vector<Variable>& vars = out_.variables;
  if (vars.size() + count <= vars.capacity()) return;
  size_t capacity = std::max(vars.size() + count, 2 * vars.capacity());
  vars.reserve(capacity);  // and the tables kept by variable (10⁶ masses: their regrowth was 20 ms)
  varOwner_.reserve(capacity);
  connectorPotential_.reserve(capacity);
}

// symbolToVariable up to a block's last symbol at once (addVariable grew it one id at a time).
void Flattener::reserveSymbolSlots(std::span<const Expr> symbols) {
  uint32_t last = 0;
  for (Expr s : {symbols.front(), symbols.back()}) last = std::max(last, s->symbolId);
  if (out_.symbolToVariable.size() <= last) out_.symbolToVariable.resize(last + 1, -1);
}

// Once per declaration: lowering it again after a dependency was resolved finds them here.
Value Flattener::variablesFor(const Declaration& d, const std::vector<int>& shape, VarRole role) {
  Instance::Slot& slot = cur_->slots[creating_->index];
  if (slot.hasVariables) return slot.variables;
  Value v{shape, {}};
  size_t count = 1;
  for (int n : shape) count *= static_cast<size_t>(n);
  // a coordinate brings its velocity and acceleration
  size_t withDerivatives = role == VarRole::Coordinate ? 3 * count : count;
  reserveVariables(withDerivatives);
  v.elems.reserve(count);
  // A component's variable is located where the model compiled declares the component (`Spring
  // k1;`): what the user can change, rather than a line of the library.
  const Instance* top = cur_;
  while (top->parent && top->parent->parent) top = top->parent;
  SourceRange where = top->decl ? top->decl->nameRange : d.nameRange;
  int attributes = 0;  // one record for the declaration's description, shared by its elements
  if (!d.description.empty()) {  // and by every instance of its class
    auto [record, added] = descriptionRecords_.try_emplace(d.description.data(), static_cast<int>(out_.attributes.size()));
    if (added) out_.attributes.push_back({.description = d.description});
    attributes = record->second;
  }
  // An array's elements are one block of symbols (Context::symbolArray): no name is hashed.
  std::string name = cur_->prefix() + d.name;
  std::vector<Expr> symbols = shape.empty() ? std::vector<Expr>{ctx_.symbol(name)} : ctx_.symbolArray(name, shape);
  if (!symbols.empty()) reserveSymbolSlots(symbols);
  for (Expr symbol : symbols) {
    addVariable({.role = role, .symbol = symbol, .declRange = where, .attributes = attributes});
    v.elems.push_back(symbol);
  }
  slot.variables = std::move(v);
  slot.hasVariables = true;
  return slot.variables;
}

void Flattener::checkShape(const Value& v, const std::vector<int>& shape, SourceRange r, const std::string& what) {
  if (v.shape != shape)
    fail(r, DiagCode::E0307, what + " has shape " + shapeText(v.shape) + ", but " + shapeText(shape) + " is needed",
         shape.empty() ? "give a scalar value" : "give an array of shape " + shapeText(shape) + ", e.g. with fill(value, ...)");
}

// The value a modifier gives (`Mass m1(m = 2)`, `extends Base(k = 1)`), else the declaration's own.
Value Flattener::bindingValue(const Declaration& d, const std::vector<int>& shape) {
  std::string name = cur_->prefix() + d.name;
  if (const ModEntry* mod = modifierOf(*cur_, d); mod && mod->mod->value) {
    Value v = modifierValue(*mod, mod->mod->value->range);
    checkShape(v, shape, mod->mod->value->range, "the value of '" + name + "'");
    return v;
  }
  if (!d.binding) {  // reported where the model compiled declares the component that holds it
    const Instance* top = cur_;
    std::string modifier = d.name + " = ...";
    while (top->parent && top->parent->parent) {
      modifier = top->decl->name + "(" + modifier + ")";
      top = top->parent;
    }
    SourceRange where = top->decl ? top->decl->nameRange : d.nameRange;
    fail(where, DiagCode::E0207, "parameter '" + name + "' has no value",
         top->decl ? "give it one with a modifier: " + top->decl->typeName.back() + " " + top->decl->name + "(" + modifier + ");"
                   : "give it a default value, e.g. parameter Real " + d.name + " = 1;");
  }
  Value v = lower(*d.binding);
  checkShape(v, shape, d.binding->range, "the value of '" + name + "'");
  return v;
}

// start/fixed/nominal/min/max/unit; a scalar value applies to every element of an array.
void Flattener::applyAttributes(const Declaration& d, const Value& vars) {
  std::string name = cur_->prefix() + d.name;
  applyAttributeList(d.mods, name, vars);
  if (const ModEntry* outer = modifierOf(*cur_, d); outer && !outer->mod->nested.empty()) {
    ScopeGuard scope(*this, *outer->scope);  // `Mass m1(s(start = 0.1))`: written where m1 is declared
    applyAttributeList(outer->mod->nested, name, vars, outer);
  }
}

void Flattener::applyAttributeList(const std::vector<ast::Modification>& mods, const std::string& name,
                                   const Value& vars, const ModEntry* outer) {
  for (const auto& mod : mods) {
    if (!mod.value) continue;
    if (mod.name == "unit") {
      if (auto* s = dyn_cast<StringExpr>(mod.value.get()))
        setAttribute(vars, true, [&](VariableAttributes& a, size_t) { a.unit = s->value; });
      continue;
    }
    if (mod.name != "start" && mod.name != "fixed" && mod.name != "nominal" && mod.name != "min" && mod.name != "max")
      continue;
    Value v;
    if (outer) {  // `Mass ms[n](s(start = {…}))`: lowered once for all n elements, each takes its own
      auto key = std::make_pair(&mod, outer->scope);
      auto it = modValues_.find(key);
      if (it == modValues_.end()) it = modValues_.emplace(key, lower(*mod.value)).first;
      checkArrayModifier(*outer, it->second, mod);
      v = elementOf(*outer, it->second);
    } else {
      v = lower(*mod.value);
    }
    if (!v.isScalar()) checkShape(v, vars.shape, mod.value->range, "the " + mod.name + " value of '" + name + "'");
    auto element = [&](size_t i) { return v.isScalar() ? v.elems[0] : v.elems[i]; };
    if (mod.name == "nominal" || mod.name == "min" || mod.name == "max") {
      Expr VariableAttributes::*field = mod.name == "nominal" ? &VariableAttributes::nominal
                                        : mod.name == "min"   ? &VariableAttributes::min
                                                              : &VariableAttributes::max;
      setAttribute(vars, v.isScalar(), [&](VariableAttributes& a, size_t i) { a.*field = element(i); });
      continue;
    }
    for (size_t i = 0; i < vars.size(); ++i) {
      Variable& var = out_.variables[out_.variableOf(vars.elems[i])];
      Expr x = element(i);
      if (mod.name == "start") var.start = x;
      else if (!x->isConstant()) fail(mod.value->range, DiagCode::E0303, "'fixed' must be true or false");
      else var.fixed = x->value != 0, var.fixedGiven = true;
    }
  }
}

// set(attributes, i) on a copy of the record of element i of `vars`, which then refers to the copy.
// With the same value for all (`sameForAll`), elements that shared a record share the new one.
void Flattener::setAttribute(const Value& vars, bool sameForAll,
                             const std::function<void(VariableAttributes&, size_t)>& set) {
  std::unordered_map<int, int> copies;  // record before -> record after (sameForAll)
  for (size_t i = 0; i < vars.size(); ++i) {
    Variable& var = out_.variables[out_.variableOf(vars.elems[i])];
    if (sameForAll)
      if (auto it = copies.find(var.attributes); it != copies.end()) {
        var.attributes = it->second;
        continue;
      }
    VariableAttributes copy = out_.attributes[var.attributes];
    set(copy, i);
    int index = static_cast<int>(out_.attributes.size());
    out_.attributes.push_back(copy);
    if (sameForAll) copies.emplace(var.attributes, index);
    var.attributes = index;
  }
}

void Flattener::lowerEquation(const ast::Equation& eq, std::vector<flat::Equation>& into, OriginKind kind) {
  if (eq.kind == EquationKind::For) {
    bool topLevel = iterators_.empty() && kind == OriginKind::Equation;
    if (limits_.keepForEquations && topLevel && lowerEquationTemplates(eq)) return;
    forEachIteration(eq.iterators, 0, [&] {
      for (const auto& b : eq.body) guarded([&] { lowerEquation(b, into, kind); });
    });
    return;
  }
  if (eq.kind == EquationKind::Connect && kind == OriginKind::Equation && eq.lhs && eq.rhs) return lowerConnect(eq);
  if (eq.kind != EquationKind::Simple || !eq.lhs || !eq.rhs) return;  // sema reported the others
  if (limits_.keepLoops && kind == OriginKind::Equation && iterators_.empty() && cur_ == &instances_.front() &&
      lowerEquationKeepingSums(eq, into))
    return;
  Value l = lower(*eq.lhs);
  Value r = lower(*eq.rhs);
  if (l.shape != r.shape)
    fail(eq.range, DiagCode::E0307, "the two sides of this equation have different shapes: " + shapeText(l.shape) +
                                " and " + shapeText(r.shape));
  countScalars(l.size(), eq.range);
  for (size_t i = 0; i < l.size(); ++i) {
    std::string element = l.isScalar() ? "" : "[" + std::to_string(i + 1) + "]";
    into.push_back({ctx_.sub(l.elems[i], r.elems[i]), {kind, eq.range, -1, element, cur_->index}, l.elems[i], r.elems[i]});
    if (kind == OriginKind::Equation) recordAlias(into.size() - 1);
  }
}

void Flattener::lowerMechanics(const MechanicsStmt& st) {
  switch (st.kind) {
    case MechanicsKind::For:
      if (limits_.keepLoops && iterators_.empty() && lowerMechanicsLoop(st)) return;
      forEachIteration(st.iterators, 0, [&] {
        for (const auto& b : st.body) guarded([&] { lowerMechanics(b); });
      });
      return;
    case MechanicsKind::Kinetic: return addTerms(out_.kinetic, st);
    case MechanicsKind::Potential: return addTerms(out_.potential, st);
    case MechanicsKind::Dissipation: return addTerms(out_.dissipation, st);
    case MechanicsKind::Force: return lowerForce(st);
    case MechanicsKind::Constraint: {
      Value l = lower(*st.value), r = lower(*st.rhs);
      if (l.shape != r.shape) fail(st.range, DiagCode::E0307, "the two sides of this constraint have different shapes");
      for (size_t i = 0; i < l.size(); ++i)
        out_.constraints.push_back(
            {ctx_.sub(l.elems[i], r.elems[i]), {OriginKind::Constraint, st.range, -1, ""}, l.elems[i], r.elems[i]});
      return;
    }
  }
}

void Flattener::addTerms(std::vector<Term>& into, const MechanicsStmt& st) {
  const char* what = st.kind == MechanicsKind::Kinetic ? "a kinetic energy"
                     : st.kind == MechanicsKind::Potential ? "a potential energy" : "a dissipation function";
  if (limits_.keepLoops) return addTermsKeepingLoops(into, st, what);
  into.push_back({lowerScalar(*st.value, what), st.range});
}

void Flattener::lowerForce(const MechanicsStmt& st) {
  Value target = lower(*st.target);
  Value value = lower(*st.value);
  if (target.shape != value.shape)
    fail(st.value->range, DiagCode::E0307, "the force has shape " + shapeText(value.shape) + " but its coordinate has shape " +
                                       shapeText(target.shape));
  for (size_t i = 0; i < target.size(); ++i) {
    int var = out_.variableOf(target.elems[i]);
    if (var < 0 || out_.variables[var].role != VarRole::Coordinate)
      fail(st.target->range, DiagCode::E0209, "force(...) must name a coordinate");
    out_.forces.push_back({var, {value.elems[i], st.range}});
  }
}

void Flattener::lowerExperiment() {
  for (const auto& ann : m_.root->cls->annotations)
    for (const auto& mod : ann.mods) {
      if (mod.name != "experiment") continue;
      for (const auto& m : mod.nested) {
        if (!m.value) continue;
        std::optional<double>* slot = m.name == "StartTime" ? &out_.experiment.startTime
                                      : m.name == "StopTime"  ? &out_.experiment.stopTime
                                      : m.name == "Interval"  ? &out_.experiment.interval
                                      : m.name == "Tolerance" ? &out_.experiment.tolerance
                                                              : nullptr;
        if (!slot) {
          diags_.warning(m.nameRange, DiagCode::W0301, "unknown experiment setting '" + m.name + "' is ignored",
                         "the settings are StartTime, StopTime, Interval and Tolerance");
          continue;
        }
        guarded([&] { *slot = lowerConstant(*m.value, "an experiment setting"); });
      }
    }
}

void renumberVariables(FlatModel& m, const std::vector<int>& newIndex) {
  size_t count = static_cast<size_t>(std::count_if(newIndex.begin(), newIndex.end(), [](int k) { return k >= 0; }));
  std::vector<Variable> vars(count);
  for (size_t v = 0; v < m.variables.size(); ++v) {
    if (newIndex[v] < 0) continue;
    Variable& var = vars[newIndex[v]] = m.variables[v];
    if (var.derivative >= 0) var.derivative = newIndex[var.derivative];
    if (var.derivativeOf >= 0) var.derivativeOf = newIndex[var.derivativeOf];
  }
  m.variables = std::move(vars);
  for (int& v : m.symbolToVariable)
    if (v >= 0) v = newIndex[v];
  for (auto& [q, t] : m.forces) q = newIndex[q];
  for (auto* eqs : {&m.equations, &m.initialEquations, &m.constraints})
    for (Equation& e : *eqs)
      if (e.origin.variable >= 0) e.origin.variable = newIndex[e.origin.variable];
}

}  // namespace qdot::flat
