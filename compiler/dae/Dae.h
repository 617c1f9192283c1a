// The DAE IR: one implicit system F(t, y, y', p) = 0 assembled from a FlatModel and its
// equations of motion. Variables are classified (differential state or algebraic) and ordered
// as results are written: coordinates, velocities, other states, algebraic variables, multipliers.
// Every equation keeps its Origin. This is what structural analysis and the kernels consume.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "flatten/FlatModel.h"
#include "mechanics/EulerLagrange.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"

namespace qdot::dae {

enum class VarKind : uint8_t { State, Algebraic };
/// What an unknown of the DAE is in the mechanics (what a declaration is: flat::VarRole).
enum class UnknownRole : uint8_t { Coordinate, Velocity, State, Algebraic, Multiplier, Derivative };
const char* roleName(UnknownRole r);

/// What the later stages read of an unknown's declaration: where it is, its start value (over
/// parameters; null = none) and nominal value, and whether the start is fixed. Not the whole
/// flat::Variable: a large model has two unknowns per array element, and the rest of the
/// declaration (name, symbol, role, description, unit, min, max) is either in the Variable or unused.
struct Declaration {
  SourceRange declRange;
  bool fixed = false;
  bool fixedGiven = false;  ///< `fixed` written by the user (flat::Variable::fixedGiven)
  sym::Expr start = nullptr;
  sym::Expr nominal = nullptr;

  static Declaration of(const flat::FlatModel& m, int variable) {
    const flat::Variable& f = m.variables[variable];
    return {.declRange = f.declRange, .fixed = f.fixed, .fixedGiven = f.fixedGiven, .start = f.start,
            .nominal = m.attributesOf(f).nominal};
  }
};

/// An unknown of the DAE: what the DAE makes of it (kind, role, symbols, result name) and what it
/// keeps of its declaration in the flat model.
struct Variable {
  std::string name;  ///< result name: "x", "der(x)", "lambda[1]"
  VarKind kind = VarKind::Algebraic;
  UnknownRole role = UnknownRole::Algebraic;
  int flatVar = -1;        ///< index in the FlatModel (-1 for multipliers)
  sym::Expr y = nullptr;   ///< the variable's symbol
  sym::Expr yp = nullptr;  ///< its time-derivative symbol (states only)
  /// A velocity without a declared start starts at 0; a multiplier's declaration is made by
  /// buildDae (the constraint's range).
  Declaration declaration;
};
static_assert(sizeof(Variable) <= 88, "dae::Variable: a large model has two per array element");

/// A DAE equation is a flat equation (residual, origin, the sides as written).
using Equation = flat::Equation;

struct Parameter {
  std::string name;
  sym::Expr symbol = nullptr;
  sym::Expr value = nullptr;  ///< default, over other parameters
  std::string description, unit;
  SourceRange declRange;
  bool input = false;  ///< an `input` of the model (a parameter whose default is 0)
};

/// A row of F that says der(variable) = derivative: a kinematic row q' = der(q), or one added by
/// index reduction. Together they form derivative chains (x, der(x), der(der(x))). After index
/// reduction the run-time dummy derivative selection drops some of them (see differentiatedRows).
struct DerivativeLink {
  int row;
  int variable;
  int derivative;
};

/// A quantity conserved along solutions (first integral) or otherwise worth monitoring.
struct Invariant {
  std::string name;
  std::string kind;  ///< "cyclic momentum" or "Jacobi integral"
  sym::Expr value = nullptr;
  /// Added to `value`: sums over every element (mech::FirstIntegral::sums), over relative symbols
  /// (Dae::patterns) whose elements are unknowns (their y) or parameters.
  std::vector<flat::IndexedTerm> sums;
};

/// Rows of F given by one template (issue 15, docs/loops.md): the rows of the elements of an array
/// over a box of subscripts. Row of the element with subscripts s: firstRow + linear(s), linear the
/// row-major index in `shape` (0 for (1, …, 1)); those rows' Equation::residual is null. The
/// residual is over relative symbols (Dae::patterns) whose arrays have this shape and whose
/// elements are unknowns in the same order (their y or y' symbols).
struct TemplateBlock {
  int firstRow = -1;
  std::vector<int> shape;
  flat::Box region;  ///< per dimension: first and last subscript
  sym::Expr residual = nullptr;
  flat::OriginKind origin = flat::OriginKind::EulerLagrange;
  SourceRange range;  ///< the array's declaration
};

/// Outputs given by one template (dae::rerollOutputs' runs): outputs [first, first + count), each
/// the value at its point i = 1..count of an expression over relative symbols (Dae::patterns) whose
/// arrays have `count` elements; those outputs' Output::value is null.
struct OutputBlock {
  int first = -1;
  int count = 0;
  sym::Expr value = nullptr;
  SourceRange range;  ///< the first output's
};

struct Dae {
  std::string name, description;
  SourceRange range;
  sym::Expr time = nullptr;
  std::vector<Variable> variables;
  std::vector<Parameter> parameters;
  std::vector<Equation> equations;  ///< Euler–Lagrange rows first (one per coordinate), then kinematic, user, constraints
  std::vector<Equation> initialEquations;
  std::vector<flat::Output> outputs;
  std::vector<Invariant> invariants;
  std::vector<int> coordinates;  ///< variable indices of the coordinates, in declaration order
  /// The coordinate of each Euler–Lagrange row (the first rowCoordinates.size() equations), also
  /// of coordinates that are not unknowns (a connector potential equal to another variable).
  std::vector<std::string> rowCoordinates;
  flat::Experiment experiment;
  std::vector<std::string> structuralParameters;  ///< "n = 8" (flat::FlatModel::structuralParameters)
  std::vector<std::pair<std::string, SourceRange>> unconnected;  ///< flat::FlatModel::unconnected
  std::vector<DerivativeLink> links;  ///< every row of the form der(variable) = derivative
  /// Index reduction (reduceIndex): per differentiated equation its rows e, e', e'', … The system then
  /// has more rows than unknowns, by dummyDerivativeCount(): the dummy derivative method keeps
  /// every row except as many links as there are derivatives of equations, chosen at run time where
  /// the differentiated equations can be solved for them (Mattsson–Söderlind).
  std::vector<std::vector<int>> differentiatedRows;
  /// Rows kept as templates (only when the equations of motion have template rows) and the
  /// relative symbols' table they use.
  std::vector<TemplateBlock> templateBlocks;
  std::vector<OutputBlock> outputBlocks;  ///< outputs kept as templates (rerolled)
  std::shared_ptr<flat::ElementPatterns> patterns;

  bool templated() const { return !templateBlocks.empty(); }

  size_t dummyDerivativeCount() const {
    size_t n = 0;
    for (const auto& rows : differentiatedRows) n += rows.size() - 1;
    return n;
  }

  size_t stateCount() const {
    size_t n = 0;
    for (const auto& v : variables) n += v.kind == VarKind::State;
    return n;
  }
};

/// Assembles the DAE, classifies variables and checks that equations and unknowns balance
/// (naming the ones left over). Returns nullopt after reporting errors (E05xx).
std::optional<Dae> buildDae(const flat::FlatModel& model, const mech::EquationsOfMotion& eom, sym::Context& ctx,
                            DiagnosticEngine& diags);

/// `qdot equations`: the derived system in readable mathematical form.
void printEquations(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm);
/// The same content as JSON for tools.
void printEquationsJson(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm);

}  // namespace qdot::dae
