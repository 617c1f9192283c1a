// A SUNDIALS linear solver for IDA's Newton matrix that eliminates its two-entry rows (the
// kinematic rows der(q) = v of a mechanics model; ida/TwoEntryRows.h) and hands the rest to KLU:
// for a chain of masses KLU then factors an n × n tridiagonal matrix instead of a 2n × 2n one with
// eight entries per mass. It takes the SUNSparseMatrix (CSC) that IDA's Jacobian callback fills.
// S in a narrow band that its entries mostly fill (the chain's tridiagonal S) is factored by a band
// LU with partial pivoting at every setup (ida/BandLu.h: a pass over the band; KLU took 0.15 s of
// the first step at 10⁶ masses and 20 ms per refactorization). Otherwise it follows SUNDIALS' own
// KLU solver: analysis and a factorization with pivoting at the first setup, refactorization
// after, factored anew when KLU's condition estimate says the pivots went bad.
#pragma once

#include <sundials/sundials_linearsolver.h>

#include <cstdint>
#include <optional>

#include "ida/KluOrdering.h"
#include "ida/TwoEntryRows.h"

namespace qdot::rt {

/// What the reduced system is factored with: S's band ordering when RCM finds a narrow band (a band
/// LU, or KLU in that ordering when the band is mostly zeros), else KLU's default (COLAMD, with
/// block triangular form when S's diagonal is zero-free).
struct ReducedKluPlan {
  TwoEntryRows rows;
  std::optional<BandOrdering> band;
  bool blockTriangular = true;
};

/// The plan for a pattern: nullopt when it has no two-entry row to eliminate.
std::optional<ReducedKluPlan> planReducedKlu(CscPattern pattern);

/// The solver (SUNLINEARSOLVER_DIRECT: matrix-based); it owns the plan. nullptr when out of memory.
SUNLinearSolver reducedKluSolver(ReducedKluPlan plan, SUNContext context);

/// The plan a solver made by reducedKluSolver works with.
const ReducedKluPlan& reducedKluPlan(SUNLinearSolver solver);

/// After a failed setup: the column of J (an unknown) where the factorization met a zero pivot, or
/// −1 (it did not fail, or not for that reason).
int64_t reducedKluSingularColumn(SUNLinearSolver solver);

/// Whether the solver factors S as a band (ida/BandLu.h) rather than by KLU.
bool reducedKluBanded(SUNLinearSolver solver);

}  // namespace qdot::rt
