// Consistent y'(t0) without IDACalcIC for the common large case: every unknown differential and
// ∂F/∂y' diagonal up to the order of its rows (a chain's masses, a rod's heat capacities, any
// explicit ODE). The Newton step on y' with y fixed is then one division per unknown, exact when F
// is linear in y'; IDACalcIC's own convergence test decides whether it is accepted.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace qdot::rt {

/// ∂F/∂y' with one non-zero entry per column and per row: column c's entry d[c], in row rowOf[c].
struct DiagonalRates {
  std::vector<uint32_t> rowOf;
  std::vector<double> d;
};

/// ∂F/∂y' = J(cj = 1) − J(cj = 0), both in one CSC pattern, if it has that form with finite
/// entries; nullopt otherwise, or where |∂F/∂y| is so large that adding 1 does not change it (the
/// difference cannot see ∂F/∂y' there).
template <class Index>
std::optional<DiagonalRates> diagonalRates(std::span<const Index> columnStarts, std::span<const Index> rowIndices,
                                           std::span<const double> at0, std::span<const double> at1);

/// The Newton step on y': yp[c] -= F[rowOf[c]] / d[c].
void stepRates(const DiagonalRates& rates, std::span<const double> F, std::span<double> yp);

/// IDACalcIC's convergence test (IDA_YA_YDP_INIT, an index-0 system) on the correction the residual
/// F at the new rates would still ask for: its WRMS norm in y's error weights 1/(rtol |y| + atol),
/// times the distance `span` to the first output, at most 0.0033 (IDA's default epsNewt).
bool ratesConverged(const DiagonalRates& rates, std::span<const double> F, std::span<const double> y, double rtol,
                    std::span<const double> atol, double span);

}  // namespace qdot::rt
