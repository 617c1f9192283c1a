// The initialization system at t0 (issue 10 §2): the DAE's rows, the initial equations compiled as
// extra rows of F (model_abi.h: nInitialRows) and the fixed start values, solved together for y and
// the derivatives of the differential unknowns by Newton's method with the analytic Jacobian
// (dF/dy is J at cj = 0, dF/dy' is J(1) - J(0)), least squares by dense QR so that consistent
// redundant conditions are accepted. Runs before IDACalcIC, which then finds nothing to change.
#pragma once

#include <string>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot::rt {

struct InitialSystemResult {
  int iterations = 0;
  double residual = 0;  ///< largest |condition| at the solution
};

/// `full`: the compiled model (all rows). `keptRow[r]`: whether DAE row r is integrated (the
/// initial rows, the last full.nInitialRows, are always used here). `isDifferential`, `fixed`: per
/// variable. y, yp: start values in, the solution out. Throws std::runtime_error naming the
/// condition that cannot hold (inconsistent conditions, or no convergence from the start values).
InitialSystemResult solveInitialSystem(const QdotModel& full, const std::vector<char>& keptRow,
                                       const int32_t* isDifferential, const int32_t* fixed, const double* p,
                                       double t0, double* y, double* yp);

}  // namespace qdot::rt
