// Pipeline: parse → check → flatten → derive (Euler–Lagrange) → DAE → kernels → bytecode or
// native code, timing each stage. Each step is one function taking the Compilation and returning
// whether the stage succeeded; continueTo runs the ones not run yet.
#include "driver/Pipeline.h"

#include <algorithm>

#include <charconv>
#include <filesystem>
#include <chrono>
#include <iostream>
#include <iterator>

#include "bodies/RigidBodies.h"
#include "bytecode/Emitter.h"
#include "dae/IndexReduction.h"
#include "dae/TemplateOde.h"
#include "flatten/FlatPrinter.h"
#include "sim/Names.h"
#include "qdot/two_halves.hpp"
#include "syntax/Parser.h"

namespace qdot::driver {
namespace {

template <class F> auto timed(double& seconds, F&& f) {
  auto t0 = std::chrono::steady_clock::now();
  auto result = f();
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

void reportMissingModel(Compilation& c, uint32_t file) {
  const std::string& model = c.options.model;
  if (model.empty()) {
    c.diags.error({file, 0, 0}, DiagCode::E0200, "this file declares no model", "declare one: model Name ... end Name;");
    return;
  }
  std::string names;
  for (const auto& cls : c.ast->classes)
    if (cls->kind == ast::ClassKind::Model) names += (names.empty() ? "" : ", ") + cls->name;
  c.diags.error({}, DiagCode::E0200, "there is no model named '" + model + "' in " + c.sources.name(file),
                names.empty() ? "the file declares no model" : "the file declares: " + names);
}

bool parse(Compilation& c, uint32_t file) {
  c.ast = timed(c.times.parse, [&] {
    auto tree = syntax::parse(c.sources, file, c.diags);
    if (tree && !c.diags.hasErrors()) bodies::lowerRigidBodies(*tree, c.sources, c.diags);
    return tree;
  });
  return c.ast && !c.diags.hasErrors();
}

// The model's file, or "" for text that is not a file (standard input, a test's buffer).
std::string modelFilePath(const Compilation& c) {
  const std::string& name = c.sources.name(c.ast->file);
  return name.empty() || name.front() == '<' || !std::filesystem::is_regular_file(name) ? "" : name;
}

bool check(Compilation& c) {
  c.libraries = std::make_unique<LibraryLoader>(libraryPath(modelFilePath(c)), c.sources, c.diags);
  sema::Library library = c.libraries->library();
  c.checked = timed(c.times.check, [&] { return sema::checkModel(*c.ast, c.options.model, c.diags, library); });
  if (!c.checked) reportMissingModel(c, c.ast->file);
  return c.checked && !c.diags.hasErrors();
}

// Whether every relative symbol of a template's body is one the loops read: an array of
// coordinates or velocities, or an array of parameters a loop addresses as p[first + linear index]
// (flat::loopableParameters; in several dimensions of the shape of the coordinates the template
// reads). `shape`: the coordinates' shape if known (a force's target), else null.
bool loopsRead(const flat::FlatModel& m, sym::Expr body, size_t rank, const std::vector<int>*& shape,
               const sym::Context& ctx, std::string* unread = nullptr) {
  auto refuse = [&](const flat::ArrayVariable& a, const char* why) {
    if (unread) *unread = "'" + a.name + "' (" + why + ")";
    return false;
  };
  std::vector<const flat::RelativeElement*> parameters;
  for (sym::Expr s : ctx.freeSymbols(body)) {
    const flat::RelativeElement* rel = m.relativeElement(s);
    if (!rel) continue;
    const flat::ArrayVariable& a = m.patterns->arrays[rel->array];
    int var = m.variableOf(a.elements[0]);
    flat::VarRole role = var >= 0 ? m.variables[var].role : flat::VarRole::Parameter;
    if (var >= 0 && (role == flat::VarRole::Coordinate || role == flat::VarRole::Velocity)) {
      if (shape && *shape != a.shape) return refuse(a, "coordinates of another shape than the others the loop reads");
      shape = &a.shape;
    } else {
      parameters.push_back(rel);
    }
  }
  for (const flat::RelativeElement* rel : parameters) {
    const flat::ArrayVariable& a = m.patterns->arrays[rel->array];
    if (m.variableOf(a.elements[0]) < 0) return refuse(a, "its elements are expressions, not variables");
    if (!shape || !flat::loopableParameters(m, *rel, rank, *shape))
      return refuse(a, "parameters a loop reads only in the coordinates' shape, subscripted by the iterators in order");
  }
  return true;
}

// A templated model's outputs: each sum a loop reads (over coordinates or velocities, see
// loopsRead) takes their shape and stays a loop; the others (over parameters or the iterator only)
// are expanded into the output's value.
void shapeOutputSums(flat::FlatModel& m, sym::Context& ctx) {
  for (flat::Output& o : m.outputs) {
    std::vector<flat::IndexedTerm> expanded;
    std::erase_if(o.sums, [&](flat::IndexedTerm& sum) {
      const std::vector<int>* shape = nullptr;
      if (loopsRead(m, sum.body, sum.box.size(), shape, ctx) && shape) return sum.shape = *shape, false;
      expanded.push_back(std::move(sum));
      return true;
    });
    o.value = flat::withSumsExpanded(m, ctx, o.value, expanded);
  }
}

// Why the templates do not apply, in words for `qdot run --stats` ("" if they do; the model has
// some: sums or force loops).
std::string whyScalar(const flat::FlatModel& m, const CompileOptions& o, const sym::Context& ctx,
                      const std::optional<std::vector<int>>& defined, size_t failing, const SourceManager& sm) {
  if (!o.keepLoops) return "loops are off (--no-loops, or a command that works on scalars)";
  if (!m.constraints.empty())
    return "it has a constraint (" + flat::lineOf(sm, m.constraints[0].origin.range) + "): index reduction works on scalars";
  if (!defined && failing < m.equations.size())
    return "the equation at " + flat::lineOf(sm, m.equations[failing].origin.range) +
           " does not define an algebraic unknown of its own over coordinates, velocities, parameters and time";
  if (!dae::initialEquationsAreStartValues(m, ctx))
    return "an initial equation (" + flat::lineOf(sm, m.initialEquations[0].origin.range) + ", …) is not a state's start value";
  std::vector<char> isDefined(m.variables.size(), 0);
  for (int z : defined ? *defined : std::vector<int>{}) isDefined[z] = 1;
  // The first variable that keeps the model scalar, searched in two halves (3·10⁶ variables at
  // 10⁶ masses: one pass over them was 17 ms).
  auto keepsScalar = [&](const flat::Variable& var, size_t v) {
    return var.alias || var.role == flat::VarRole::Derivative || (var.role == flat::VarRole::Unknown && !isDefined[v]);
  };
  size_t firstFound[2] = {m.variables.size(), m.variables.size()};
  inTwoHalves(m.variables.size(), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      if (keepsScalar(m.variables[v], v)) {
        firstFound[begin == 0 ? 0 : 1] = v;
        break;
      }
  });
  if (size_t v = std::min(firstFound[0], firstFound[1]); v < m.variables.size()) {
    const flat::Variable& var = m.variables[v];
    if (var.alias) return "'" + std::string(var.name) + "' is an alias (connections and alias equations work on scalars)";
    if (var.role == flat::VarRole::Derivative) return "'" + std::string(var.name) + "' is the rate of an unknown that is not a coordinate";
    return "'" + std::string(var.name) + "' is an unknown no equation defines explicitly";
  }
  std::string unread;
  for (const auto& sum : m.indexedSums) {
    const std::vector<int>* shape = nullptr;
    if (!loopsRead(m, sum.body, sum.box.size(), shape, ctx, &unread))
      return "the sum at " + flat::lineOf(sm, sum.range) + " reads " + unread;
  }
  for (const auto& f : m.indexedForces) {
    const std::vector<int>* shape = &m.patterns->arrays[m.relativeElement(f.target)->array].shape;
    if (!loopsRead(m, f.body, f.box.size(), shape, ctx, &unread))
      return "the force at " + flat::lineOf(sm, f.range) + " reads " + unread;
  }
  return "";
}

// Where the stages after flattening take templates (docs/loops.md): a model of energies over
// coordinates only — no constraints, components or aliases (their structural passes work on
// scalars), equations only where they define algebraic unknowns explicitly, initial equations that
// are start values at most. Its Jacobi integral is a sum over every element: the kernels loop it too.
// `defined`: the algebraic unknowns the model's equations define explicitly (explicitDefinitions),
// which become outputs: the equations may be those definitions.
bool hasTemplates(const flat::FlatModel& m) { return !m.indexedSums.empty() || !m.indexedForces.empty(); }

// The equations of a model of energies that each define an algebraic unknown explicitly — `z =
// expr` or `expr = z`, expr over coordinates, velocities, parameters and time — one per unknown,
// every unknown of the model so defined: per equation, the unknown it defines; nullopt otherwise,
// `failing` the first equation that is no such definition (or the count of equations: an unknown
// none defines).
// (What dae::eliminateExplicitAlgebraics would solve out of the scalar DAE; with templates they
// become outputs before the stages that need every row.)
std::optional<std::vector<int>> explicitDefinitions(const flat::FlatModel& m, const sym::Context& ctx, size_t& failing) {
  using flat::VarRole;
  auto definable = [&](sym::Expr s) {
    int v = m.variableOf(s);
    if (v < 0) return -1;
    const flat::Variable& var = m.variables[v];
    bool algebraic = var.role == VarRole::Unknown && var.derivative < 0 && !var.alias;
    return algebraic && !(var.fixed && var.fixedGiven) ? v : -1;
  };
  auto overStates = [&](sym::Expr e) {
    for (sym::Expr s : ctx.freeSymbols(e)) {
      if (m.patterns->iteratorOf(s) >= 0) continue;  // a kept sum's iterator
      const flat::RelativeElement* rel = m.relativeElement(s);  // an element of a kept sum
      int v = m.variableOf(rel ? m.patterns->arrays[rel->array].elements[0] : s);
      VarRole r = v >= 0 ? m.variables[v].role : VarRole::Unknown;
      if (r != VarRole::Coordinate && r != VarRole::Velocity && r != VarRole::Parameter && r != VarRole::Time) return false;
    }
    return true;
  };
  std::vector<const std::vector<flat::IndexedTerm>*> sumsOf(m.equations.size(), nullptr);
  for (const auto& [index, sums] : m.equationSums) sumsOf[index] = &sums;
  auto sumsOverStates = [&](size_t e) {
    return !sumsOf[e] || std::all_of(sumsOf[e]->begin(), sumsOf[e]->end(), [&](const flat::IndexedTerm& t) { return overStates(t.body); });
  };
  std::vector<int> defined;
  std::vector<char> seen(m.variables.size(), 0);
  for (size_t k = 0; k < m.equations.size(); ++k) {
    const flat::Equation& e = m.equations[k];
    failing = k;
    if (e.origin.kind != flat::OriginKind::Equation || !e.lhs || !e.rhs) return std::nullopt;
    int z = definable(e.lhs);
    if (sumsOf[k] && (z < 0 || !overStates(e.rhs) || !sumsOverStates(k))) return std::nullopt;  // (its sums are the rhs')
    if (z < 0 || !overStates(e.rhs)) z = overStates(e.lhs) ? definable(e.rhs) : -1;
    if (z < 0 || seen[z]++) return std::nullopt;
    defined.push_back(z);
  }
  for (size_t v = 0; v < m.variables.size(); ++v)
    if (m.variables[v].role == VarRole::Unknown && !m.variables[v].alias && !seen[v]) return failing = m.equations.size(), std::nullopt;
  return defined;
}

// Whether some expression of the model that the DAE substitutes aliases into reads symbol s (the
// equations, each defining its own unknown over states and parameters, read no other unknown).
bool readsSymbol(const flat::FlatModel& m, const sym::Context& ctx, sym::Expr s) {
  auto reads = [&](sym::Expr e) { return e && ctx.dependsOn(e, s); };
  for (const auto& [q, t] : m.forces)
    if (reads(t.value)) return true;
  for (const auto& f : m.indexedForces)
    if (reads(f.body)) return true;
  for (const auto& o : m.outputs) {
    if (reads(o.value)) return true;
    for (const auto& sum : o.sums)
      if (reads(sum.body)) return true;
  }
  for (const auto* terms : {&m.kinetic, &m.potential, &m.dissipation})
    for (const auto& t : *terms)
      if (reads(t.value)) return true;
  for (const auto& sum : m.indexedSums)
    if (reads(sum.body)) return true;
  for (const auto& e : m.initialEquations)
    if (reads(e.residual)) return true;
  for (const auto& e : m.constraints)
    if (reads(e.residual)) return true;
  for (const auto& v : m.variables)
    if (reads(v.start) || reads(v.alias)) return true;
  return false;
}

// The explicitly defined unknowns leave the system: each an alias of its value (the DAE
// substitutes it wherever it is read, a force say) and an output, first among the outputs in the
// order of the unknowns, as dae::eliminateExplicitAlgebraics places them.
void defineAsOutputs(flat::FlatModel& m, const std::vector<int>& defined, sym::Context& ctx) {
  std::vector<std::pair<int, size_t>> order;  // (unknown, its equation)
  for (size_t e = 0; e < defined.size(); ++e) order.push_back({defined[e], e});
  std::sort(order.begin(), order.end());
  std::vector<std::vector<flat::IndexedTerm>> sumsOf(m.equations.size());
  for (auto& [index, sums] : m.equationSums) sumsOf[index] = std::move(sums);  // of `z = …` only
  m.equationSums.clear();
  std::vector<flat::Output> outputs;
  for (auto [z, e] : order) {
    const flat::Equation& eq = m.equations[e];
    sym::Expr value = m.variableOf(eq.lhs) == z ? eq.rhs : eq.lhs;
    // A force or an output that reads z reads its value: with kept sums, the whole of it (made only
    // then: else nothing substitutes the alias).
    bool read = !sumsOf[e].empty() && readsSymbol(m, ctx, m.variables[z].symbol);
    m.variables[z].alias = read ? flat::withSumsExpanded(m, ctx, value, sumsOf[e]) : value;
    outputs.push_back({std::string(m.variables[z].name), value, eq.origin.range, flat::OutputKind::Plain, std::move(sumsOf[e])});
  }
  m.outputs.insert(m.outputs.begin(), std::make_move_iterator(outputs.begin()), std::make_move_iterator(outputs.end()));
  m.equations.clear();
}

// Whether a template of the model reads an iterator as a number (`0.1*i`): expanded, it is equal
// to the scalar lowering to rounding, not node for node (its constants fold in another order).
bool readsIterators(const flat::FlatModel& m, const sym::Context& ctx) {
  for (const auto& sum : m.indexedSums)
    if (m.patterns->readsIterator(ctx, sum.body)) return true;
  for (const auto& f : m.indexedForces)
    if (m.patterns->readsIterator(ctx, f.body)) return true;
  for (const auto& o : m.outputs)
    for (const auto& sum : o.sums)
      if (m.patterns->readsIterator(ctx, sum.body)) return true;
  for (const auto& [index, sums] : m.equationSums)
    for (const auto& sum : sums)
      if (m.patterns->readsIterator(ctx, sum.body)) return true;
  return false;
}

// Whether `for` equations may stay templates (docs/loops.md), from the syntax: a run that keeps
// loops, of a model of equations only — no mechanics or components (initial
// equations that are start values are checked on the flat model) — with `for` loops of equations naming at most one derivative each (`der(x[i]) = …`,
// `m*der(v[i]) = …`, `f[i] = …`; flat::mayKeepForEquation), one of them naming some. Flattening
// then keeps them only if each row is matched to its own unknown (dae::isTemplatedOde), else it
// flattens again.
bool forEquationsMayStay(const Compilation& c) {
  const sema::CheckedClass& root = *c.checked->root;
  if (!c.options.keepLoops || !root.mechanics.empty()) return false;  // (no mechanics: no invariants)
  for (const auto& [name, symbol] : root.symbols)
    if (symbol.kind == sema::SymbolKind::Component) return false;
  auto keepable = [](const ast::Equation* eq) { return eq->kind == ast::EquationKind::For && flat::mayKeepForEquation(*eq); };
  auto withRates = [](const ast::Equation* eq) { return eq->kind == ast::EquationKind::For && flat::namesDerivatives(*eq); };
  return std::any_of(root.equations.begin(), root.equations.end(), keepable) &&
         std::any_of(root.equations.begin(), root.equations.end(), withRates);
}

// Flattening with the `for` equations kept as templates, silently (its diagnostics are dropped):
// the model, if it is an explicit ODE whose DAE keeps them and nothing was reported; else nullopt
// and a Context as new, so that flattening again gives exactly what it gives without this attempt.
std::optional<flat::FlatModel> flattenKeepingEquations(Compilation& c, flat::FlattenLimits limits) {
  limits.keepForEquations = true;
  DiagnosticEngine attempt;
  auto model = flat::flatten(*c.checked, c.ctx, attempt, limits, c.options.structural);
  if (model) flat::expandEquationSums(*model, c.ctx);  // (an explicit ODE's rows are scalars or `for` templates)
  if (model && attempt.diagnostics().empty() && !model->equationTemplates.empty() && dae::isTemplatedOde(*model, c.ctx))
    return model;
  model.reset();
  c.ctx.clear();
  return std::nullopt;
}

// The first array of components of a model ("ms[1]"), or "".
std::string firstComponentArray(const flat::FlatModel& m) {
  for (const std::string& path : m.components)
    if (path.find('[') != std::string::npos) return path;
  return "";
}

// A result asked for that is no variable or output of the flat model but near a variable's name is
// most likely a typo (`links[3].b.ff`). The components are then left as they are: summing would
// drop the flows it may be a typo of, and the error that follows could not suggest the right name.
// (A name far from every variable, such as an invariant's, `jacobi`, is resolved later.)
std::string misspeltResult(const flat::FlatModel& m, const Compilation& c) {
  std::vector<std::string_view> names;  // made for the first name that is not found
  for (const std::string& name : c.options.results) {
    sym::Expr s = c.ctx.findSymbol(name);
    if ((s && m.variableOf(s) >= 0) ||
        std::any_of(m.outputs.begin(), m.outputs.end(), [&](const flat::Output& o) { return o.name == name; }))
      continue;
    if (names.empty())
      for (const flat::Variable& v : m.variables) names.push_back(v.name);
    if (rt::closestName(name, names)) return "'" + name + "', asked for, is not a result of the model";
  }
  return "";
}

// A run of a model with arrays of components that asks for some results only (`qdot run --outputs`):
// its components' energies summed over their connections (flat::sumConnectedEnergies), a
// Lagrangian over the coordinates whose repeated structure can stay templates. Returns why not
// ("" if it was rewritten, or has no array of components).
std::string sumComponentArrays(flat::FlatModel& m, Compilation& c) {
  if (!c.options.keepLoops || firstComponentArray(m).empty()) return "";
  if (c.options.results.empty()) return "every result is asked for, the connectors' flows too";
  if (std::string why = misspeltResult(m, c); !why.empty()) return why;
  std::string why = flat::sumConnectedEnergies(m, c.ctx, c.options.results);
  if (why.empty()) flat::rerollTerms(m, c.ctx, c.options.rerollMinimumRun), c.componentsSummed = true;
  return why;
}

bool flatten(Compilation& c) {
  c.flat = timed(c.times.flatten, [&] {
    flat::FlattenLimits limits = c.options.limits;
    limits.keepLoops = true;
    if (forEquationsMayStay(c))
      if (auto model = flattenKeepingEquations(c, limits)) {
        c.loops = "";
        return model;
      }
    auto model = flat::flatten(*c.checked, c.ctx, c.diags, limits, c.options.structural);
    std::string componentsWhy = model && !c.diags.hasErrors() ? sumComponentArrays(*model, c) : "";
    std::optional<std::vector<int>> defined;
    size_t failing = 0;
    if (model) defined = model->equations.empty() ? std::vector<int>{} : explicitDefinitions(*model, c.ctx, failing);
    bool repeated = model && (hasTemplates(*model) || std::any_of(model->outputs.begin(), model->outputs.end(),
                                                                      [](const flat::Output& o) { return !o.sums.empty(); }) ||
                              !model->equationSums.empty());
    std::string why = model && hasTemplates(*model) ? whyScalar(*model, c.options, c.ctx, defined, failing, c.sources)
                                                    : "its repeated structure is only in outputs or equations";
    bool templates = model && defined && hasTemplates(*model) && why.empty();
    if (repeated) c.loops = templates ? "" : why;
    if (model && !repeated && !firstComponentArray(*model).empty())
      c.loops = "it has arrays of components (" + firstComponentArray(*model) + ", …), which are expanded" +
                (componentsWhy.empty() ? "" : ": " + componentsWhy);
    if (templates && !defined->empty()) {
      defineAsOutputs(*model, *defined, c.ctx);
      c.eliminated.eliminated = defined->size();  // solved out as the scalar DAE would have them
    }
    if (templates) shapeOutputSums(*model, c.ctx);
    if (model && !templates) {
      if ((!model->templatesRound && !readsIterators(*model, c.ctx)) || c.diags.hasErrors()) {
        flat::expandIndexedSums(*model, c.ctx);  // exactly the scalar lowering's nodes
      } else {  // an iterator's value or a factor folds in another order than the scalar lowering: flatten again
        model.reset();
        c.ctx.clear();
        limits.keepLoops = false;
        c.componentsSummed = false;  // (flattened as written)
        DiagnosticEngine again;  // the same diagnostics as the first time, already reported
        model = flat::flatten(*c.checked, c.ctx, again, limits, c.options.structural);
      }
    }
    return model;
  });
  return c.flat && !c.diags.hasErrors();
}

bool derive(Compilation& c) {
  c.eom = timed(c.times.derive, [&] { return mech::deriveEquationsOfMotion(*c.flat, c.ctx, c.diags, c.options.simplify); });
  return c.eom && !c.diags.hasErrors();
}

bool buildDae(Compilation& c) {
  c.dae = timed(c.times.dae, [&] {
    std::optional<dae::Dae> d = dae::buildDae(*c.flat, *c.eom, c.ctx, c.diags);
    // A templated DAE is an ODE in the accelerations of one row per coordinate (index 1), and its
    // coordinates are coupled along the arrays: nothing to reduce, nothing worth pruning.
    if (d && d->templated()) return d;
    if (d && c.loops && c.loops->empty())  // kept through flattening, but mechanics peeled every element
      c.loops = "no region of elements shares its rows (each element's row is its own)";
    if (d && c.options.eliminateAlgebraics) c.eliminated = dae::eliminateExplicitAlgebraics(*d, c.ctx);
    if (d && !c.options.results.empty()) {
      std::vector<std::string> names = c.options.results;
      if (c.options.keepInvariants)
        for (const auto& inv : d->invariants) names.push_back(inv.name);
      c.pruned = dae::pruneToResults(*d, names, c.ctx);
    }
    if (d && !dae::reduceIndex(*d, c.ctx, c.diags)) d.reset();
    if (d && c.options.keepLoops && c.options.rerollRows) c.rerolled = dae::rerollRows(*d, c.ctx, c.options.rerollMinimumRun);
    return d;
  });
  if (c.dae) c.experiment = c.dae->experiment;
  bool ok = c.dae && !c.diags.hasErrors();
  if (ok && c.options.releaseStages) c.eom.reset(), c.flat.reset();
  return ok;
}

bool buildKernels(Compilation& c) {
  c.kernels = timed(c.times.kernel, [&] {
    return std::make_shared<const kernel::KernelModule>(kernel::buildKernels(*c.dae, c.ctx, c.diags));
  });
  bool ok = !c.diags.hasErrors();
  if (ok && c.options.releaseStages) {  // the kernels hold no symbolic nodes
    // A large DAE's per-element objects take a while to destroy (0.05 s at 10⁶ masses): on the core
    // the single-threaded compile leaves idle, while this one goes on to the solver. The DAE only
    // points into the Context (never reads through the pointers while destroyed), so the Context
    // is cleared meanwhile.
    if (c.releasing.joinable()) c.releasing.join();
    c.releasing = std::jthread([dae = std::move(*c.dae)]() mutable { dae = dae::Dae{}; });
    c.dae.reset();
    c.ctx.clear();
  }
  return ok;
}

bool emitBytecode(Compilation& c) {
  c.bytecode = timed(c.times.bytecode, [&] { return bytecode::emitBytecode(*c.kernels, c.sources); });
  return true;
}

// A JIT failure is not an error in the model: c.internalError says what failed.
bool compileNative(Compilation& c) {
  Result<ModelPtr> model =
      timed(c.times.native, [&] { return llvmbackend::createJitModel(c.kernels, c.sources, c.options.jit, &c.jitStats); });
  if (!model) {
    c.internalError = "the LLVM JIT failed: " + model.error();
    return false;
  }
  c.native = std::move(model).value();
  return true;
}

// Runs stage `s` (whose predecessors have run).
bool runStage(Compilation& c, Stage s) {
  switch (s) {
    case Stage::Parse: return true;  // done by compileFile/compileSource
    case Stage::Check: return check(c);
    case Stage::Flatten: return flatten(c);
    case Stage::Derive: return derive(c);
    case Stage::Dae: return buildDae(c);
    case Stage::Kernel: return buildKernels(c);
    case Stage::Bytecode: return emitBytecode(c);
    case Stage::Native: return compileNative(c);
  }
  return false;
}

bool startFrom(Compilation& c, uint32_t file, Stage until) {
  c.ok = parse(c, file);
  c.reached = Stage::Parse;
  return continueTo(c, until);
}

}  // namespace

bool continueTo(Compilation& c, Stage until) {
  while (c.ok && c.reached < until) {
    Stage next = static_cast<Stage>(static_cast<int>(c.reached) + 1);
    if (next == Stage::Bytecode && until == Stage::Native) next = Stage::Native;  // the other backend
    if (!runStage(c, next)) {
      // The JIT failing on valid kernels (c.internalError) leaves the compilation usable: the
      // bytecode backend can still run the model.
      c.ok = next == Stage::Native;
      return false;
    }
    c.reached = next;
  }
  if (c.ok && until == Stage::Bytecode && !c.bytecode) c.ok = emitBytecode(c);  // reached Native before
  return c.ok && c.reached >= until;
}

bool compileFile(Compilation& c, const std::string& path, Stage until) {
  uint32_t file = 0;
  if (path == kStandardInput) {
    std::string text(std::istreambuf_iterator<char>(std::cin), {});
    file = c.sources.addBuffer("<stdin>", std::move(text));
  } else if (std::string error; !c.sources.addFile(path, file, error)) {
    c.diags.error({}, DiagCode::E0001, error, "check the path of the model file");
    return c.ok = false;
  }
  return startFrom(c, file, until);
}

bool compileSource(Compilation& c, std::string name, std::string text, Stage until) {
  return startFrom(c, c.sources.addBuffer(std::move(name), std::move(text)), until);
}

namespace {

// The scalar Integer parameter `name` of the checked model, or null.
// The scalar Integer parameter `name` of the checked model, or of one of its (scalar) components
// by dotted path (`str.n`), or null.
const ast::Declaration* integerParameter(const sema::CheckedModel& m, const std::string& name) {
  const sema::CheckedClass* cls = m.root;
  size_t begin = 0;
  for (size_t dot; (dot = name.find('.', begin)) != std::string::npos; begin = dot + 1) {
    const sema::ModelSymbol* part = cls->find(name.substr(begin, dot - begin));
    if (!part || part->kind != sema::SymbolKind::Component || !part->component || !part->decl->dims.empty())
      return nullptr;
    cls = part->component;
  }
  const sema::ModelSymbol* s = cls->find(name.substr(begin));
  return s && s->kind == sema::SymbolKind::IntegerParameter ? s->decl : nullptr;
}

}  // namespace

std::string takeStructuralParameters(Compilation& c, std::vector<std::string>& assignments) {
  std::vector<std::string> rest;
  for (const std::string& a : assignments) {
    std::size_t eq = a.find('=');
    std::string name = a.substr(0, eq);
    const ast::Declaration* d = eq == std::string::npos ? nullptr : integerParameter(*c.checked, name);
    if (!d) {
      rest.push_back(a);
      continue;
    }
    if (!d->dims.empty() || !d->typeDims.empty())
      return "-p " + a + ": '" + name + "' is an array of Integer parameters; only a scalar one can be set with -p";
    std::string text = a.substr(eq + 1);
    long value = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size())
      return "-p " + a + ": '" + name + "' is an Integer parameter (structural: it is applied before compiling); give a whole number, e.g. -p " + name + "=3";
    if (!c.options.structural.emplace(name, value).second) return "-p " + name + " is given twice";
  }
  assignments = std::move(rest);
  return "";
}

std::string structuralParameterList(const Compilation& c) {
  std::string list;
  for (const ast::Declaration* d : c.checked->root->declarations)
    if (integerParameter(*c.checked, d->name) == d) list += (list.empty() ? "" : ", ") + d->name;
  return list;
}

bool compileFile(Compilation& c, const std::string& path, std::string_view model, Stage until) {
  c.options.model = model;
  return compileFile(c, path, until);
}

bool compileSource(Compilation& c, std::string name, std::string text, std::string_view model, Stage until) {
  c.options.model = model;
  return compileSource(c, std::move(name), std::move(text), until);
}

}  // namespace qdot::driver
