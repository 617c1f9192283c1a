// Simplification beyond the canonical form the builders keep: expand-and-collect to a sum of
// products with numeric coefficients, sin² + cos² = 1 and cosh² − sinh² = 1, angle-sum
// contraction (sin a cos b − cos a sin b = sin(a − b), cos a cos b + sin a sin b = cos(a − b)),
// and factoring of a factor common to every term. The result is never longer than the input
// (expressionCost), evaluates to the same value up to rounding wherever the input is defined, and
// is a function of the expression alone (deterministic, independent of memory addresses).
//
// Cost is bounded: each call may create at most a budget of monomials, proportional to the size
// of its input; past it the call gives up and returns its input, so the pass is never exponential.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "symbolic/Expr.h"

namespace qdot::sym {

/// `--simplify=none|fast|full`: none keeps the builders' canonical form; fast expands within a
/// budget of a few monomials per input node; full allows far more and also simplifies expressions
/// without trigonometric or hyperbolic functions (pure polynomials).
enum class SimplifyLevel { None, Fast, Full };

/// Parses "none", "fast", "full"; false for anything else.
bool parseSimplifyLevel(std::string_view text, SimplifyLevel& level);

/// A simplification pass over many expressions of one Context, sharing its memo of simplified
/// function arguments (sin(θ₁ − θ₂) appears in many rows).
class Simplifier {
 public:
  Simplifier(Context& ctx, SimplifyLevel level);
  ~Simplifier();
  Simplifier(const Simplifier&) = delete;
  Simplifier& operator=(const Simplifier&) = delete;

  /// The simplified e (e itself at level None, past the budget, or when nothing is shorter).
  Expr operator()(Expr e);
  /// Whether the last call ran out of budget (and so returned its input).
  bool gaveUp() const;
  /// Monomials created so far (the budgeted work), for benchmarks and tests.
  size_t work() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// One expression at one level.
Expr simplify(Context& ctx, Expr e, SimplifyLevel level = SimplifyLevel::Fast);

/// For evaluation: sin(a ± b) and cos(a ± b) of two symbols written as products of sin and cos of
/// each (sin a cos b ± cos a sin b, cos a cos b ∓ sin a sin b), so that a kernel computes sin and cos
/// of every angle once and shares them, as a hand-written N-link residual does, instead of calling
/// sin and cos once per difference (n² calls for an n-link pendulum). Returns the rewritten roots.
std::vector<Expr> expandAngleDifferences(Context& ctx, std::span<const Expr> roots);

/// Whether the level simplifies e at all: None never, Full always, Fast when e contains a
/// trigonometric, hyperbolic, exp or log function or a non-integer power (where the identities
/// apply; a pure polynomial such as a spring energy only gets longer when expanded). O(DAG size).
bool worthSimplifying(Expr e, SimplifyLevel level);

/// The length measure the simplifier minimises: the number of operations, leaves and non-unit
/// coefficients of e written out as a tree (shared subexpressions counted at each use).
size_t expressionCost(Expr e);

}  // namespace qdot::sym
