// Repeated structure kept as templates (issue 15, docs/loops.md). With FlattenLimits::keepLoops,
// a summand `sum(body for i in a:b, j in c:d)` of an energy statement whose body indexes declared
// arrays by an iterator plus a constant (x[i+1], der(x[i]), k[i], y[i, j-1]) is lowered once, with
// each such subscript a *relative symbol* (`x[%1+1]`), instead of once per element. Anything else
// is lowered as before, so a template is only ever an exact rewriting of what expansion gives
// (expandIndexedSums turns it back; tests/unit/IndexedSumTest.cpp checks node identity).
// With FlattenLimits::keepForEquations, a top-level `for` equation naming one derivative,
// `der(x[i]) = rhs` or `m*der(v[i]) = f`, is lowered the same way, once (EquationTemplate).
#include <algorithm>
#include <cmath>

#include "flatten/Flattener.h"
#include "qdot/two_halves.hpp"

namespace qdot::flat {

using namespace qdot::ast;
using sym::Expr;

namespace {

/// Thrown by the template lowering where the scalar lowering must take over; never after a
/// diagnostic was reported.
struct NotATemplate {};

bool mentions(const ast::Expr* e, const std::vector<TemplateIterator>& its);

}  // namespace

/// Decides from the syntax alone whether a sum's body can be lowered as a template: arithmetic,
/// der() and elementary functions over numbers, names and subscripts, with the iterators in
/// subscripts of declared arrays only as `i`, `i + e`, `e + i` or `i - e` (e free of iterators),
/// and elsewhere as numbers (`0.1*i`).
/// Checking first means the template lowering never meets an iterator where a number is needed.
class TemplateCheck {
 public:
  explicit TemplateCheck(const std::vector<TemplateIterator>& its) : its_(its) {}

  bool body(const ast::Expr& e) const {
    switch (e.kind) {
      case ExprKind::Number: return true;
      case ExprKind::Name: return true;  // an iterator as a number too (`0.1*i`: its value, %k)
      case ExprKind::Unary: return cast<UnaryExpr>(&e)->op != UnaryOp::Not && body(*cast<UnaryExpr>(&e)->operand);
      case ExprKind::Binary: {
        auto* b = cast<BinaryExpr>(&e);
        bool arithmetic = b->op == BinaryOp::Add || b->op == BinaryOp::Sub || b->op == BinaryOp::Mul ||
                          b->op == BinaryOp::Div || b->op == BinaryOp::Pow;
        return arithmetic && body(*b->lhs) && body(*b->rhs);
      }
      case ExprKind::Call: return call(*cast<CallExpr>(&e));
      case ExprKind::Index: return index(*cast<IndexExpr>(&e));
      default: return false;
    }
  }

  /// The iterator a subscript uses and the constant part's expression (nullptr: none), or -1.
  int subscriptIterator(const ast::Expr& s, const ast::Expr*& offset, bool& negative) const {
    offset = nullptr;
    negative = false;
    if (auto* n = dyn_cast<NameExpr>(&s)) return iteratorIndex(*n);
    auto* b = dyn_cast<BinaryExpr>(&s);
    if (!b || (b->op != BinaryOp::Add && b->op != BinaryOp::Sub)) return -1;
    auto* l = dyn_cast<NameExpr>(b->lhs.get());
    if (int k = l ? iteratorIndex(*l) : -1; k >= 0 && !mentions(b->rhs.get(), its_)) {
      offset = b->rhs.get();
      negative = b->op == BinaryOp::Sub;
      return k;
    }
    auto* r = dyn_cast<NameExpr>(b->rhs.get());
    if (int k = r ? iteratorIndex(*r) : -1; k >= 0 && b->op == BinaryOp::Add && !mentions(b->lhs.get(), its_)) {
      offset = b->lhs.get();
      return k;
    }
    return -1;
  }

  int iteratorIndex(const NameExpr& n) const {  // innermost first (a definition's own iterator may shadow one)
    if (n.parts.size() != 1) return -1;
    for (size_t k = its_.size(); k-- > 0;)
      if (its_[k].name == n.parts[0]) return static_cast<int>(k);
    return -1;
  }

 private:
  const std::vector<TemplateIterator>& its_;

  bool isIterator(const NameExpr& n) const { return iteratorIndex(n) >= 0; }

  bool call(const CallExpr& c) const {
    static const char* const kAllowed[] = {"der", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh",
                                           "tanh", "exp", "log", "sqrt", "abs"};
    std::string name = c.callee->dotted();
    bool allowed = std::any_of(std::begin(kAllowed), std::end(kAllowed), [&](const char* a) { return name == a; });
    if (!allowed || c.args.size() != 1 || !c.namedArgs.empty()) return false;
    return body(*c.args[0]);
  }

  bool index(const IndexExpr& e) const {
    auto* base = dyn_cast<NameExpr>(e.base.get());
    if (!base || base->parts.size() != 1 || isIterator(*base)) return false;
    for (const auto& s : e.subscripts) {
      if (!mentions(s.get(), its_)) continue;
      const ast::Expr* offset;
      bool negative;
      if (subscriptIterator(*s, offset, negative) < 0) return false;
    }
    return true;
  }
};

namespace {

// True if the expression names one of the iterators anywhere.
bool mentions(const ast::Expr* e, const std::vector<TemplateIterator>& its) {
  if (!e) return false;
  switch (e->kind) {
    case ExprKind::Name: return TemplateCheck(its).iteratorIndex(*cast<NameExpr>(e)) >= 0;
    case ExprKind::Unary: return mentions(cast<UnaryExpr>(e)->operand.get(), its);
    case ExprKind::Binary:
      return mentions(cast<BinaryExpr>(e)->lhs.get(), its) || mentions(cast<BinaryExpr>(e)->rhs.get(), its);
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(e);
      return std::any_of(c->args.begin(), c->args.end(), [&](const ExprPtr& a) { return mentions(a.get(), its); });
    }
    case ExprKind::Index: {
      auto* x = cast<IndexExpr>(e);
      return mentions(x->base.get(), its) ||
             std::any_of(x->subscripts.begin(), x->subscripts.end(), [&](const ExprPtr& s) { return mentions(s.get(), its); });
    }
    case ExprKind::Number:
    case ExprKind::Bool:
    case ExprKind::String:
    case ExprKind::End: return false;
    default: return true;  // anything else: assume it may (the check then refuses the template)
  }
}

const CallExpr* sumCall(const ast::Expr& e) {
  auto* c = dyn_cast<CallExpr>(&e);
  if (!c || c->callee->dotted() != "sum" || c->args.size() != 1 || !c->namedArgs.empty()) return nullptr;
  return dyn_cast<ComprehensionExpr>(c->args[0].get()) ? c : nullptr;
}

}  // namespace

// The top-level summands of an energy statement or an output's binding, with their signs. A
// summand naming a scalar definition of this instance (`kinetic = T;` with `Real T = sum(…) + …;`)
// stands for the summands of its binding: definitions are substituted where they are used, so its
// sums are this statement's (outside `for` loops only, where no iterator can capture a name of the
// binding; a cycle of definitions is left to the usual lowering to report). A product or quotient
// with sums on one side only (`0.5*m*sum(…)`, `0.5*k*(x[1]^2 + sum(…))`, `sum(…)/n`) gives that
// side's summands the other side as a factor; elsewhere a product is one summand.
void Flattener::collectSummands(const ast::Expr& e, bool negated, std::vector<Summand::Factor>& factors,
                                std::vector<Summand>& out, std::vector<const ast::Declaration*>& through) {
  if (auto* b = dyn_cast<BinaryExpr>(&e); b && (b->op == BinaryOp::Add || b->op == BinaryOp::Sub)) {
    collectSummands(*b->lhs, negated, factors, out, through);
    collectSummands(*b->rhs, b->op == BinaryOp::Sub ? !negated : negated, factors, out, through);
    return;
  }
  if (auto* u = dyn_cast<UnaryExpr>(&e); u && u->op != UnaryOp::Not) {
    collectSummands(*u->operand, u->op == UnaryOp::Neg ? !negated : negated, factors, out, through);
    return;
  }
  if (auto* b = dyn_cast<BinaryExpr>(&e); b && (b->op == BinaryOp::Mul || b->op == BinaryOp::Div) && mayContainSum(e)) {
    const ast::Expr *factor = nullptr, *summands = nullptr;
    if (!mayContainSum(*b->rhs) && hasSumSummand(*b->lhs, through)) factor = b->rhs.get(), summands = b->lhs.get();
    else if (b->op == BinaryOp::Mul && !mayContainSum(*b->lhs) && hasSumSummand(*b->rhs, through))
      factor = b->lhs.get(), summands = b->rhs.get();
    if (factor) {
      factors.push_back({factor, b->op == BinaryOp::Div});
      collectSummands(*summands, negated, factors, out, through);
      factors.pop_back();
      return;
    }
  }
  // (at most kMaxInlined deep: a chain of definitions as long as the model is the work list's)
  constexpr size_t kMaxInlined = 8;
  const ast::Declaration* d = through.size() < kMaxInlined ? substitutedDefinition(e) : nullptr;
  if (d && std::find(through.begin(), through.end(), d) == through.end()) {
    inlined_.insert(&cur_->slots[cur_->cls->find(d->name)->index]);
    through.push_back(d);
    collectSummands(*d->binding, negated, factors, out, through);
    through.pop_back();
    return;
  }
  out.push_back({&e, negated, factors});
}

void Flattener::collectSummands(const ast::Expr& e, std::vector<Summand>& out, const ast::Declaration* own) {
  std::vector<const ast::Declaration*> through;
  if (own) through.push_back(own);
  std::vector<Summand::Factor> factors;
  collectSummands(e, false, factors, out, through);
}

// Whether some summand of e (collectSummands) is a sum(…) call.
bool Flattener::hasSumSummand(const ast::Expr& e, std::vector<const ast::Declaration*>& through) {
  std::vector<Summand> summands;
  std::vector<Summand::Factor> factors;
  std::set<const Instance::Slot*> inlined = inlined_;  // only looking: nothing is inlined yet
  collectSummands(e, false, factors, summands, through);
  inlined_ = std::move(inlined);
  return std::any_of(summands.begin(), summands.end(), [](const Summand& t) { return sumCall(*t.expr) != nullptr; });
}

// Whether e may contain a sum(…) call: one written in it, or a name of a definition (whose
// binding might have one). A factor must not: products of sums are not linear in either.
bool Flattener::mayContainSum(const ast::Expr& e) {
  switch (e.kind) {
    case ExprKind::Number:
    case ExprKind::Bool:
    case ExprKind::String:
    case ExprKind::End: return false;
    case ExprKind::Name: {
      auto* n = cast<NameExpr>(&e);
      const sema::ModelSymbol* s = n->parts.size() == 1 ? cur_->cls->find(n->parts[0]) : nullptr;
      return s && s->kind == sema::SymbolKind::Definition;
    }
    case ExprKind::Index: return mayContainSum(*cast<IndexExpr>(&e)->base);
    case ExprKind::Unary: return mayContainSum(*cast<UnaryExpr>(&e)->operand);
    case ExprKind::Binary: return mayContainSum(*cast<BinaryExpr>(&e)->lhs) || mayContainSum(*cast<BinaryExpr>(&e)->rhs);
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(&e);
      return c->callee->dotted() == "sum" || std::any_of(c->args.begin(), c->args.end(), [&](const ExprPtr& a) { return mayContainSum(*a); });
    }
    default: return true;
  }
}

// One summand: its sum kept as a template (true; `sum` has the body with the summand's sign and
// factors), or its value lowered (false; `value`). A factor makes the expanded template equal to
// the scalar lowering to rounding only (FlatModel::templatesRound).
bool Flattener::lowerSummand(const Summand& t, const char* what, IndexedSum& sum, Expr& value) {
  if (const CallExpr* c = sumCall(*t.expr); c && !m_.calls.count(c) && lowerIndexedSum(*c, t.negated, sum)) {
    sum.body = withFactors(sum.body, t);
    out_.templatesRound |= !t.factors.empty();
    return true;
  }
  Expr v = lowerScalar(*t.expr, what);
  value = withFactors(t.negated ? ctx_.neg(v) : v, t);
  out_.templatesRound |= !t.factors.empty();
  return false;
}

// v times the summand's factors, the innermost first (a*(b*v)).
Expr Flattener::withFactors(Expr v, const Summand& t) {
  for (auto f = t.factors.rbegin(); f != t.factors.rend(); ++f) {
    Expr x = lowerScalar(*f->expr, "a factor of a sum");
    v = f->divide ? ctx_.div(v, x) : ctx_.mul(x, v);
  }
  return v;
}

// The declaration a plain name `T` stands for where its own binding is its value: a scalar
// definition of the current instance, not an output, that no modifier binds, outside loops; else
// nullptr.
const ast::Declaration* Flattener::substitutedDefinition(const ast::Expr& e) {
  auto* n = dyn_cast<NameExpr>(&e);
  if (!n || n->parts.size() != 1 || !iterators_.empty() || !templateIterators_.empty()) return nullptr;
  const sema::ModelSymbol* s = cur_->cls->find(n->parts[0]);
  // (not an output: where the scalar lowering resolves one, its column comes first)
  if (!s || s->kind != sema::SymbolKind::Definition || s->decl->causality == Causality::Output || !s->decl->binding ||
      !s->decl->typeDims.empty() || !s->decl->dims.empty())
    return nullptr;
  return modifierOf(*cur_, *s->decl) ? nullptr : s->decl;
}

// Whether an expression reads nothing but numbers, `time`, the comprehensions' own iterators and
// the current instance's coordinates, parameters and constants declared before declaration
// `declaredBefore` (by plain names; der() of a coordinate is its velocity, made with it): lowering
// it makes no variable and resolves no declaration not resolved already, so when it is lowered
// does not matter.
bool Flattener::readsOnlyCoordinatesAndData(const ast::Expr& e, std::vector<std::string>& its, int declaredBefore) {
  auto all = [&](const std::vector<ExprPtr>& es) {
    return std::all_of(es.begin(), es.end(), [&](const ExprPtr& x) { return !x || readsOnlyCoordinatesAndData(*x, its, declaredBefore); });
  };
  switch (e.kind) {
    case ExprKind::Number:
    case ExprKind::Bool:
    case ExprKind::String:
    case ExprKind::End: return true;
    case ExprKind::Name: {
      auto* n = cast<NameExpr>(&e);
      if (n->parts.size() != 1) return false;
      if (std::find(its.begin(), its.end(), n->parts[0]) != its.end()) return true;
      const sema::ModelSymbol* s = cur_->cls->find(n->parts[0]);
      if (!s) return n->parts[0] == "time";
      bool data = s->kind == sema::SymbolKind::Coordinate || s->kind == sema::SymbolKind::Parameter ||
                  s->kind == sema::SymbolKind::IntegerParameter || s->kind == sema::SymbolKind::Constant;
      return data && s->index < declaredBefore;
    }
    case ExprKind::Index: {
      auto* x = cast<IndexExpr>(&e);
      return readsOnlyCoordinatesAndData(*x->base, its, declaredBefore) && all(x->subscripts);
    }
    case ExprKind::Unary: return readsOnlyCoordinatesAndData(*cast<UnaryExpr>(&e)->operand, its, declaredBefore);
    case ExprKind::Binary:
      return readsOnlyCoordinatesAndData(*cast<BinaryExpr>(&e)->lhs, its, declaredBefore) &&
             readsOnlyCoordinatesAndData(*cast<BinaryExpr>(&e)->rhs, its, declaredBefore);
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(&e);
      return all(c->args) && std::all_of(c->namedArgs.begin(), c->namedArgs.end(), [&](const NamedArg& a) {
               return !a.value || readsOnlyCoordinatesAndData(*a.value, its, declaredBefore);
             });
    }
    case ExprKind::Range: {
      auto* r = cast<RangeExpr>(&e);
      return (!r->start || readsOnlyCoordinatesAndData(*r->start, its, declaredBefore)) &&
             (!r->step || readsOnlyCoordinatesAndData(*r->step, its, declaredBefore)) && (!r->stop || readsOnlyCoordinatesAndData(*r->stop, its, declaredBefore));
    }
    case ExprKind::Array: return all(cast<ArrayExpr>(&e)->elements);
    case ExprKind::Comprehension: {
      auto* c = cast<ComprehensionExpr>(&e);
      size_t outer = its.size();
      bool ok = true;
      for (const auto& it : c->iterators) {
        ok = ok && (!it.range || readsOnlyCoordinatesAndData(*it.range, its, declaredBefore));
        its.push_back(it.name);
      }
      ok = ok && readsOnlyCoordinatesAndData(*c->body, its, declaredBefore);
      its.resize(outer);
      return ok;
    }
    case ExprKind::If: {
      auto* f = cast<IfExpr>(&e);
      return all(f->conditions) && all(f->values) && (!f->elseValue || readsOnlyCoordinatesAndData(*f->elseValue, its, declaredBefore));
    }
    default: return false;
  }
}

// A scalar definition (not an output) whose binding has sums as summands, or an array bound to a
// comprehension, that reads only coordinates and data (readsOnlyCoordinatesAndData): with
// templates, an energy statement or an output that names it lowers its binding summand by summand
// (collectSummands), a sum that reads an element lowers that element (lowerDefinitionElement), so
// resolving it at its declaration would only expand it for nothing. It waits (deferred_): still unused
// after everything else, it is resolved then (for its diagnostics), unless a statement inlined it.
bool Flattener::defersDefinition(Instance& inst, const sema::ModelSymbol& s) {
  const ast::Declaration& d = *s.decl;
  if (s.kind != sema::SymbolKind::Definition || d.causality == Causality::Output || !d.binding || modifierOf(inst, d))
    return false;
  std::vector<std::string> its;
  if (!readsOnlyCoordinatesAndData(*d.binding, its, s.index)) return false;
  // An array bound to a comprehension, which templates read element by element (lowerDefinitionElement).
  if (d.typeDims.size() + d.dims.size() == 1) {
    auto* c = dyn_cast<ComprehensionExpr>(d.binding.get());
    auto* range = c && c->iterators.size() == 1 ? dyn_cast<RangeExpr>(c->iterators[0].range.get()) : nullptr;
    if (!range || !range->start || !range->stop || range->step) return false;
    deferred_.push_back({&inst, &s});
    return true;
  }
  if (!d.typeDims.empty() || !d.dims.empty()) return false;
  std::vector<Summand> summands;  // (no definition to go through: it reads none)
  collectSummands(*d.binding, summands, &d);
  if (std::none_of(summands.begin(), summands.end(), [](const Summand& t) { return sumCall(*t.expr) != nullptr; }))
    return false;
  deferred_.push_back({&inst, &s});
  return true;
}

void Flattener::addTermsKeepingLoops(std::vector<Term>& into, const MechanicsStmt& st, const char* what) {
  std::vector<Summand> summands;
  collectSummands(*st.value, summands, nullptr);
  std::vector<Expr> scalars;
  std::vector<IndexedSum> sums;
  for (const Summand& s : summands) {
    IndexedSum sum;
    Expr value = nullptr;
    if (lowerSummand(s, what, sum, value)) sums.push_back(std::move(sum));
    else scalars.push_back(value);
  }
  IndexedSum::Energy energy = st.kind == MechanicsKind::Kinetic     ? IndexedSum::Energy::Kinetic
                              : st.kind == MechanicsKind::Potential ? IndexedSum::Energy::Potential
                                                                    : IndexedSum::Energy::Dissipation;
  for (IndexedSum& sum : sums) {
    sum.energy = energy;
    sum.term = static_cast<int>(into.size());
    out_.indexedSums.push_back(std::move(sum));
  }
  into.push_back({ctx_.add(scalars), st.range});
}

// A scalar `output Real y = …` of the model whose binding has `sum(… for i in a:b)` summands:
// the output with the sums a loop can compute kept as templates (Output::sums), its value the other
// summands; false (nothing lowered) where the declaration is lowered as usual — not the model's
// own, not a scalar output definition, modified, or no sum kept. The declaration itself stays
// unresolved: a use of it elsewhere resolves it as usual (keptOutputs_ then expands the output).
bool Flattener::lowerOutputKeepingSums(Instance& inst, const sema::ModelSymbol& s) {
  const ast::Declaration& d = *s.decl;
  Instance::Slot& slot = inst.slots[s.index];
  if (&inst != &instances_.front() || s.kind != sema::SymbolKind::Definition || d.causality != Causality::Output ||
      !d.binding || !d.typeDims.empty() || !d.dims.empty() || slot.state != Instance::Slot::Empty ||
      modifierOf(inst, d))
    return false;
  std::vector<Summand> summands;
  collectSummands(*d.binding, summands, &d);
  auto isSum = [&](const Summand& t) { const CallExpr* c = sumCall(*t.expr); return c && !m_.calls.count(c); };
  if (std::none_of(summands.begin(), summands.end(), isSum)) return false;
  slot.state = Instance::Slot::Pending;  // a binding that reads its own output is a cycle (E0312)
  bool rounded = out_.templatesRound;
  std::vector<Expr> scalars;
  std::vector<IndexedTerm> sums;
  try {
    for (const Summand& t : summands) {
      IndexedSum sum;
      Expr value = nullptr;
      if (lowerSummand(t, "an output", sum, value)) sums.push_back({std::move(sum.box), {}, sum.body});
      else scalars.push_back(value);
    }
  } catch (...) {
    slot.state = Instance::Slot::Failed;
    throw;
  }
  slot.state = Instance::Slot::Empty;
  if (sums.empty()) {  // lowered as usual (again: its side effects are made already, in the same order)
    out_.templatesRound = rounded;
    return false;
  }
  keptOutputs_[&slot] = out_.outputs.size();
  out_.outputs.push_back({d.name, ctx_.add(scalars), d.nameRange, outputKind(d), std::move(sums)});
  return true;
}

// `z = … + sum(…)` in the model's equations, z a scalar unknown of the model: the equation with
// the sums of its right side kept (FlatModel::equationSums) where one of them reads coordinates or
// velocities — z is then no alias, and the pipeline makes the equation z's definition, an output
// (driver/Pipeline.cpp), or expands the sums. Sums over parameters only are expanded here (the
// equation may make z an alias); false (nothing recorded) where no sum was kept.
bool Flattener::lowerEquationKeepingSums(const ast::Equation& eq, std::vector<Equation>& into) {
  auto* name = dyn_cast<NameExpr>(eq.lhs.get());
  const sema::ModelSymbol* z = name && name->parts.size() == 1 ? cur_->cls->find(name->parts[0]) : nullptr;
  if (!z || z->kind != sema::SymbolKind::Unknown || !z->decl->typeDims.empty() || !z->decl->dims.empty()) return false;
  std::vector<Summand> summands;
  collectSummands(*eq.rhs, summands, nullptr);
  if (std::none_of(summands.begin(), summands.end(), [](const Summand& t) { return sumCall(*t.expr) != nullptr; }))
    return false;
  bool rounded = out_.templatesRound;
  Expr lhs = lowerScalar(*eq.lhs, "an equation");
  std::vector<Expr> scalars;
  std::vector<IndexedTerm> sums;
  for (const Summand& t : summands) {
    IndexedSum sum;
    Expr value = nullptr;
    if (lowerSummand(t, "an equation", sum, value)) sums.push_back({std::move(sum.box), {}, sum.body});
    else scalars.push_back(value);
  }
  auto readsStates = [&](const IndexedTerm& sum) {
    for (Expr s : ctx_.freeSymbols(sum.body))
      if (const RelativeElement* rel = out_.relativeElement(s)) {
        int var = out_.variableOf(out_.patterns->arrays[rel->array].elements[0]);
        if (var >= 0 && out_.variables[var].role != VarRole::Parameter) return true;
      }
    return false;
  };
  if (std::none_of(sums.begin(), sums.end(), readsStates)) {
    out_.templatesRound = rounded;
    return false;  // lowered as usual (again: its side effects are made already, in the same order)
  }
  countScalars(1, eq.range);
  Expr rhs = ctx_.add(scalars);
  into.push_back({ctx_.sub(lhs, rhs), {OriginKind::Equation, eq.range, -1, "", cur_->index}, lhs, rhs});
  out_.equationSums.push_back({into.size() - 1, std::move(sums)});
  return true;
}

// Appends a loop's iterator `a:b` to `its` if it can be a template's: plain integer bounds that
// name no earlier iterator, a range that is not empty, a name not taken by an earlier iterator.
bool Flattener::addTemplateIterator(const ast::Iterator& it, std::vector<TemplateIterator>& its) {
  auto* r = dyn_cast<RangeExpr>(it.range.get());
  if (!r || !r->start || !r->stop || r->step) return false;
  if (mentions(r->start.get(), its) || mentions(r->stop.get(), its)) return false;
  if (std::any_of(its.begin(), its.end(), [&](const TemplateIterator& o) { return o.name == it.name; })) return false;
  // Bounds that are not plain integers (1:1e300, 1:2.5) are the scalar lowering's to report.
  Expr lo = lowerScalar(*r->start, "a loop range"), hi = lowerScalar(*r->stop, "a loop range");
  auto plain = [](Expr v) { return v->isConstant() && std::abs(v->value) < 1e9 && v->value == std::floor(v->value); };
  if (!plain(lo) || !plain(hi) || hi->value < lo->value) return false;  // an empty loop: the scalar lowering's nothing
  its.push_back({it.name, static_cast<long>(lo->value), static_cast<long>(hi->value)});
  return true;
}

// e lowered with `its` as the template's iterators (relative symbols for their subscripts), or
// nullopt where it is no template (NotATemplate: the scalar lowering takes over); the iterators are
// cleared on every way out. `unknownRates`: der() of an array of unknowns is an array (for equations).
std::optional<Expr> Flattener::lowerTemplated(const ast::Expr& e, const std::vector<TemplateIterator>& its, const char* what,
                                              bool unknownRates) {
  templateIterators_ = its;
  ratesOfUnknowns_ = unknownRates;
  struct Clear {
    Flattener& f;
    ~Clear() { f.templateIterators_.clear(), f.ratesOfUnknowns_ = false; }
  } clear{*this};
  try {
    return lowerScalar(e, what);
  } catch (NotATemplate&) {
    return std::nullopt;
  }
}

// Lowers the sum as a template; false (nothing reported, nothing recorded) where the scalar
// lowering must do it.
bool Flattener::lowerIndexedSum(const CallExpr& call, bool negated, IndexedSum& sum) {
  const auto& comp = *cast<ComprehensionExpr>(call.args[0].get());
  std::vector<TemplateIterator> its;
  for (const auto& it : comp.iterators)
    if (!addTemplateIterator(it, its)) return false;
  if (!TemplateCheck(its).body(*comp.body)) return false;
  std::optional<Expr> body = lowerTemplated(*comp.body, its, "the terms of a sum");
  if (!body) return false;
  sum.body = negated ? ctx_.neg(*body) : *body;
  for (const auto& it : its) sum.box.push_back({it.first, it.last});
  sum.range = call.range;
  return true;
}

// --- for equations (FlattenLimits::keepForEquations) ---

namespace {

// `der(x[i, j])` with i, j the template's iterators in order: the element a row of the template
// defines the derivative of.
bool isOwnDerivative(const ast::Expr& e, const TemplateCheck& check, size_t iterators) {
  auto* c = dyn_cast<CallExpr>(&e);
  if (!c || c->callee->dotted() != "der" || c->args.size() != 1 || !c->namedArgs.empty()) return false;
  auto* x = dyn_cast<IndexExpr>(c->args[0].get());
  auto* base = x ? dyn_cast<NameExpr>(x->base.get()) : nullptr;
  if (!base || base->parts.size() != 1 || check.iteratorIndex(*base) >= 0 || x->subscripts.size() != iterators) return false;
  for (size_t d = 0; d < iterators; ++d) {
    auto* s = dyn_cast<NameExpr>(x->subscripts[d].get());
    if (!s || check.iteratorIndex(*s) != static_cast<int>(d)) return false;
  }
  return true;
}

// Collects the der() calls of an expression; false if it has a part no template can hold (the
// precise check is TemplateCheck's).
bool collectDerCalls(const ast::Expr& e, std::vector<const CallExpr*>& calls) {
  switch (e.kind) {
    case ExprKind::Number:
    case ExprKind::Name: return true;
    case ExprKind::Unary: return collectDerCalls(*cast<UnaryExpr>(&e)->operand, calls);
    case ExprKind::Binary:
      return collectDerCalls(*cast<BinaryExpr>(&e)->lhs, calls) && collectDerCalls(*cast<BinaryExpr>(&e)->rhs, calls);
    case ExprKind::Index: {
      auto* x = cast<IndexExpr>(&e);
      for (const auto& s : x->subscripts)
        if (!collectDerCalls(*s, calls)) return false;
      return collectDerCalls(*x->base, calls);
    }
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(&e);
      if (c->callee->dotted() == "der") calls.push_back(c);
      for (const auto& a : c->args)
        if (!collectDerCalls(*a, calls)) return false;
      return c->namedArgs.empty();
    }
    default: return false;
  }
}

// The der() calls of a simple equation: none (an algebraic row) or one; nullopt for more, or for
// an equation of another kind.
std::optional<const CallExpr*> derCallOf(const ast::Equation& eq) {
  if (eq.kind != EquationKind::Simple || !eq.lhs || !eq.rhs) return std::nullopt;
  std::vector<const CallExpr*> calls;
  if (!collectDerCalls(*eq.lhs, calls) || !collectDerCalls(*eq.rhs, calls) || calls.size() > 1) return std::nullopt;
  return calls.empty() ? nullptr : calls[0];
}

}  // namespace

bool mayKeepForEquation(const ast::Equation& loop) {
  if (loop.kind == EquationKind::For)
    return !loop.body.empty() && std::all_of(loop.body.begin(), loop.body.end(), mayKeepForEquation);
  std::optional<const CallExpr*> der = derCallOf(loop);
  return der && (!*der || ((*der)->args.size() == 1 && dyn_cast<IndexExpr>((*der)->args[0].get())));
}

bool namesDerivatives(const ast::Equation& loop) {
  if (loop.kind == EquationKind::For) return std::any_of(loop.body.begin(), loop.body.end(), namesDerivatives);
  std::optional<const CallExpr*> der = derCallOf(loop);
  return der && *der;
}

// The iterators of a top-level `for` equation and of the loops nested in it while each loop holds
// only the next (`for i … loop for j … loop … end for; end for`); `innermost` becomes the loop whose
// body holds the equations. nullopt where a loop cannot be a template's.
std::optional<std::vector<TemplateIterator>> Flattener::equationTemplateIterators(const ast::Equation*& innermost) {
  std::vector<TemplateIterator> its;
  for (const ast::Equation* loop = innermost;; loop = &loop->body[0]) {
    for (const auto& it : loop->iterators)
      if (!addTemplateIterator(it, its)) return std::nullopt;
    innermost = loop;
    if (loop->body.size() != 1 || loop->body[0].kind != EquationKind::For) return its;
  }
}

// Every equation of the loop as a template, or false (nothing recorded) where the scalar lowering
// must do the loop: an equation that names no derivative or more than one, or one of another
// element than `der(x[i, …])` (the iterators in order), a side TemplateCheck refuses, a subscript
// out of bounds.
bool Flattener::lowerEquationTemplates(const ast::Equation& loop) {
  const ast::Equation* innermost = &loop;
  std::optional<std::vector<TemplateIterator>> its = equationTemplateIterators(innermost);
  if (!its || innermost->body.empty()) return false;
  std::vector<EquationTemplate> templates;
  for (const auto& eq : innermost->body) {
    std::optional<EquationTemplate> t = lowerEquationTemplate(eq, *its);
    if (!t) return false;
    templates.push_back(std::move(*t));
  }
  countScalars(pointCount(templates[0].box) * templates.size(), loop.range);
  for (EquationTemplate& t : templates) out_.equationTemplates.push_back(std::move(t));
  return true;
}

std::optional<EquationTemplate> Flattener::lowerEquationTemplate(const ast::Equation& eq,
                                                                 const std::vector<TemplateIterator>& its) {
  TemplateCheck check(its);
  std::optional<const CallExpr*> der = derCallOf(eq);
  if (!der || (*der && !isOwnDerivative(**der, check, its.size())) || !check.body(*eq.lhs) || !check.body(*eq.rhs))
    return std::nullopt;
  EquationTemplate t;
  std::optional<Expr> lhs = lowerTemplated(*eq.lhs, its, "the left side of an equation", true);
  std::optional<Expr> rhs = lhs ? lowerTemplated(*eq.rhs, its, "the right side of an equation", true) : std::nullopt;
  if (!rhs) return std::nullopt;
  t.lhs = *lhs, t.rhs = *rhs;
  for (const auto& it : its) t.box.push_back({it.first, it.last});
  t.origin = {OriginKind::Equation, eq.range, -1, "", cur_->index};
  return t;
}

// --- forces in `for` loops (FlattenLimits::keepLoops) ---

// Every statement of a top-level mechanics loop (and of the loops nested in it while each holds only
// the next) as a template: a force on `x[i + o, …]`, x an array of coordinates subscripted by the
// iterators in order, or an energy statement (a sum over the loop's box); or false (nothing
// recorded) where the scalar lowering must do the loop.
bool Flattener::lowerMechanicsLoop(const MechanicsStmt& loop) {
  std::vector<TemplateIterator> its;
  const MechanicsStmt* inner = &loop;
  for (;;) {
    for (const auto& it : inner->iterators)
      if (!addTemplateIterator(it, its)) return false;
    if (inner->body.size() != 1 || inner->body[0].kind != MechanicsKind::For) break;
    inner = &inner->body[0];
  }
  if (inner->body.empty()) return false;
  std::vector<IndexedForce> forces;
  std::vector<std::pair<const MechanicsStmt*, IndexedSum>> energies;
  for (const MechanicsStmt& st : inner->body) {
    if (st.kind != MechanicsKind::Force) {
      std::optional<IndexedSum> sum = lowerEnergyTemplate(st, its);
      if (!sum) return false;
      energies.push_back({&st, std::move(*sum)});
      continue;
    }
    std::optional<IndexedForce> f = lowerForceTemplate(st, its);
    if (!f) return false;
    forces.push_back(std::move(*f));
  }
  Box box;
  for (const auto& it : its) box.push_back({it.first, it.last});
  countScalars(pointCount(box) * inner->body.size(), loop.range);
  size_t first = out_.indexedForces.size();
  for (IndexedForce& f : forces) f.position = out_.forces.size(), f.first = first, out_.indexedForces.push_back(std::move(f));
  // Each energy statement: one term its sum adds to (the scalar lowering's term per point and
  // statement; expanded, equal to it to rounding, so the fallback flattens again).
  for (auto& [st, sum] : energies) {
    std::vector<Term>& into = st->kind == MechanicsKind::Kinetic     ? out_.kinetic
                              : st->kind == MechanicsKind::Potential ? out_.potential
                                                                     : out_.dissipation;
    sum.term = static_cast<int>(into.size());
    into.push_back({ctx_.zero(), st->range});
    out_.indexedSums.push_back(std::move(sum));
    out_.templatesRound = true;
  }
  return true;
}

// `kinetic = e;` (potential, dissipation) inside a template loop: the sum of e over the loop's box.
std::optional<IndexedSum> Flattener::lowerEnergyTemplate(const MechanicsStmt& st, const std::vector<TemplateIterator>& its) {
  if (st.kind != MechanicsKind::Kinetic && st.kind != MechanicsKind::Potential && st.kind != MechanicsKind::Dissipation)
    return std::nullopt;
  if (!st.value || !TemplateCheck(its).body(*st.value)) return std::nullopt;
  IndexedSum sum;
  sum.energy = st.kind == MechanicsKind::Kinetic     ? IndexedSum::Energy::Kinetic
               : st.kind == MechanicsKind::Potential ? IndexedSum::Energy::Potential
                                                     : IndexedSum::Energy::Dissipation;
  std::optional<Expr> body = lowerTemplated(*st.value, its, "an energy");
  if (!body) return std::nullopt;
  sum.body = *body;
  for (const auto& it : its) sum.box.push_back({it.first, it.last});
  sum.range = st.range;
  return sum;
}

std::optional<IndexedForce> Flattener::lowerForceTemplate(const MechanicsStmt& st, const std::vector<TemplateIterator>& its) {
  TemplateCheck check(its);
  if (!st.target || !st.value || st.at || !isa<IndexExpr>(st.target.get()) || !check.body(*st.target) ||
      !check.body(*st.value))
    return std::nullopt;
  IndexedForce f;
  std::optional<Expr> target = lowerTemplated(*st.target, its, "the coordinate of a force");
  std::optional<Expr> body = target ? lowerTemplated(*st.value, its, "a force") : std::nullopt;
  if (!body) return std::nullopt;
  f.target = *target, f.body = *body;
  const RelativeElement* rel = out_.patterns->find(f.target);
  if (!rel || rel->dims.size() != its.size()) return std::nullopt;
  for (size_t d = 0; d < rel->dims.size(); ++d)
    if (rel->dims[d].iterator != static_cast<int>(d)) return std::nullopt;
  int var = out_.variableOf(out_.patterns->arrays[rel->array].elements[0]);
  if (var < 0 || out_.variables[var].role != VarRole::Coordinate) return std::nullopt;  // the scalar lowering reports it
  for (const auto& it : its) f.box.push_back({it.first, it.last});
  f.range = st.range;
  return f;
}

// x[i+1] inside a template: the relative symbol of that pattern (nullopt: no iterator in the
// subscripts, an ordinary subscript).
std::optional<Value> Flattener::lowerRelativeIndex(const IndexExpr& e) {
  if (!mentions(&e, templateIterators_)) return std::nullopt;
  if (const ComprehensionExpr* binding = elementwiseDefinition(e)) return lowerDefinitionElement(e, *binding);
  Value holder;
  const Value& base = subscriptBase(*e.base, holder);
  if (&base == &holder || e.subscripts.size() != base.shape.size()) throw NotATemplate{};
  RelativeElement rel;
  TemplateCheck check(templateIterators_);
  for (size_t d = 0; d < e.subscripts.size(); ++d) {
    const ast::Expr* offsetExpr;
    bool negative;
    int k = check.subscriptIterator(*e.subscripts[d], offsetExpr, negative);
    long offset = 0;
    if (k < 0) {
      offset = plainInteger(*e.subscripts[d]);
    } else if (offsetExpr) {
      offset = plainInteger(*offsetExpr);
      if (negative) offset = -offset;
    }
    if (k >= 0 && templateIterators_[k].alias >= 0) offset += templateIterators_[k].shift, k = templateIterators_[k].alias;
    long lo = k < 0 ? offset : templateIterators_[k].first + offset;
    long hi = k < 0 ? offset : templateIterators_[k].last + offset;
    if (lo < 1 || hi > base.shape[d]) throw NotATemplate{};  // the scalar lowering reports it
    rel.dims.push_back({k, static_cast<int>(offset)});
  }
  rel.array = arrayOf(base, cast<NameExpr>(e.base.get())->parts[0]);
  return Value::scalar(relativeSymbol(rel));
}

// `px[i + o]` where px is a one-dimensional definition of this instance bound (unmodified) to a
// comprehension `{body for j in a:b}`: that comprehension, else nullptr.
const ComprehensionExpr* Flattener::elementwiseDefinition(const IndexExpr& e) {
  auto* name = dyn_cast<NameExpr>(e.base.get());
  if (!name || name->parts.size() != 1 || e.subscripts.size() != 1 || !iterators_.empty() ||
      TemplateCheck(templateIterators_).iteratorIndex(*name) >= 0)
    return nullptr;
  const sema::ModelSymbol* s = cur_->cls->find(name->parts[0]);
  if (!s || s->kind != sema::SymbolKind::Definition || !s->decl->binding || s->decl->typeDims.size() + s->decl->dims.size() != 1 ||
      modifierOf(*cur_, *s->decl))
    return nullptr;
  auto* c = dyn_cast<ComprehensionExpr>(s->decl->binding.get());
  auto* range = c && c->iterators.size() == 1 ? dyn_cast<RangeExpr>(c->iterators[0].range.get()) : nullptr;
  return range && range->start && range->stop && !range->step ? c : nullptr;
}

// The element of such a definition at the template's point: its comprehension's body with j the
// template iterator plus the subscript's offset (shifted by the range's start), lowered as part of
// the template — so a sum over `px[i]` reads the coordinates px is made of, as if written out.
// Where that is not a template (a constant subscript, a range out of bounds, a body TemplateCheck
// refuses), the element is lowered as usual (nullopt) or the template is refused (NotATemplate).
std::optional<Value> Flattener::lowerDefinitionElement(const IndexExpr& e, const ComprehensionExpr& binding) {
  const ast::Expr* offsetExpr;
  bool negative;
  TemplateCheck check(templateIterators_);
  int k = check.subscriptIterator(*e.subscripts[0], offsetExpr, negative);
  if (k < 0) throw NotATemplate{};
  long offset = offsetExpr ? (negative ? -plainInteger(*offsetExpr) : plainInteger(*offsetExpr)) : 0;
  if (templateIterators_[k].alias >= 0) offset += templateIterators_[k].shift, k = templateIterators_[k].alias;
  const ast::Iterator& j = binding.iterators[0];
  const auto& range = *cast<RangeExpr>(j.range.get());
  // (names of the binding are the definition's: none may be taken for a template's iterator)
  std::vector<TemplateIterator> outer;  // those the binding's own iterator does not shadow
  for (const TemplateIterator& it : templateIterators_)
    if (it.name != j.name) outer.push_back(it);
  if (mentions(range.start.get(), templateIterators_) || mentions(range.stop.get(), templateIterators_) ||
      mentions(binding.body.get(), outer))
    throw NotATemplate{};
  long a = plainInteger(*range.start), b = plainInteger(*range.stop);
  if (templateIterators_[k].first + offset < 1 || templateIterators_[k].last + offset > b - a + 1) throw NotATemplate{};
  templateIterators_.push_back({j.name, templateIterators_[k].first + offset + a - 1, templateIterators_[k].last + offset + a - 1,
                                k, offset + a - 1});
  struct Pop {
    std::vector<TemplateIterator>& its;
    ~Pop() { its.pop_back(); }
  } pop{templateIterators_};
  if (!TemplateCheck(templateIterators_).body(*binding.body)) throw NotATemplate{};
  Value element = Value::scalar(lowerScalar(*binding.body, "an element of a definition"));
  inlined_.insert(&cur_->slots[cur_->cls->find(cast<NameExpr>(e.base.get())->parts[0])->index]);
  return element;
}

// A subscript's constant part as an integer; anything else (a range, `end`, 1.5) is the scalar
// lowering's to take (and to report).
long Flattener::plainInteger(const ast::Expr& e) {
  if (e.kind == ExprKind::Range || e.kind == ExprKind::End || e.kind == ExprKind::Comprehension) throw NotATemplate{};
  Expr v = lowerScalar(e, "a subscript");
  if (!v->isConstant() || std::abs(v->value) >= 1e9 || v->value != std::floor(v->value)) throw NotATemplate{};
  return static_cast<long>(v->value);
}

int Flattener::arrayOf(const Value& declared, const std::string& name) {
  auto [it, added] = arrayIds_.try_emplace(&declared, static_cast<int>(out_.patterns->arrays.size()));
  if (!added) return it->second;
  std::string unique = name;
  auto taken = [&](const std::string& n) {
    return std::any_of(out_.patterns->arrays.begin(), out_.patterns->arrays.end(), [&](const ArrayVariable& a) { return a.name == n; });
  };
  for (int k = 2; taken(unique); ++k) unique = name + "#" + std::to_string(k);
  out_.patterns->arrays.push_back({unique, declared.shape, std::vector<Expr>(declared.elems.begin(), declared.elems.end())});
  return it->second;
}

Expr Flattener::relativeSymbol(const RelativeElement& rel) { return out_.patterns->symbol(ctx_, rel); }

// der(x[%1+1]) = der(x)[%1+1]: the array of the elements' derivatives, made once. Only arrays of
// coordinates and velocities (whose derivatives every element has in the scalar lowering too), of
// parameters and constants (derivative 0), and in an equation template of unknowns (every element
// gets its der(): the model is templated only if each is then defined by an equation).
Expr Flattener::rateOfRelative(const RelativeElement& rel) {
  ArrayVariable& a = out_.patterns->arrays[rel.array];
  if (a.derivative < 0) {
    std::vector<Expr> rates;
    bool constant = true, moving = true, unknowns = ratesOfUnknowns_, made = true;
    for (Expr e : a.elements) {
      int var = out_.variableOf(e);
      VarRole role = var >= 0 ? out_.variables[var].role : VarRole::Parameter;
      bool isConstant = e->isConstant() || (var >= 0 && role == VarRole::Parameter);
      bool isMoving = var >= 0 && (role == VarRole::Coordinate || role == VarRole::Velocity);
      constant &= isConstant;
      moving &= isMoving;
      unknowns &= var >= 0 && role == VarRole::Unknown;
      made &= var >= 0 && out_.variables[var].derivative >= 0;
    }
    if (constant) return ctx_.zero();
    if (!moving && !unknowns) throw NotATemplate{};
    if (made) {  // a coordinate array's velocities and accelerations exist already: read them
      rates.resize(a.elements.size());
      inTwoHalves(rates.size(), [&](size_t first, size_t last) {
        for (size_t k = first; k < last; ++k)
          rates[k] = out_.variables[out_.variables[out_.variableOf(a.elements[k])].derivative].symbol;
      });
    } else {
      rates = derivativeSymbols(a.elements, derivativeSite_);
    }
    int id = static_cast<int>(out_.patterns->arrays.size());
    out_.patterns->arrays.push_back({"der(" + a.name + ")", a.shape, std::move(rates)});
    out_.patterns->arrays[rel.array].derivative = id;
  }
  RelativeElement d = rel;
  d.array = out_.patterns->arrays[rel.array].derivative;
  return relativeSymbol(d);
}

Expr ElementPatterns::symbol(sym::Context& ctx, const RelativeElement& rel) {
  std::string name = arrays[rel.array].name;
  name += '[';
  for (size_t d = 0; d < rel.dims.size(); ++d) {
    if (d) name += ',';
    const auto& dim = rel.dims[d];
    if (dim.iterator >= 0) {
      name += '%';
      name += std::to_string(dim.iterator + 1);
      if (dim.offset > 0) name += '+';
    }
    if (dim.iterator < 0 || dim.offset) name += std::to_string(dim.offset);
  }
  name += ']';
  Expr s = ctx.symbol(name);
  elements_.try_emplace(s->symbolId, rel);
  return s;
}

Expr ElementPatterns::iteratorSymbol(sym::Context& ctx, int k) {
  if (iterators_.size() <= static_cast<size_t>(k)) iterators_.resize(k + 1, nullptr);
  if (!iterators_[k]) iterators_[k] = ctx.symbol("%" + std::to_string(k + 1));
  return iterators_[k];
}

bool ElementPatterns::readsIterator(const sym::Context& ctx, Expr e) const {
  if (iterators_.empty()) return false;
  for (Expr s : ctx.freeSymbols(e))
    if (iteratorOf(s) >= 0) return true;
  return false;
}

Expr ElementPatterns::elementAt(const RelativeElement& rel, std::span<const long> point) const {
  const ArrayVariable& a = arrays[rel.array];
  size_t flat = 0;
  for (size_t d = 0; d < rel.dims.size(); ++d) {
    long sub = rel.dims[d].offset + (rel.dims[d].iterator < 0 ? 0 : point[rel.dims[d].iterator]);
    flat = flat * a.shape[d] + static_cast<size_t>(sub - 1);
  }
  return a.elements[flat];
}

Expr instantiate(const FlatModel& model, sym::Context& ctx, Expr body, std::span<const long> point) {
  std::unordered_map<Expr, Expr> map;
  for (Expr s : ctx.freeSymbols(body))
    if (const RelativeElement* rel = model.relativeElement(s)) map.emplace(s, model.patterns->elementAt(*rel, point));
    else if (int k = model.patterns->iteratorOf(s); k >= 0) map.emplace(s, ctx.constant(static_cast<double>(point[k])));
  return ctx.substitute(body, map);
}

bool loopableParameters(const FlatModel& m, const RelativeElement& rel, size_t rank, std::span<const int> shape) {
  const ArrayVariable& a = m.patterns->arrays[rel.array];
  if (rel.dims.size() != rank || a.elements.empty()) return false;
  if (rank > 1 && !std::equal(a.shape.begin(), a.shape.end(), shape.begin(), shape.end())) return false;
  for (size_t d = 0; d < rank; ++d)
    if (rel.dims[d].iterator != static_cast<int>(d)) return false;
  int first = m.variableOf(a.elements[0]);
  for (size_t k = 0; k < a.elements.size(); ++k) {
    int var = m.variableOf(a.elements[k]);
    if (first < 0 || var != first + static_cast<int>(k) || m.variables[var].role != VarRole::Parameter) return false;
  }
  return true;
}

Expr withSumsExpanded(const FlatModel& model, sym::Context& ctx, Expr value, const std::vector<IndexedTerm>& sums) {
  for (const IndexedTerm& sum : sums) {
    std::vector<Expr> parts;
    parts.reserve(pointCount(sum.box));
    forEachPoint(sum.box, [&](std::span<const long> point, size_t) { parts.push_back(instantiate(model, ctx, sum.body, point)); });
    value = ctx.add(value, ctx.add(parts));
  }
  return value;
}

void expandEquationSums(FlatModel& model, sym::Context& ctx) {
  for (const auto& [index, sums] : model.equationSums) {
    Equation& e = model.equations[index];
    e.rhs = withSumsExpanded(model, ctx, e.rhs, sums);
    e.residual = ctx.sub(e.lhs, e.rhs);
  }
  model.equationSums.clear();
}

void expandIndexedSums(FlatModel& model, sym::Context& ctx) {
  expandEquationSums(model, ctx);
  for (Output& o : model.outputs) {
    o.value = withSumsExpanded(model, ctx, o.value, o.sums);
    o.sums.clear();
  }
  for (const IndexedSum& sum : model.indexedSums) {
    std::vector<Expr> parts;
    parts.reserve(pointCount(sum.box));
    forEachPoint(sum.box, [&](std::span<const long> point, size_t) { parts.push_back(instantiate(model, ctx, sum.body, point)); });
    std::vector<Term>& terms = sum.energy == IndexedSum::Energy::Kinetic     ? model.kinetic
                               : sum.energy == IndexedSum::Energy::Potential ? model.potential
                                                                             : model.dissipation;
    terms[sum.term].value = ctx.add(terms[sum.term].value, ctx.add(parts));
  }
  model.indexedSums.clear();
  // Later loops first: each inserts its forces where the scalar lowering would have put them, point
  // by point its statements in turn.
  const std::vector<IndexedForce>& all = model.indexedForces;
  for (size_t end = all.size(); end > 0;) {
    size_t begin = all[end - 1].first;
    std::vector<std::pair<int, Term>> forces;
    forEachPoint(all[begin].box, [&](std::span<const long> point, size_t) {
      for (size_t k = begin; k < end; ++k) {
        Expr target = instantiate(model, ctx, all[k].target, point);
        forces.push_back({model.variableOf(target), {instantiate(model, ctx, all[k].body, point), all[k].range}});
      }
    });
    model.forces.insert(model.forces.begin() + static_cast<long>(all[begin].position), forces.begin(), forces.end());
    end = begin;
  }
  model.indexedForces.clear();
}

}  // namespace qdot::flat
