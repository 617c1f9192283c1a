// FlatModel: one model after flattening — every array, for-loop, reduction and comprehension
// expanded to scalar variables (`x[1]`, `M[1,2]`), definitions substituted, constants and Integer
// parameters folded, every expression a symbolic DAG over the variables' symbols. Every equation
// and energy term remembers the source range it came from. Handed to the mechanics stage.
// Variable names are views of their symbols' names (owned by the Context), descriptions and units
// views of the AST: both outlive the FlatModel, and a large model has one variable per element.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "support/SourceManager.h"
#include "symbolic/Expr.h"

namespace qdot::flat {

enum class VarRole : uint8_t {
  Time,          ///< the independent variable `time`
  Parameter,     ///< run-time parameter (Real or Boolean); `value` is its default
  Coordinate,    ///< generalized coordinate q
  Velocity,      ///< der(q) of a coordinate (a state of the first-order system)
  Acceleration,  ///< der(der(q))
  Unknown,       ///< `Real x;`: a state if der(x) appears, otherwise algebraic
  Derivative,    ///< der(x) of an Unknown
  Multiplier,    ///< Lagrange multiplier of a constraint
};
const char* roleName(VarRole r);

/// What few variables have, kept beside them: a variable refers to a record (Variable::attributes),
/// and the elements of an array share one as long as they are given the same values (its
/// description, a unit or nominal written once for all).
struct VariableAttributes {
  std::string_view description;
  std::string_view unit;
  sym::Expr nominal = nullptr, min = nullptr, max = nullptr;
};

// A large model has three of these per array element (x, der(x), der(der(x))): what most of them
// never have lives in VariableAttributes, and the indices and flags fill what would be padding.
struct Variable {
  std::string_view name;  ///< user-facing scalar name: `th[1]`, `der(th[1])` (the symbol's name)
  VarRole role = VarRole::Unknown;
  bool fixed = false;
  bool fixedGiven = false;  ///< `fixed` written by the user (else a default: a coordinate's start is fixed)
  bool input = false;  ///< Parameter: an `input` of the model (value 0 unless set; B of `qdot linearize`)
  int derivative = -1;  ///< index of the variable that is der(this), -1 if none
  sym::Expr symbol = nullptr;
  SourceRange declRange;  ///< the declaration's name (or the der() that created it)
  int derivativeOf = -1;  ///< this is der(variables[derivativeOf])
  sym::Expr start = nullptr;  ///< start attribute (over parameters); null if none
  sym::Expr value = nullptr;  ///< Parameter: default value (over other parameters)
  /// Not an unknown: equal to this expression (another variable, or one of parameters and time)
  /// through connections and alias equations (`a.s = s`, `a.s = s0`). The Euler–Lagrange rows are
  /// derived with the variable itself; the DAE substitutes the alias everywhere.
  sym::Expr alias = nullptr;
  int attributes = 0;  ///< index in FlatModel::attributes (0: none)
};
static_assert(sizeof(Variable) <= 80, "flat::Variable: a large model has three per array element (see above)");

enum class OriginKind {
  Equation,         ///< a line of the equation section
  InitialEquation,  ///< a line of the initial equation section
  EulerLagrange,    ///< the Euler–Lagrange row of a coordinate
  Kinematic,        ///< der(q) is the velocity of q
  Constraint,       ///< a holonomic constraint
  Connection,       ///< the flows of a connection set sum to zero (an unconnected flow is zero)
};

/// Where a flat equation came from, for diagnostics (Rumoca's practice).
struct Origin {
  OriginKind kind = OriginKind::Equation;
  SourceRange range;
  int variable = -1;  ///< EulerLagrange/Kinematic: the coordinate; Constraint: its multiplier
  std::string element;  ///< for array equations: which element, e.g. "[2]"
  int component = 0;    ///< which component instance wrote it (FlatModel::components; 0 = the model)
  int differentiated = 0;  ///< how many times index reduction differentiated it (0: as written)
};

/// `residual = 0` (user equations are stored as lhs - rhs).
struct Equation {
  sym::Expr residual = nullptr;
  Origin origin;
  sym::Expr lhs = nullptr, rhs = nullptr;  ///< the sides as written (for printing), if any
};

/// One contribution to T, V, D or a generalized force, with the statement it came from.
struct Term {
  sym::Expr value = nullptr;
  SourceRange range;
  bool connectionFlow = false;  ///< a force: a connector's flow (spec §7), not a `force(q)` statement
};

/// A box of subscripts or iterator values (issue 15): per dimension its first and last value,
/// inclusive. Every template ranges over one; these are the only walks over them.
using Box = std::vector<std::pair<long, long>>;

/// The number of points of a box (0 if a dimension is empty).
inline size_t pointCount(const Box& box) {
  size_t n = 1;
  for (auto [lo, hi] : box) n *= hi >= lo ? static_cast<size_t>(hi - lo + 1) : 0;
  return n;
}

/// f(point) for every point of the box, row-major (the last dimension fastest), and f's count c
/// (0, 1, …: the order of a loop over the box).
template <class F>
void forEachPoint(const Box& box, F&& f) {
  if (pointCount(box) == 0) return;
  std::vector<long> point;
  for (auto [lo, hi] : box) point.push_back(lo);
  for (size_t c = 0;; ++c) {
    f(std::span<const long>(point), c);
    size_t d = point.size();
    while (d > 0 && ++point[d - 1] > box[d - 1].second) point[d - 1] = box[d - 1].first, --d;
    if (d == 0) return;
  }
}

/// The row-major index (0-based) of 1-based subscripts in an array of `shape`.
inline long linearIndex(std::span<const int> shape, std::span<const long> subscripts) {
  long k = 0;
  for (size_t d = 0; d < shape.size(); ++d) k = k * shape[d] + (subscripts[d] - 1);
  return k;
}

/// An array kept whole so that repeated structure stays repeated (issue 15, docs/loops.md): its
/// elements, row-major, are still scalar expressions (a declared variable's are its variables'
/// symbols). `derivative` is the array of the elements' der() (-1 until it is needed).
struct ArrayVariable {
  std::string name;  ///< the declaration's name: "x", "der(x)"
  std::vector<int> shape;
  std::vector<sym::Expr> elements;
  int derivative = -1;
};

/// What a relative symbol such as `x[%1+1]` stands for inside a template: the element of array
/// `array` whose subscript in dimension d is (value of iterator dims[d].iterator) + dims[d].offset,
/// or the constant dims[d].offset when that iterator is -1. Subscripts are 1-based.
struct RelativeElement {
  struct Dim {
    int iterator = -1;
    int offset = 0;
  };
  int array = -1;
  std::vector<Dim> dims;
};

/// The arrays templates index and their relative symbols: an interning table beside the symbolic
/// Context. Later stages add the patterns they derive (shifted offsets, derivatives) as they add
/// nodes to the Context, so the FlatModel holds it by shared pointer.
class ElementPatterns {
 public:
  std::vector<ArrayVariable> arrays;

  /// The relative symbol of a pattern, named after it ("x[%1+1]", "z[1,%2]"); made on first use.
  sym::Expr symbol(sym::Context& ctx, const RelativeElement& rel);
  /// The pattern a symbol stands for, or nullptr.
  const RelativeElement* find(sym::Expr s) const {
    if (elements_.empty() || !s->isSymbol()) return nullptr;
    auto it = elements_.find(s->symbolId);
    return it == elements_.end() ? nullptr : &it->second;
  }
  /// The element a relative symbol stands for at a point of its template's iterators.
  sym::Expr elementAt(const RelativeElement& rel, std::span<const long> point) const;

  /// The value of a template's iterator k (0-based) used as a number (`0.1*i`), the symbol `%k+1`;
  /// made on first use. In one dimension only: a 1-D loop computes it from its offset (ldidx).
  sym::Expr iteratorSymbol(sym::Context& ctx, int k);
  /// The iterator whose value a symbol is, or -1.
  int iteratorOf(sym::Expr s) const {
    for (size_t k = 0; k < iterators_.size(); ++k)
      if (iterators_[k] == s) return static_cast<int>(k);
    return -1;
  }
  /// Whether e reads an iterator's value.
  bool readsIterator(const sym::Context& ctx, sym::Expr e) const;

 private:
  std::unordered_map<uint32_t, RelativeElement> elements_;  ///< by symbolId
  std::vector<sym::Expr> iterators_;                        ///< by iterator
};

/// `sum(body for i in a:b, j in c:d)` in an energy, kept as one template instead of one term per
/// element: Σ over the box of iterator values of `body`, an expression over parameters, time, plain
/// variables and relative symbols (the iterators appear only in subscripts).
/// The sum is a summand of kinetic/potential/dissipation[term] (which holds the other summands).
struct IndexedSum {
  enum class Energy : uint8_t { Kinetic, Potential, Dissipation };
  Energy energy = Energy::Kinetic;
  int term = -1;
  Box box;  ///< per iterator: first and last value
  sym::Expr body = nullptr;
  SourceRange range;  ///< the sum(...) call
};

/// `for i in a:b, j in c:d loop force(x[i+o, j+p]) = body; end for` in the mechanics section, kept
/// as one template instead of one force per element (FlattenLimits::keepLoops, issue 15): at every
/// point of the box the generalized force `body` on the element `target` (a relative symbol of an
/// array of coordinates, subscript d iterator d plus a constant). Expanded, its forces go to
/// FlatModel::forces at `position`, where the scalar lowering puts them: point by point, the
/// forces of one loop (its `first` template and those after it with the same `first`) in turn.
struct IndexedForce {
  Box box;  ///< per iterator: first and last value
  sym::Expr target = nullptr;
  sym::Expr body = nullptr;
  SourceRange range;  ///< the force statement
  size_t position = 0;
  size_t first = 0;  ///< index in FlatModel::indexedForces of its loop's first force
};

/// Σ over a box of iterator values of `body`, an expression over relative symbols (%k: iterator k)
/// whose arrays have `shape` and are subscripted in dimension d by iterator d plus a constant (in one
/// dimension, any length): a sum over every element that a loop computes (issue 15) — a templated
/// model's Jacobi integral.
struct IndexedTerm {
  Box box;
  std::vector<int> shape;
  sym::Expr body = nullptr;
};

/// `for i in a:b, j in c:d loop der(x[i, j]) = rhs; end for` kept as one template instead of one
/// equation per point (issue 15, docs/loops.md): the equation at every point of the box, its sides
/// over relative symbols (`der(x)[%1,%2]`, `x[%1+1,%2]`), parameters and time. Only the loops whose
/// body is `der(x[i, …]) = …` with x indexed by the iterators in order, and only when flattened with
/// FlattenLimits::keepForEquations.
struct EquationTemplate {
  Box box;  ///< per iterator (nested loops: outer first): first and last value
  sym::Expr lhs = nullptr, rhs = nullptr;
  Origin origin;  ///< the equation inside the loop (no element)
};

/// How the runtime treats an output column between rows (`annotation(unwrap = …)`): an angle made
/// continuous by multiples of 2π, or one of a z-x-z Euler-angle triple ψ, θ, φ (a rigid body's),
/// made continuous together (θ changes sign where the body passes through θ = 0).
enum class OutputKind : uint8_t { Plain, Angle, EulerPsi, EulerTheta, EulerPhi };

/// An output column: `value`, plus with templates (FlattenLimits::keepLoops) the sums over boxes
/// that its binding's `sum(... for i in a:b)` summands are kept as: the output is value + Σ sums.
/// The flattener records them with an empty shape; the pipeline gives each the shape of the
/// coordinates it reads where a loop can compute it and expands the others (expandOutputSums).
struct Output {
  std::string name;
  sym::Expr value = nullptr;
  SourceRange range;
  OutputKind kind = OutputKind::Plain;
  std::vector<IndexedTerm> sums;
};

struct Experiment {
  std::optional<double> startTime, stopTime, interval, tolerance;
};

struct FlatModel {
  std::string name;
  std::string description;
  SourceRange range;
  std::vector<Variable> variables;    ///< variables[kTime] is `time`
  std::vector<int> symbolToVariable;  ///< indexed by sym symbolId; -1 for non-variable symbols
  /// Variable::attributes indexes these; [0] has none (the attributes of most variables).
  std::vector<VariableAttributes> attributes = std::vector<VariableAttributes>(1);
  std::vector<Equation> equations;
  std::vector<Equation> initialEquations;
  std::vector<Term> kinetic, potential, dissipation;
  std::vector<std::pair<int, Term>> forces;  ///< (coordinate variable, term)
  std::vector<Equation> constraints;         ///< g(q, t) = 0, origin.range = the statement
  std::vector<Output> outputs;
  /// Repeated structure kept as templates (only when flattened with FlattenLimits::keepLoops; see
  /// expandIndexedSums): the sums, the arrays their relative symbols index, and those symbols.
  std::vector<IndexedSum> indexedSums;
  std::vector<IndexedForce> indexedForces;  ///< `force(x[i]) = …` in `for` loops, kept as templates
  std::shared_ptr<ElementPatterns> patterns = std::make_shared<ElementPatterns>();
  /// Equations `z = … + sum(…)` of the model (z a scalar unknown, the sums over coordinates or
  /// velocities) whose sums are kept as templates (FlattenLimits::keepLoops): by equation index, the
  /// sums its rhs (and residual) leave out. The pipeline makes such an equation an output (z defined
  /// explicitly) or expands them (expandIndexedSums); no stage after flattening sees them.
  std::vector<std::pair<size_t, std::vector<IndexedTerm>>> equationSums;
  /// A template or summand was lowered with a factor distributed over a sum (`0.5*m*sum(…)`) or
  /// reads an iterator as a number: expanded, the model equals the scalar lowering to rounding,
  /// not node for node (the pipeline then flattens again rather than expand).
  bool templatesRound = false;
  /// `for` equations kept as templates (FlattenLimits::keepForEquations); their points are not in
  /// `equations`.
  std::vector<EquationTemplate> equationTemplates;
  /// The component instances, by path ("m1", "ms[2]", "sys.m1"); [0] is the model itself ("").
  std::vector<std::string> components;
  /// Components' connectors joined to nothing (their flows are 0), by path, with the component's
  /// declaration: the structural checks name them when they leave something undetermined.
  std::vector<std::pair<std::string, SourceRange>> unconnected;
  /// The connections do no work on the system: every connector's flow is a force on one of its
  /// component's coordinates or acts where the potential is fixed, so the flows of each node cancel
  /// in the power balance (what the Jacobi integral needs of a component model).
  bool connectionsConserveEnergy = true;
  Experiment experiment;
  /// The scalar Integer parameters the model uses, as "n = 8": structural (they size arrays), so
  /// fixed in what is compiled from this model (shown by executables' --help).
  std::vector<std::string> structuralParameters;

  static constexpr int kTime = 0;  ///< index of `time` in variables (a keyword: no other variable has its name)
  sym::Expr time() const { return variables[kTime].symbol; }

  /// The variable a symbol stands for, or -1 (a variable's symbol has the variable's name, so
  /// ctx.findSymbol(name) and this find a variable by name).
  int variableOf(sym::Expr s) const {
    return s->isSymbol() && s->symbolId < symbolToVariable.size() ? symbolToVariable[s->symbolId] : -1;
  }
  const VariableAttributes& attributesOf(const Variable& v) const { return attributes[v.attributes]; }
  /// The relative element a symbol stands for, or nullptr.
  const RelativeElement* relativeElement(sym::Expr s) const { return patterns->find(s); }
  /// In order; a large model's variables (3·10⁶ at 10⁶ masses) are looked through in two halves.
  std::vector<int> variablesWithRole(VarRole r) const;
};

}  // namespace qdot::flat
