// Instances: the tree of component instances under the model (spec §7), the modifiers that
// reach each one, and the references that go through components (`m1.s`, `ms[i].a.s`).
#include <numeric>

#include "flatten/Flattener.h"
#include "support/Assert.h"

namespace qdot::flat {

using namespace qdot::ast;
using sema::SymbolKind;

Instance& Flattener::newInstance(const sema::CheckedClass& cls, Instance* parent, const Declaration* decl,
                                 std::string path) {
  Instance& inst = instances_.emplace_back();
  inst.cls = &cls;
  inst.parent = parent;
  inst.decl = decl;
  inst.path = std::move(path);
  inst.index = static_cast<int>(out_.components.size());
  inst.slots.resize(cls.declarations.size());
  out_.components.push_back(inst.path);
  return inst;
}

static std::string elementSuffix(const std::vector<int>& shape, size_t k) {
  if (shape.empty()) return "";
  std::vector<int> idx(shape.size());
  for (size_t d = shape.size(); d-- > 0;) {
    idx[d] = static_cast<int>(k % shape[d]) + 1;
    k /= shape[d];
  }
  std::string s = "[";
  for (size_t d = 0; d < idx.size(); ++d) s += (d ? "," : "") + std::to_string(idx[d]);
  return s + "]";
}

// Creates the components of `inst` (arrays element by element) and, recursively, theirs. A
// component's modifiers: those the enclosing levels give it (outer first: they win), then its
// declaration's own; a connector learns which of its potentials its component's energies use.
void Flattener::instantiate(Instance& inst) {
  for (const Declaration* d : inst.cls->declarations) {
    const sema::ModelSymbol& s = inst.cls->symbols.at(d->name);
    if (s.kind != SymbolKind::Component || !s.component) continue;
    std::vector<int> shape;
    {
      ScopeGuard scope(*this, inst);
      shape = evaluateDims(*d);
    }
    size_t count = std::accumulate(shape.begin(), shape.end(), size_t{1}, std::multiplies<>());
    countScalars(count, d->nameRange);
    ComponentArray& array = inst.children[d];
    array.shape = shape;
    const ModEntry* outer = modifierOf(inst, *d);
    for (size_t k = 0; k < count; ++k) {
      Instance& child = newInstance(*s.component, &inst, d, inst.prefix() + d->name + elementSuffix(shape, k));
      if (outer)  // `cs[3](k(k = {10, 20, 30}))`: the element of cs, then of k if it is an array too
        for (const auto& m : outer->mod->nested) child.mods.push_back(nestedEntry(*outer, m, shape, k));
      for (const auto& m : d->mods)
        child.mods.push_back({&m, &inst, shape.empty() ? -1 : static_cast<int>(k), shape});
      if (s.component->isConnector())
        for (const std::string& p : inst.cls->energyPotentials)
          if (p.size() > d->name.size() && p.compare(0, d->name.size() + 1, d->name + ".") == 0)
            child.promoted.push_back(p.substr(d->name.size() + 1));
      array.elems.push_back(&child);
    }
    for (Instance* child : array.elems) instantiate(*child);
  }
}

// A modifier inside an outer one (`cs[3](k(k = {10, 20, 30}))` reaching cs[2].k): it picks the
// outer entry's element, then this declaration's element `k` if it is an array too.
ModEntry Flattener::nestedEntry(const ModEntry& outer, const ast::Modification& m, const std::vector<int>& shape,
                                size_t k) {
  if (shape.empty()) return {&m, outer.scope, outer.element, outer.shape};
  size_t count = std::accumulate(shape.begin(), shape.end(), size_t{1}, std::multiplies<>());
  std::vector<int> combined = outer.element >= 0 ? outer.shape : std::vector<int>{};
  combined.insert(combined.end(), shape.begin(), shape.end());
  int element = static_cast<int>((outer.element >= 0 ? static_cast<size_t>(outer.element) * count : 0) + k);
  return {&m, outer.scope, element, combined};
}

// The modification of `d` in `inst`: from outside first, else its class's `extends Base(d = …)`.
const ModEntry* Flattener::modifierOf(const Instance& inst, const Declaration& d) {
  for (const ModEntry& m : inst.mods)
    if (m.mod->name == d.name) return &m;
  auto it = inst.cls->extendsModifiers.find(&d);
  if (it == inst.cls->extendsModifiers.end()) return nullptr;
  // Made once per instance and declaration (a deque: entries do not move).
  auto key = std::make_pair(it->second, &inst);
  auto found = extendsEntries_.find(key);
  if (found == extendsEntries_.end())
    found = extendsEntries_.emplace(key, ModEntry{it->second, const_cast<Instance*>(&inst), -1, {}}).first;
  return &found->second;
}

// An array value given to an array of components gives each its element (`Mass ms[n](m = fill(1, n))`);
// any other value applies to every element.
Value Flattener::elementOf(const ModEntry& entry, const Value& v) {
  if (entry.element < 0 || v.shape.size() < entry.shape.size() ||
      !std::equal(entry.shape.begin(), entry.shape.end(), v.shape.begin()))
    return v;
  std::vector<int> rest(v.shape.begin() + static_cast<long>(entry.shape.size()), v.shape.end());
  size_t per = std::accumulate(rest.begin(), rest.end(), size_t{1}, std::multiplies<>());
  Value out{rest, {}};
  for (size_t i = 0; i < per; ++i) out.elems.push_back(v.elems[entry.element * per + i]);
  return out;
}

Value Flattener::modifierValue(const ModEntry& entry, SourceRange) {
  auto key = std::make_pair(entry.mod, entry.scope);
  auto it = modValues_.find(key);
  if (it == modValues_.end()) {
    ScopeGuard scope(*this, *entry.scope);
    Value v = lower(*entry.mod->value);
    it = modValues_.emplace(key, std::move(v)).first;
  }
  checkArrayModifier(entry, it->second, *entry.mod);
  return elementOf(entry, it->second);
}

// An array value for an array of components must have its shape first; else one error (not one
// per element).
void Flattener::checkArrayModifier(const ModEntry& entry, const Value& v, const ast::Modification& written) {
  if (entry.element < 0 || v.isScalar()) return;
  bool fits = v.shape.size() >= entry.shape.size() && std::equal(entry.shape.begin(), entry.shape.end(), v.shape.begin());
  if (fits) return;
  if (!badModifiers_.insert(&written).second) throw FlattenAbort{};
  fail(written.value->range, DiagCode::E0307,
       "this value has shape " + shapeText(v.shape) + ", but it modifies an array of components of shape " +
           shapeText(entry.shape),
       "give one value per component (an array of shape " + shapeText(entry.shape) + ") or a single value for all");
}

const sema::ModelSymbol& Flattener::symbolIn(const Instance& inst, const std::string& name, SourceRange where) {
  if (const sema::ModelSymbol* s = inst.cls->find(name)) return *s;
  fail(where, DiagCode::E0202, "'" + inst.cls->fullName + "' has no element '" + name + "'");
}

const ComponentArray& Flattener::childArray(Instance& inst, const std::string& name, SourceRange where) {
  const sema::ModelSymbol& s = symbolIn(inst, name, where);
  auto it = inst.children.find(s.decl);
  if (s.kind != SymbolKind::Component || it == inst.children.end())
    fail(where, DiagCode::E0224, "'" + inst.prefix() + name + "' is not a component");
  return it->second;
}

static Instance& single(const ComponentArray& a, const std::string& name, SourceRange where, Flattener& f) {
  if (!a.shape.empty() || a.elems.size() != 1)
    f.fail(where, DiagCode::E0305, "'" + name + "' is an array of components: give a subscript", "e.g. " + name + "[1]");
  return *a.elems[0];
}

// The components an expression names as a whole array: `ms`, `sys.ms`, `c.ms`.
const ComponentArray& Flattener::componentArrayOf(const Expr& e) {
  if (auto* n = dyn_cast<NameExpr>(&e)) {
    Instance* inst = cur_;
    for (size_t i = 0; i + 1 < n->parts.size(); ++i)
      inst = &single(childArray(*inst, n->parts[i], n->range), n->parts[i], n->range, *this);
    return childArray(*inst, n->parts.back(), n->range);
  }
  if (auto* m = dyn_cast<MemberExpr>(&e)) return childArray(instanceOf(*m->base), m->field, m->fieldRange);
  fail(e.range, DiagCode::E0224, "this is not a component");
}

// The one component an expression names: `m1`, `ms[2]`, `sys.m1.a`, `ms[i].a`.
Instance& Flattener::instanceOf(const Expr& e) {
  if (auto* ix = dyn_cast<IndexExpr>(&e)) {
    const ComponentArray& a = componentArrayOf(*ix->base);
    if (ix->subscripts.size() != a.shape.size())
      fail(e.range, DiagCode::E0305, std::to_string(ix->subscripts.size()) + " subscript(s) for an array of " +
                                         std::to_string(a.shape.size()) + " dimension(s) of components");
    size_t offset = 0;
    for (size_t d = 0; d < a.shape.size(); ++d) offset = offset * a.shape[d] + (subscriptIndex(*ix->subscripts[d], a.shape[d]) - 1);
    return *a.elems[offset];
  }
  const ComponentArray& a = componentArrayOf(e);
  return single(a, "this", e.range, *this);
}

// `m1.s`, `sys.m1.a.s`: through scalar components to a declaration of the last one.
Value Flattener::lowerDotted(const NameExpr& n) {
  Instance* inst = cur_;
  for (size_t i = 0; i + 1 < n.parts.size(); ++i)
    inst = &single(childArray(*inst, n.parts[i], n.range), n.parts[i], n.range, *this);
  const sema::ModelSymbol& s = symbolIn(*inst, n.parts.back(), n.range);
  if (s.kind == SymbolKind::Component)
    fail(n.range, DiagCode::E0224, "'" + n.dotted() + "' is a component, not a value");
  return valueOf(*inst, s, n.range);
}

// `ms[i].s`, `ms[i].a.s`.
Value Flattener::lowerMember(const MemberExpr& e) {
  Instance& inst = instanceOf(*e.base);
  const sema::ModelSymbol& s = symbolIn(inst, e.field, e.fieldRange);
  if (s.kind == SymbolKind::Component) fail(e.range, DiagCode::E0224, "this is a component, not a value");
  return valueOf(inst, s, e.range);
}

}  // namespace qdot::flat
