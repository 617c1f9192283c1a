// Flatten: expands a checked model into a FlatModel (see FlatModel.h).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "flatten/FlatModel.h"
#include "sema/Sema.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"

namespace qdot::flat {

/// Limits that keep hostile input from exhausting memory (a clear error instead).
struct FlattenLimits {
  size_t maxScalars = 20'000'000;  ///< total scalar elements across all arrays and loops
  /// Keep `sum(... for i in a:b)` in energies as IndexedSums (templates) where its body indexes
  /// arrays by the iterator plus constants (docs/loops.md); otherwise every sum is expanded.
  bool keepLoops = false;
  /// Keep top-level `for` equations each naming at most one derivative, of an element `der(x[i, …])`
  /// with the iterators in order (`der(x[i]) = rhs`, `m*der(v[i]) = f`, `f[i] = k*(x[i] - x[i-1])`),
  /// whose sides index arrays by the iterators plus constants, as EquationTemplates (docs/loops.md);
  /// any other equation is expanded.
  /// Only for a model the pipeline then checks with dae::isTemplatedOde (else it flattens again).
  bool keepForEquations = false;
};

/// Whether the syntax of a `for` equation allows keepForEquations to keep it (the flattener decides
/// with the names resolved): loops nested one in the next, around equations that each contain at
/// most one der() call, of an indexed name (an equation without one is an algebraic row).
bool mayKeepForEquation(const ast::Equation& loop);
/// Whether a `for` equation contains a der() call (a model without one has nothing to keep).
bool namesDerivatives(const ast::Equation& loop);

/// Values that replace the bindings of scalar Integer parameters (`qdot run -p n=3`): the model
/// is flattened as if they were written there, so the arrays they size take the new sizes. Every
/// name must be a scalar Integer parameter of the model (the driver checks it against sema).
using StructuralValues = std::map<std::string, long, std::less<>>;

/// Expands arrays, loops, reductions and comprehensions; substitutes definitions and constants;
/// builds T, V, D, forces and equations. Returns nullopt if errors were reported.
std::optional<FlatModel> flatten(const sema::CheckedModel& model, sym::Context& ctx, DiagnosticEngine& diags,
                                 FlattenLimits limits = {}, const StructuralValues& structural = {});

/// The body of a template at one point of its iterators' box: iterator symbols become the point's
/// values, relative symbols the elements they stand for. `point` has one value per iterator.
sym::Expr instantiate(const FlatModel& model, sym::Context& ctx, sym::Expr body, std::span<const long> point);

/// value + Σ over each sum's box of its body at that point (the sums in order, each one Add of its
/// points): what the scalar lowering gives for a binding `value + sum(…) + …`.
sym::Expr withSumsExpanded(const FlatModel& model, sym::Context& ctx, sym::Expr value, const std::vector<IndexedTerm>& sums);

/// Adds the kept sums of equations (FlatModel::equationSums) to their right sides and residuals.
void expandEquationSums(FlatModel& model, sym::Context& ctx);

/// Expands every IndexedSum into its energy term, every IndexedForce into its forces, every
/// equation's and output's sums into its sides and value (the model then is what flattening without keepLoops gives) and
/// clears the templates.
void expandIndexedSums(FlatModel& model, sym::Context& ctx);

/// Renumbers the model's variables: variable v becomes newIndex[v], or leaves the model where it is -1
/// (the new indices are 0..k-1, each used once). Every index of a variable follows: derivatives, the
/// symbol table, forces' targets, equations' origins; nothing else may name a dropped variable.
void renumberVariables(FlatModel& model, const std::vector<int>& newIndex);

/// `s` or `-s` for a symbol s: (s, ±1); nullopt for anything else (an alias's value).
std::optional<std::pair<sym::Expr, int>> signedSymbol(sym::Expr e);

/// Components' energies summed over their connections (SummedEnergies.cpp): where every
/// connector's flow is read only by the force its connection made on a coordinate, the aliases are
/// substituted into the energies and forces, and the flows, the aliased variables and the
/// connections' forces leave the model, which then is one Lagrangian over the coordinates (the
/// rows of each connection node summed; its flows cancel in the sum). `results`: the results asked
/// for (a flow among them keeps the model as it is; an aliased variable becomes an output). Returns
/// "" if the model was rewritten, else why not (and leaves it untouched).
std::string sumConnectedEnergies(FlatModel& model, sym::Context& ctx, std::span<const std::string> results);

/// Energy terms that repeat along arrays of components as IndexedSums (RerollTerms.cpp): variables
/// named alike but for one subscript numbered 1..N (`ms[i].s`) become an array (`ms.s`), and a run
/// of at least `minimumRun` consecutive terms of one statement, each the one before with every
/// such subscript one higher, one sum over its box. Parameters the sums read are renumbered to
/// consecutive variables per array. Returns the number of sums made.
size_t rerollTerms(FlatModel& model, sym::Context& ctx, size_t minimumRun);

/// Whether a loop can read relative symbol `rel` of a template over `rank` iterators, whose rows are
/// laid out in an array of `shape`, as the parameter p[first + the row's linear index + offset]:
/// every element of its array a parameter, the elements consecutive variables (the DAE numbers
/// parameters in variable order), subscript d the template's iterator d plus a constant, and in
/// more than one dimension the array of that shape. Otherwise the template stays scalar.
bool loopableParameters(const FlatModel& m, const RelativeElement& rel, size_t rank, std::span<const int> shape);

}  // namespace qdot::flat
