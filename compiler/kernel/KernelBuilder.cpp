// buildKernels: turns a dae::Dae into the six programs of the model ABI. Residual and Jacobian go
// through one CSE together (shared temporaries) and are then lowered as two programs, each
// computing only the temporaries it needs: IDA evaluates the residual far more often than the
// Jacobian, so the residual must not pay for Jacobian-only work.
#include <unordered_map>
#include <algorithm>
#include <cstring>
#include <optional>
#include <limits>
#include <unordered_set>

#include "dae/Initialization.h"
#include "kernel/Jacobian.h"
#include "kernel/Lowering.h"
#include "qdot/two_halves.hpp"
#include "support/Assert.h"
#include "support/Diagnostic.h"
#include "symbolic/Simplify.h"

namespace qdot::kernel {
namespace {

using sym::Expr;

std::string shorten(std::string s, size_t max = 120) {
  if (s.size() > max) s = s.substr(0, max - 3) + "...";
  return s;
}

class Builder {
 public:
  Builder(const dae::Dae& dae, sym::Context& ctx, DiagnosticEngine& diags) : dae_(dae), ctx_(ctx), diags_(diags) {}

  KernelModule run() {
    describeModel();
    addEquationSources();
    buildParameters();
    buildInitialValues();
    buildResidualAndJacobian();
    m_.program(ModelProgram::Outputs) = buildOutputs();
    m_.program(ModelProgram::Invariants) = buildInvariants();
    return std::move(m_);
  }

 private:
  const dae::Dae& dae_;
  std::unordered_map<int, std::string> nameOfFlat_;
  sym::Context& ctx_;
  DiagnosticEngine& diags_;
  KernelModule m_;
  std::vector<uint32_t> equationSource_;
  std::vector<uint32_t> scalarRows_;  ///< the DAE's rows with a residual of their own (not a template block's)

  uint32_t addSource(std::string label, SourceRange range, std::string text = {}) {
    m_.sources.push_back({std::move(label), range, shorten(std::move(text))});
    return static_cast<uint32_t>(m_.sources.size() - 1);
  }

  // The ABI's output kinds: a z-x-z triple only where ψ, θ, φ are all kept, in order (pruning by
  // --outputs may keep part of one: its ψ and φ are then unwrapped as single angles).
  static std::vector<int32_t> outputKinds(const std::vector<flat::Output>& outputs) {
    using K = flat::OutputKind;
    std::vector<int32_t> kinds(outputs.size(), 0);
    for (size_t i = 0; i < outputs.size(); ++i) {
      K k = outputs[i].kind;
      if (k == K::EulerPsi && i + 2 < outputs.size() && outputs[i + 1].kind == K::EulerTheta &&
          outputs[i + 2].kind == K::EulerPhi) {
        kinds[i] = 2;
        i += 2;
      } else if (k == K::Angle || k == K::EulerPsi || k == K::EulerPhi) {
        kinds[i] = 1;
      }
    }
    return kinds;
  }

  void describeModel() {
    ModelDescription& d = m_.description.edit();
    d.name = dae_.name;
    size_t n = dae_.variables.size();
    d.variableNames.resize(n);
    d.isDifferential.resize(n);
    d.fixed.resize(n);
    // One pass over 2·10⁶ unknowns of 88 bytes at 10⁶ masses: in two halves (each writes its own).
    inTwoHalves(n, [&](size_t first, size_t last) {
      for (size_t j = first; j < last; ++j) {
        const dae::Variable& v = dae_.variables[j];
        d.variableNames[j] = v.name;
        d.isDifferential[j] = v.kind == dae::VarKind::State;
        d.fixed[j] = !defaultFixed(v) ? kStartGuess : v.declaration.fixedGiven ? kFixedAsWritten : kFixedByDefault;
      }
    });
    for (const auto& p : dae_.parameters) {
      d.parameterNames.push_back(p.name);
      d.parameterDescriptions.push_back(p.description);
    }
    for (const auto& o : dae_.outputs) d.outputNames.push_back(o.name);
    d.outputKinds = outputKinds(dae_.outputs);
    for (const auto& inv : dae_.invariants) d.invariantNames.push_back(inv.name);
    d.structuralParameters = dae_.structuralParameters;
    if (dae_.differentiatedRows.empty()) return;  // index ≤ 1: no dummy derivatives to choose
    for (const auto& l : dae_.links) d.derivativeLinks.insert(d.derivativeLinks.end(), {l.row, l.variable, l.derivative});
    d.differentiatedRowStarts.push_back(0);
    for (const auto& rows : dae_.differentiatedRows) {
      d.differentiatedRows.insert(d.differentiatedRows.end(), rows.begin(), rows.end());
      d.differentiatedRowStarts.push_back(static_cast<int32_t>(d.differentiatedRows.size()));
    }
  }

  // Coordinates and velocities that are states start fixed; another state is fixed if it has a
  // start value (or fixed = true); an algebraic variable's start is only a guess unless fixed.
  static bool defaultFixed(const dae::Variable& v) {
    if (v.declaration.fixedGiven || v.declaration.fixed) return v.declaration.fixed;  // as written
    if (v.kind != dae::VarKind::State) return false;
    return v.role == dae::UnknownRole::Coordinate || v.role == dae::UnknownRole::Velocity ||
           v.declaration.start != nullptr;
  }

  // Name of the DAE variable that is flat variable `flatVar` (a map, built once: labels are made
  // for every equation, and a search per label would be quadratic in the model size).
  std::string variableNameOfFlat(int flatVar) {
    if (nameOfFlat_.empty())
      for (const auto& v : dae_.variables) nameOfFlat_.emplace(v.flatVar, v.name);
    auto it = nameOfFlat_.find(flatVar);
    return it == nameOfFlat_.end() ? "?" : it->second;
  }

  std::string equationLabel(size_t i, const dae::Equation& e) {
    std::string label = "equation " + std::to_string(i + 1);
    switch (e.origin.kind) {
      case flat::OriginKind::EulerLagrange:
        return label + " (Euler-Lagrange equation of " +
               (i < dae_.rowCoordinates.size() ? dae_.rowCoordinates[i] : variableNameOfFlat(e.origin.variable)) + ")";
      case flat::OriginKind::Kinematic: return label + " (velocity of " + variableNameOfFlat(e.origin.variable) + ")";
      case flat::OriginKind::Constraint: return label + " (constraint" + e.origin.element + ")";
      case flat::OriginKind::Connection: return label + " (flow balance of the connection " + e.origin.element + ")";
      case flat::OriginKind::Equation:
      case flat::OriginKind::InitialEquation: break;
    }
    return e.origin.element.empty() ? label : label + " (element " + e.origin.element + ")";
  }

  std::string equationText(const dae::Equation& e) const {
    if (!e.lhs || !e.rhs) return {};
    return sym::toString(ctx_, e.lhs) + " = " + sym::toString(ctx_, e.rhs);
  }

  void addEquationSources() {
    // One source per scalar row, parameter, initial equation, output and invariant: reserved, as a
    // large expanded model has hundreds of thousands (each with two strings to move on growth). A
    // template block's rows share one; start values and nominals (one each where they are not
    // numbers in runs) are left to grow: counting them here reserved 480 bytes per mass of the 10⁶
    // chain that nothing wrote, and the heap prefaulter populated a lead of it.
    size_t scalarRows = 0;
    for (const auto& e : dae_.equations) scalarRows += e.residual != nullptr;
    m_.sources.reserve(scalarRows + dae_.parameters.size() + dae_.initialEquations.size() + dae_.outputs.size() +
                       dae_.invariants.size());
    // A template block's rows are served by its loop's one source (blockSource), not one each.
    for (size_t i = 0; i < dae_.equations.size(); ++i) {
      const auto& e = dae_.equations[i];
      equationSource_.push_back(e.residual ? addSource(equationLabel(i, e), e.origin.range, equationText(e)) : UINT32_MAX);
      if (e.residual) scalarRows_.push_back(static_cast<uint32_t>(i));
    }
  }

  // y, y', p and time as loads (cj too for the Jacobian).
  void bindInputs(ProgramBuilder& b, bool variables, Expr cj = nullptr) {
    if (dae_.time) b.bindLoad(dae_.time, Op::LoadTime, 0);
    for (uint32_t k = 0; k < dae_.parameters.size(); ++k) b.bindLoad(dae_.parameters[k].symbol, Op::LoadP, k);
    if (cj) b.bindLoad(cj, Op::LoadCj, 0);
    if (variables) b.bindUnknowns(unknowns());
  }

  // The DAE's y and y' by symbol, built on first use and shared by every program and the Jacobian.
  const UnknownSymbols& unknowns() {
    if (!unknowns_) unknowns_.emplace(dae_);
    return *unknowns_;
  }
  std::optional<UnknownSymbols> unknowns_;

  // A symbol no input binds: at the source that used it (the model's line if that has no location).
  void reportUnbound(const ProgramBuilder& b, const std::string& where, const char* help) {
    for (const auto& use : b.unboundSymbols()) {
      SourceRange r = use.source < m_.sources.size() ? m_.sources[use.source].range : SourceRange{};
      diags_.error(r.valid() ? r : dae_.range, DiagCode::E0602,
                   "'" + std::string(ctx_.symbolName(use.symbol)) + "' is not available in the " + where, help);
    }
  }

  // --- parameters ------------------------------------------------------------------------------

  // Depth-first post-order over "default of i uses j" in declaration order; cycles are reported.
  std::vector<uint32_t> parameterOrder() {
    size_t n = dae_.parameters.size();
    std::unordered_map<Expr, uint32_t> index;
    for (uint32_t k = 0; k < n; ++k) index[dae_.parameters[k].symbol] = k;
    std::vector<std::vector<uint32_t>> uses(n);
    for (uint32_t k = 0; k < n; ++k)
      if (dae_.parameters[k].value)
        for (Expr s : ctx_.freeSymbols(dae_.parameters[k].value))
          if (auto it = index.find(s); it != index.end()) uses[k].push_back(it->second);
    std::vector<uint32_t> order;
    std::vector<uint8_t> state(n, 0);  // 0 new, 1 on the path, 2 done
    for (uint32_t k = 0; k < n; ++k) visitParameter(k, uses, state, order);
    return order;
  }

  void visitParameter(uint32_t root, const std::vector<std::vector<uint32_t>>& uses, std::vector<uint8_t>& state,
                      std::vector<uint32_t>& order) {
    std::vector<std::pair<uint32_t, size_t>> stack;
    if (state[root] == 0) stack.emplace_back(root, 0), state[root] = 1;
    while (!stack.empty()) {
      auto& [k, next] = stack.back();
      if (next < uses[k].size()) {
        uint32_t j = uses[k][next++];
        if (state[j] == 1) cyclic_.insert(j), cyclic_.insert(k);
        if (state[j] == 0) stack.emplace_back(j, 0), state[j] = 1;
        continue;
      }
      state[k] = 2;
      order.push_back(k);
      stack.pop_back();
    }
  }
  std::unordered_set<uint32_t> cyclic_;

  // p_i = overridden_i ? given_i : default_i, in dependency order.
  void buildParameters() {
    ProgramBuilder b(programName(ModelProgram::Parameters));  // defaults see other parameters only (not time)
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (uint32_t k : parameterOrder()) {
      const auto& p = dae_.parameters[k];
      std::string text = p.value ? p.name + " = " + sym::toString(ctx_, p.value) : std::string();
      b.setSource(addSource("parameter " + p.name, p.declRange, text));
      bool usable = p.value && !cyclic_.count(k);
      if (cyclic_.count(k))
        diags_.error(p.declRange.valid() ? p.declRange : dae_.range, DiagCode::E0312,
                     "the value of parameter '" + p.name + "' depends on itself",
                     "break the cycle: a parameter cannot refer to itself, directly or through others");
      uint32_t given = b.emit(Op::LoadGiven, 0, 0, 0, k);
      uint32_t overridden = b.emit(Op::LoadOverridden, 0, 0, 0, k);
      uint32_t fallback = usable ? b.lower(p.value) : b.constant(nan);
      uint32_t value = b.emit(Op::Select, overridden, given, fallback);
      b.bindRegister(p.symbol, value);
      b.store(k, value);
    }
    reportUnbound(b, "parameter bindings", "a parameter's value may use only literals, constants and other parameters");
    m_.program(ModelProgram::Parameters) = b.finish(static_cast<uint32_t>(dae_.parameters.size()));
  }

  // --- start values ----------------------------------------------------------------------------

  std::unordered_map<size_t, size_t> initialEquationOf_;  ///< variable → the initial equation that sets it
  std::vector<dae::StartUse> startUse_;                   ///< per variable: what its start value is
  std::vector<dae::Equation> initialRows_;                ///< initial equations that are not start values

  struct Starts {
    std::vector<Expr> values;       ///< per variable: y0 (null: 0)
    std::vector<uint32_t> sources;  ///< per variable: the source of its value (UINT32_MAX: none)
  };

  // By symbol id, whether it is a parameter (built on first use: a model may have an initial
  // equation per element, each looked up here).
  bool isParameter(Expr s) {
    if (parameterSymbol_.empty() && !dae_.parameters.empty())
      for (const auto& p : dae_.parameters) {
        if (parameterSymbol_.size() <= p.symbol->symbolId) parameterSymbol_.resize(p.symbol->symbolId + 1, 0);
        parameterSymbol_[p.symbol->symbolId] = 1;
      }
    return s->symbolId < parameterSymbol_.size() && parameterSymbol_[s->symbolId];
  }
  std::vector<char> parameterSymbol_;

  bool overParameters(Expr e) {
    for (Expr s : ctx_.freeSymbols(e))
      if (s != dae_.time && !isParameter(s)) return false;
    return true;
  }

  // `v = expr` (either side) with expr over parameters and time: v's start value. (The value of
  // a derivative, `der(x) = expr`, is a condition of the initialization system.)
  bool applyInitialEquation(size_t i, Starts& starts) {
    const dae::Equation& e = dae_.initialEquations[i];
    if (!e.lhs || !e.rhs) return false;
    for (int side = 0; side < 2; ++side) {
      Expr target = side ? e.rhs : e.lhs, value = side ? e.lhs : e.rhs;
      if (!target->isSymbol() || !overParameters(value)) continue;
      std::optional<UnknownSymbols::Unknown> u = unknowns().find(target);
      if (!u || u->derivative) continue;
      size_t j = u->variable;
      if (!acceptInitialEquation(e, i, j, true)) return true;  // reported
      uint32_t src = addSource("initial equation " + std::to_string(i + 1), e.origin.range, equationText(e));
      starts.values[j] = value, starts.sources[j] = src, m_.description.edit().fixed[j] = kFixedAsWritten;
      startUse_[j] = dae::StartUse::Required;
      return true;
    }
    return false;
  }

  // What today's start values can honour, and nothing silently dropped (until the initialization
  // system of the structural issue solves any consistent mix): the derivative of a state follows
  // from the equations at the start, so `der(der(x)) = 5` or `der(x) = 0` of a first-order state is
  // refused; a value given twice, or given to a variable whose declared start is fixed, is a conflict.
  bool acceptInitialEquation(const dae::Equation& e, size_t i, size_t j, bool value) {
    const auto& v = dae_.variables[j];
    SourceRange at = e.origin.range.valid() ? e.origin.range : dae_.range;
    auto [it, first] = initialEquationOf_.try_emplace(j, i);
    if (!first) {
      auto& d = diags_.error(at, DiagCode::E0604, "the initial value of '" + v.name + "' is given twice",
                             "keep one of the two initial equations");
      d.notes.push_back({dae_.initialEquations[it->second].origin.range, "first given here"});
      return false;
    }
    if (v.declaration.start && v.declaration.fixed && v.declaration.fixedGiven) {
      auto& d = diags_.error(at, DiagCode::E0604,
                             "'" + v.name + "' has a fixed start value and this initial equation as well",
                             "remove one of the two, or declare the start a guess: " + v.name + "(start = ..., fixed = false)");
      d.notes.push_back({v.declaration.declRange, "declared here"});
      return false;
    }
    return true;
  }

  // One pass over the variables (a large model has millions): declared starts and their use.
  Starts collectStarts() {
    size_t n = dae_.variables.size();
    Starts starts;
    starts.values.resize(n);
    startUse_.resize(n);
    inTwoHalves(n, [&](size_t first, size_t last) {
      for (size_t j = first; j < last; ++j) {
        const dae::Declaration& d = dae_.variables[j].declaration;
        starts.values[j] = d.start;
        startUse_[j] = d.fixedGiven ? (d.fixed ? dae::StartUse::Required : dae::StartUse::Guess)  // as written
                       : m_.description->fixed[j] ? dae::StartUse::Default
                                                 : dae::StartUse::Guess;
      }
    });
    starts.sources.assign(n, UINT32_MAX);
    std::vector<char> looped = inRuns(numberRuns(starts.values), n);
    for (size_t j = 0; j < n; ++j)
      if (starts.values[j] && !looped[j])
        starts.sources[j] = addSource("start value of " + dae_.variables[j].name, dae_.variables[j].declaration.declRange);
    for (size_t i = 0; i < dae_.initialEquations.size(); ++i)
      if (!applyInitialEquation(i, starts)) initialRows_.push_back(dae_.initialEquations[i]);
    if (!initialRows_.empty()) planInitialRows();
    return starts;
  }

  // Initial equations that are not start values are rows of F used only at t0 (the run's initial
  // Newton solve); the starts they replace are computed instead of kept. After index reduction the
  // plan sees every row (the constraint and its derivatives); the run solves with the rows of the
  // dummy derivatives chosen at the start values.
  void planInitialRows() {
    std::optional<std::vector<char>> kept = dae::planInitialization(dae_, initialRows_, startUse_, ctx_, diags_);
    if (!kept) return;
    for (size_t j = 0; j < kept->size(); ++j)
      if (!(*kept)[j]) m_.description.edit().fixed[j] = kStartGuess;
  }

  // out = [y0 (n), yp0 (n), nominal (n)]; stores of a plain 0 serve no source. Runs of numbers
  // (a large array's starts, its zero derivatives and nominals) are stored by loops.
  void buildInitialValues() {
    Starts starts = collectStarts();
    ProgramBuilder b(programName(ModelProgram::InitialValues));
    bindInputs(b, false);
    auto n = static_cast<uint32_t>(dae_.variables.size());
    auto store = [&](uint32_t slot, Expr value, uint32_t source) {
      b.setSource(value ? source : UINT32_MAX);
      b.store(slot, value ? b.lower(value) : b.constant(0.0));
    };
    std::vector<Expr> derivatives(n, nullptr), nominal(n);  // y'0 = 0: no start value gives one
    inTwoHalves(n, [&](size_t first, size_t last) {
      for (size_t j = first; j < last; ++j) nominal[j] = dae_.variables[j].declaration.nominal;
    });
    storeSection(b, 0, starts.values, [&](uint32_t j) { store(j, starts.values[j], starts.sources[j]); });
    storeSection(b, n, derivatives, [&](uint32_t j) { store(n + j, nullptr, UINT32_MAX); });
    storeSection(b, 2 * n, nominal, [&](uint32_t j) {
      const auto& v = dae_.variables[j];
      store(2 * n + j, nominal[j], nominal[j] ? addSource("nominal value of " + v.name, v.declaration.declRange) : UINT32_MAX);
    });
    reportUnbound(b, "start values", "a start value may use only literals, constants, parameters and time");
    m_.program(ModelProgram::InitialValues) = b.finish(3 * n);
  }

  // A run of at least kLoopRun slots whose values are numbers (null is 0), all equal or c_k =
  // b·(k + 1) bit for bit (what `{b*i for i in 1:n}` flattens to): one loop stores it, with the
  // same values. Shorter runs, and anything computed, are stored one by one (and keep their sources).
  static constexpr size_t kLoopRun = 16;
  struct NumberRun {
    size_t begin, end;
    double base;
    bool proportional;  ///< value = base·(k + 1), k counted from `begin`; else `base`
  };

  static std::optional<double> numberOf(Expr e) {
    if (!e) return 0.0;
    return e->isConstant() ? std::optional<double>(e->value) : std::nullopt;
  }
  static bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

  static std::vector<NumberRun> numberRuns(const std::vector<Expr>& values) {
    std::vector<NumberRun> runs;
    for (size_t j = 0; j < values.size();) {
      std::optional<double> first = numberOf(values[j]);
      if (!first) {
        ++j;
        continue;
      }
      size_t equal = j + 1, proportional = j + 1;
      while (equal < values.size() && numberOf(values[equal]) && sameBits(*numberOf(values[equal]), *first)) ++equal;
      while (proportional < values.size() && numberOf(values[proportional]) &&
             sameBits(*numberOf(values[proportional]), *first * static_cast<double>(proportional - j + 1)))
        ++proportional;
      size_t end = std::max(equal, proportional);
      if (end - j >= kLoopRun) {
        runs.push_back({j, end, *first, proportional > equal});
        j = end;
      } else {
        ++j;
      }
    }
    return runs;
  }

  static std::vector<char> inRuns(const std::vector<NumberRun>& runs, size_t n) {
    std::vector<char> in(n, 0);
    for (const NumberRun& r : runs) std::fill(in.begin() + static_cast<long>(r.begin), in.begin() + static_cast<long>(r.end), 1);
    return in;
  }

  // Stores values[j] at slot0 + j: the runs by loops, the rest by storeOne(j), in order.
  template <class StoreOne>
  void storeSection(ProgramBuilder& b, uint32_t slot0, const std::vector<Expr>& values, StoreOne&& storeOne) {
    size_t j = 0;
    for (const NumberRun& r : numberRuns(values)) {
      for (; j < r.begin; ++j) storeOne(static_cast<uint32_t>(j));
      b.setSource(UINT32_MAX);
      uint32_t base = b.constant(r.base), one = r.proportional ? b.constant(1.0) : 0;
      b.beginLoop(Loop{.count = static_cast<uint32_t>(r.end - r.begin)});
      uint32_t value = base;
      if (r.proportional) value = b.emit(Op::Mul, base, b.emit(Op::Add, b.emit(Op::LoadLoopOffset), one));
      b.storeLooped(slot0 + static_cast<uint32_t>(r.begin), value);
      b.endLoop();
      j = r.end;
    }
    for (; j < values.size(); ++j) storeOne(static_cast<uint32_t>(j));
  }

  // --- residual and Jacobian ---------------------------------------------------------------------

  void buildResidualAndJacobian() {
    Expr cj = ctx_.symbol("$cj");
    JacobianEntries jac = initialRows_.empty() ? differentiate(dae_, unknowns(), ctx_, cj)
                                                : differentiate(withInitialRows(), unknowns(), ctx_, cj);
    auto nonzeros = static_cast<uint32_t>(jac.rowIndices.size());
    m_.description.edit().jacobianColumnStarts = std::move(jac.columnStarts);
    m_.description.edit().jacobianRowIndices = std::move(jac.rowIndices);
    std::vector<Expr> roots;
    std::vector<uint32_t> rows;  // the rows the roots are (template ones are not)
    for (uint32_t i : scalarRows_) roots.push_back(dae_.equations[i].residual), rows.push_back(i);
    for (size_t k = 0; k < initialRows_.size(); ++k) {  // after every DAE row: rows used only at t0
      const auto& e = initialRows_[k];
      auto row = static_cast<int32_t>(dae_.equations.size() + k);
      m_.description.edit().initialRows.push_back(row);
      m_.description.edit().initialRowLabels.push_back("initial equation " + equationText(e));
      equationSource_.push_back(addSource("initial equation (t0 only)", e.origin.range, equationText(e)));
      roots.push_back(e.residual), rows.push_back(static_cast<uint32_t>(row));
    }
    size_t rowRoots = roots.size();
    for (const ScalarEntry& e : jac.scalarEntries) roots.push_back(e.value);
    roots = sym::expandAngleDifferences(ctx_, roots);  // sin/cos of each angle once, shared
    sym::CseResult cse = sym::eliminateCommonSubexpressions(ctx_, roots, "$t");
    m_.sharedTemporaries = cse.temporaries.size();
    size_t n = dae_.equations.size() + initialRows_.size();

    ProgramBuilder res(programName(ModelProgram::Residual));
    bindInputs(res, true);
    for (const auto& [t, value] : cse.temporaries) res.bindTemporary(t, value);
    for (size_t k = 0; k < rowRoots; ++k) res.setSource(equationSource_[rows[k]]), res.store(rows[k], res.lower(cse.outputs[k]));
    for (size_t b = 0; b < dae_.templateBlocks.size(); ++b) emitBlock(res, b, jac, false);
    reportUnbound(res, "residual", "declare it as a variable or a parameter");
    m_.program(ModelProgram::Residual) = res.finish(static_cast<uint32_t>(n));

    ProgramBuilder jb(programName(ModelProgram::Jacobian));
    bindInputs(jb, true, cj);
    for (const auto& [t, value] : cse.temporaries) jb.bindTemporary(t, value);
    for (size_t k = 0; k < jac.scalarEntries.size(); ++k) {
      const ScalarEntry& e = jac.scalarEntries[k];
      jb.setSource(equationSource_[e.row]);
      jb.store(e.position, jb.lower(cse.outputs[rowRoots + k]));
    }
    jb.reserveIndexTable(jacobianIndexTableSize(jac));
    for (size_t b = 0; b < dae_.templateBlocks.size(); ++b) emitBlock(jb, b, jac, true);
    m_.program(ModelProgram::Jacobian) = jb.finish(nonzeros);
  }

  // What the Jacobian's blocks append to its index table: every template entry's CSC positions
  // and the offsets of each block that loops over a table (more than one dimension).
  size_t jacobianIndexTableSize(const JacobianEntries& jac) const {
    size_t n = 0;
    std::vector<char> hasEntries(dae_.templateBlocks.size(), 0);
    for (const TemplateEntry& e : jac.templateEntries) n += e.positions.size(), hasEntries[e.block] = 1;
    for (size_t b = 0; b < hasEntries.size(); ++b)
      if (hasEntries[b] && dae_.templateBlocks[b].region.size() > 1) n += flat::pointCount(dae_.templateBlocks[b].region);
    return n;
  }

  // --- template blocks (issue 15, docs/loops.md) ---------------------------------------------------

  // One loop over block b's region: its rows (residual) or its Jacobian entries, each stored at its
  // CSC position through an index table. The block's own CSE; temporaries that read no relative
  // symbol (parameters only) are computed once before the loop. The entries' positions move to the
  // program's index table (freed here: a large model has millions).
  void emitBlock(ProgramBuilder& b, size_t k, JacobianEntries& jac, bool jacobian) {
    const dae::TemplateBlock& block = dae_.templateBlocks[k];
    std::vector<Expr> roots;
    std::vector<TemplateEntry*> entries;
    if (!jacobian) roots.push_back(block.residual);
    for (TemplateEntry& e : jac.templateEntries)
      if (jacobian && e.block == static_cast<int>(k)) roots.push_back(e.value), entries.push_back(&e);
    if (roots.empty()) return;
    std::vector<Expr> perIteration = iteratorsFromOffset(b, roots, block.region);
    sym::CseResult cse = sym::eliminateCommonSubexpressions(ctx_, roots, "$b" + std::to_string(k) + (jacobian ? "j" : "r"));
    b.setSource(blockSource(k));
    long base = openLoop(b, cse, jac.templateOperands[k], perIteration, block.shape, block.region);
    if (!jacobian) b.storeLooped(static_cast<uint32_t>(block.firstRow + base), b.lower(cse.outputs[0]));
    for (size_t e = 0; e < entries.size(); ++e) {
      b.storeIndexed(b.appendIndexTable(entries[e]->positions), b.lower(cse.outputs[e]));
      std::vector<uint32_t>().swap(entries[e]->positions);
    }
    b.endLoop();
  }

  using Operand = TemplateOperand;

  // Opens the loop of a template over `region` (arrays of `shape`): its operands as loads from the
  // region's first point on, its CSE temporaries bound, those that read nothing per iteration (no
  // operand, not the loop offset) lowered before the loop. Returns that first point's linear index.
  long openLoop(ProgramBuilder& b, const sym::CseResult& cse, const std::vector<Operand>& operands,
                const std::vector<Expr>& perIteration, const std::vector<int>& shape, const flat::Box& region) {
    std::vector<long> lo;
    for (auto [first, last] : region) lo.push_back(first);
    long base = flat::linearIndex(shape, lo);
    for (const auto& op : operands)
      b.bindLoopedLoad(op.symbol, op.parameter ? Op::LoadPLooped : op.derivative ? Op::LoadYpLooped : Op::LoadYLooped,
                       static_cast<uint32_t>(op.variable + base + op.offset));
    for (const auto& [t, value] : cse.temporaries) b.bindTemporary(t, value);
    for (Expr t : invariantTemporaries(cse, operands, perIteration)) b.lower(t);
    b.beginLoop(loopOver(b, shape, region, base));
    return base;
  }

  // Row-major points of the region as offsets from its first point: an affine loop in one
  // dimension, a table of offsets in more.
  static Loop loopOver(ProgramBuilder& b, const std::vector<int>& shape, const flat::Box& region, long base) {
    Loop loop;
    loop.count = static_cast<uint32_t>(flat::pointCount(region));
    if (region.size() == 1) return loop;
    std::vector<uint32_t> offsets;
    offsets.reserve(loop.count);
    flat::forEachPoint(region, [&](std::span<const long> p, size_t) {
      offsets.push_back(static_cast<uint32_t>(flat::linearIndex(shape, p) - base));
    });
    loop.offsetTable = b.appendIndexTable(offsets);
    return loop;
  }

  // A template's iterators used as numbers (%k, flat::ElementPatterns::iteratorSymbol) in `roots`,
  // in the loop over `region` (row-major from its first point): in one dimension first + L, L read
  // with ldidx (L = c); in more, first_k + X[t_k + c], from a table of each point's subscript k
  // (minus first_k) read with ldx. Returns the symbols bound per iteration (none if no root reads
  // an iterator).
  std::vector<Expr> iteratorsFromOffset(ProgramBuilder& b, std::vector<Expr>& roots, const flat::Box& region) {
    if (!dae_.patterns || std::none_of(roots.begin(), roots.end(), [&](Expr r) { return dae_.patterns->readsIterator(ctx_, r); }))
      return {};
    std::vector<Expr> perIteration;
    std::unordered_map<Expr, Expr> map;
    for (size_t k = 0; k < region.size(); ++k) {
      Expr value = ctx_.symbol("$X" + std::to_string(k + 1));
      if (region.size() == 1) {
        b.bindLoopOffset(value);
      } else {
        std::vector<uint32_t> subscripts;
        subscripts.reserve(flat::pointCount(region));
        flat::forEachPoint(region, [&](std::span<const long> p, size_t) { subscripts.push_back(static_cast<uint32_t>(p[k] - region[k].first)); });
        b.bindLoopedLoad(value, Op::LoadTable, b.appendIndexTable(subscripts));
      }
      perIteration.push_back(value);
      map.emplace(dae_.patterns->iteratorSymbol(ctx_, static_cast<int>(k)), ctx_.add(value, ctx_.constant(double(region[k].first))));
    }
    for (Expr& r : roots) r = ctx_.substitute(r, map);
    return perIteration;
  }

  // The temporaries whose values read no relative symbol (nor the loop offset), directly or through
  // other temporaries (CSE lists a temporary after those it uses).
  std::vector<Expr> invariantTemporaries(const sym::CseResult& cse, const std::vector<Operand>& operands,
                                         const std::vector<Expr>& perIteration = {}) {
    std::unordered_set<Expr> variant(perIteration.begin(), perIteration.end());
    for (const auto& op : operands) variant.insert(op.symbol);
    std::vector<Expr> invariant;
    for (const auto& [t, value] : cse.temporaries) {
      bool reads = false;
      for (Expr s : ctx_.freeSymbols(value)) reads = reads || variant.count(s);
      if (reads) variant.insert(t);
      else invariant.push_back(t);
    }
    return invariant;
  }

  uint32_t blockSource(size_t k) {
    const dae::TemplateBlock& block = dae_.templateBlocks[k];
    std::string what = block.origin == flat::OriginKind::Kinematic      ? "velocities"
                       : block.origin == flat::OriginKind::EulerLagrange ? "Euler-Lagrange equations"
                                                                        : "equations";
    return addSource(what + " of elements [" + regionText(block.region) + "] (one loop)", block.range);
  }

  static std::string regionText(const flat::Box& region) {
    std::string text;
    for (auto [first, last] : region)
      text += (text.empty() ? "" : ", ") + std::to_string(first) + (last > first ? ":" + std::to_string(last) : "");
    return text;
  }

  dae::Dae withInitialRows() const {
    dae::Dae d = dae_;
    d.equations.insert(d.equations.end(), initialRows_.begin(), initialRows_.end());
    return d;
  }

  // --- outputs and invariants --------------------------------------------------------------------

  // out[i] = values[i]; `after` may add to them (an invariant's sums).
  // out[slots[i]] = values[i] (slots empty: out[i]), `count` outputs in all; `after` may add to
  // them (an invariant's sums) or store the others (output blocks).
  template <class After = void (*)(ProgramBuilder&)>
  Program buildMonitor(ModelProgram program, const std::vector<Expr>& values, const std::vector<uint32_t>& sources,
                       After after = [](ProgramBuilder&) {}, const std::vector<uint32_t>& slots = {},
                       std::optional<size_t> count = std::nullopt) {
    sym::CseResult cse = sym::eliminateCommonSubexpressions(ctx_, values, "$t");
    ProgramBuilder b(programName(program));
    bindInputs(b, true);
    for (const auto& [t, value] : cse.temporaries) b.bindTemporary(t, value);
    for (uint32_t i = 0; i < values.size(); ++i)
      b.setSource(sources[i]), b.store(slots.empty() ? i : slots[i], b.lower(cse.outputs[i]));
    after(b);
    reportUnbound(b, programName(program), "declare it as a variable or a parameter");
    return b.finish(static_cast<uint32_t>(count.value_or(values.size())));
  }

  // The outputs with a value of their own, then the sums of some and the output blocks (one loop each).
  Program buildOutputs() {
    std::vector<Expr> values;
    std::vector<uint32_t> sources, slots;
    for (uint32_t i = 0; i < dae_.outputs.size(); ++i) {
      const flat::Output& o = dae_.outputs[i];
      if (!o.value) continue;  // an output block's
      values.push_back(o.value);
      slots.push_back(i);
      sources.push_back(addSource("output " + o.name, o.range, o.name + " = " + sym::toString(ctx_, o.value)));
    }
    auto after = [&](ProgramBuilder& b) {
      LoopOperands operands(dae_, ctx_, unknowns());
      for (uint32_t i = 0; i < dae_.outputs.size(); ++i)
        for (size_t k = 0; k < dae_.outputs[i].sums.size(); ++k)
          emitSum(b, i, dae_.outputs[i].sums[k], "output " + dae_.outputs[i].name, "$o" + std::to_string(i) + "_" + std::to_string(k),
                  dae_.outputs[i].range, operands);
      for (size_t k = 0; k < dae_.outputBlocks.size(); ++k) emitOutputBlock(b, k, operands);
    };
    return buildMonitor(ModelProgram::Outputs, values, sources, after, slots, dae_.outputs.size());
  }

  // Outputs first..first + count − 1 of an output block: one loop storing its value at each point.
  void emitOutputBlock(ProgramBuilder& b, size_t k, LoopOperands& reader) {
    const dae::OutputBlock& block = dae_.outputBlocks[k];
    std::vector<int> shape{block.count};
    flat::Box box{{1, block.count}};
    std::vector<Operand> operands = reader.read(shape, box, block.value);
    std::vector<Expr> body{block.value};
    std::vector<Expr> perIteration = iteratorsFromOffset(b, body, box);
    sym::CseResult cse = sym::eliminateCommonSubexpressions(ctx_, body, "$ob" + std::to_string(k));
    const std::string& first = dae_.outputs[block.first].name;
    const std::string& last = dae_.outputs[block.first + block.count - 1].name;
    b.setSource(addSource("outputs " + first + " … " + last + " (one loop)", block.range));
    long base = openLoop(b, cse, operands, perIteration, shape, box);
    b.storeLooped(static_cast<uint32_t>(block.first + base), b.lower(cse.outputs[0]));
    b.endLoop();
  }

  Program buildInvariants() {
    std::vector<Expr> values;
    std::vector<uint32_t> sources;
    for (const auto& inv : dae_.invariants) {
      values.push_back(inv.value);
      sources.push_back(addSource("invariant " + inv.name + " (" + inv.kind + ")", dae_.range));
    }
    return buildMonitor(ModelProgram::Invariants, values, sources, [&](ProgramBuilder& b) {
      LoopOperands operands(dae_, ctx_, unknowns());
      for (uint32_t i = 0; i < dae_.invariants.size(); ++i)
        for (size_t k = 0; k < dae_.invariants[i].sums.size(); ++k)
          emitSum(b, i, dae_.invariants[i].sums[k], "invariant " + dae_.invariants[i].name,
                  "$s" + std::to_string(i) + "_" + std::to_string(k), dae_.range, operands);
    });
  }

  // A sum of monitored quantity i (an invariant's, an output's): one loop adding its body at every
  // point of its box to out[i] (after the quantity's scalar part was stored there), with the body's
  // own CSE (temporaries named `prefix`…) and its loop-invariant temporaries computed before the loop.
  void emitSum(ProgramBuilder& b, uint32_t i, const flat::IndexedTerm& sum, const std::string& what, const std::string& prefix,
               SourceRange range, LoopOperands& reader) {
    std::vector<Operand> operands = reader.read(sum.shape, sum.box, sum.body);
    std::vector<Expr> body{sum.body};
    std::vector<Expr> perIteration = iteratorsFromOffset(b, body, sum.box);
    sym::CseResult cse = sym::eliminateCommonSubexpressions(ctx_, body, prefix);
    b.setSource(addSource(what + ": sum over [" + regionText(sum.box) + "] (one loop)", range));
    openLoop(b, cse, operands, perIteration, sum.shape, sum.box);
    b.storeAdd(i, b.lower(cse.outputs[0]));
    b.endLoop();
  }
};

}  // namespace

KernelModule buildKernels(const dae::Dae& dae, sym::Context& ctx, DiagnosticEngine& diags) {
  return Builder(dae, ctx, diags).run();
}

}  // namespace qdot::kernel
