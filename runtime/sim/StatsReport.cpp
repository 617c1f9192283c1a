// formatStats: one line per quantity, labels padded to one column.
#include "sim/StatsReport.h"

#include <fmt/format.h>

#include "arkode/ArkodeSession.h"
#include "sim/ProcessClock.h"

namespace qdot::rt {
namespace {

void line(std::string& out, std::string_view label, const std::string& value) {
  out += fmt::format("  {:<22} {}\n", label, value);
}

std::string toleranceText(const ToleranceSummary& t) {
  std::string range = fmt::format("atol min {:.3g}, median {:.3g}, max {:.3g}", t.atolMin, t.atolMedian, t.atolMax);
  std::size_t nominal = t.count - t.automatic;
  if (t.atolGiven)
    return fmt::format("rtol {:g}, atol {:g} absolute ({} of {} unknowns with a nominal: atol x nominal): {}", t.rtol,
                       t.atolUser, nominal, t.count, range);
  std::string velocities =
      t.velocities == 0 ? ""
                        : fmt::format("; {} velocit{} at least position scale x {:.3g} 1/s, the lowest linearized "
                                      "frequency at the start",
                                      t.velocities, t.velocities == 1 ? "y" : "ies", t.frequency);
  return fmt::format("rtol {:g} (to the solver as {:.3g}, calibrated for the global error), atol = that x scale, {} of {} "
                     "scales automatic (max(|value|, 1e-3 x largest start value of its kind){}; docs/accuracy.md): {}",
                     t.rtol, t.solverRtol, t.automatic, t.count, velocities, range);
}

}  // namespace

std::string formatStats(const SimulationResult& r) {
  const SolverStats& s = r.stats;
  std::string out = "statistics:\n";
  bool arkode = r.solver == SolverKind::Arkode;  // --solver arkode: y' = g(t, y), one residual and two Jacobian calls each
  if (arkode) line(out, "integrator", fmt::format("arkode, {}", kArkodeMethodName));
  line(out, "steps", fmt::format("{} (last step {:.3g}, order {})", s.steps, s.lastStep, s.lastOrder));
  line(out, arkode ? "right-hand side evals" : "residual evaluations", fmt::format("{}", s.residualEvaluations));
  line(out, "Jacobian evaluations", fmt::format("{}", s.jacobianEvaluations));
  line(out, arkode ? "linear solves" : "nonlinear iterations", fmt::format("{}", s.nonlinearIterations));
  line(out, "error-test failures", fmt::format("{}", s.errorTestFailures));
  line(out, "convergence failures", fmt::format("{}", s.convergenceFailures));
  line(out, "linear solver",
       fmt::format("{} ({}{}{})", linearSolverName(r.linearSolver),
                   r.linearSolverChosenAutomatically ? "chosen automatically" : "as requested",
                   r.linearSolver != LinearSolverKind::Klu ? ""
                   : r.bandwidth ? fmt::format("; band ordering, bandwidth {}", *r.bandwidth)
                   : !r.blockTriangular ? "; without block triangular form: the Jacobian's diagonal has structural zeros"
                                        : "",
                   r.eliminatedRows > 0 ? fmt::format("; {} two-entry rows eliminated first{}", r.eliminatedRows,
                                                       r.reducedAsBand ? ", the rest by a band LU with partial pivoting" : "")
                                       : ""));
  if (!s.dummyDerivatives.empty())
    line(out, "dummy derivatives",
         fmt::format("{} (index reduction; chosen again {} time{} during the run)", s.dummyDerivatives, s.dummyChanges,
                     s.dummyChanges == 1 ? "" : "s"));
  if (s.initialNewtonIterations >= 0)
    line(out, "initial values", fmt::format("initialization system solved ({} Newton iterations)", s.initialNewtonIterations));
  else
    line(out, "initial values", r.initialValues == InitialValueMethod::CalcIC ? "made consistent by IDACalcIC"
                                : r.initialValues == InitialValueMethod::DiagonalRates
                                    ? "made consistent directly (dF/dy' diagonal: y' -= F/diag, checked)"
                                : arkode ? "consistent as given (y' = g(t0, y0))"
                                         : "consistent as given");
  line(out, "tolerances", toleranceText(r.tolerances));
  line(out, "rows written", fmt::format("{}", r.rows));
  std::optional<double> sinceStart = r.firstStepDone ? secondsSinceProcessStart(*r.firstStepDone) : std::nullopt;
  line(out, "wall time",
       fmt::format("setup {:.3f} s, solve {:.3f} s (first step {:.3f} s{})", r.setupSeconds, r.solveSeconds,
                   r.firstStepSeconds,
                   sinceStart ? fmt::format(", done {:.3f} s after the process started", *sinceStart) : ""));
  if (r.peakMemoryBytes)  // a large model's memory is a figure users compare, as its time
    line(out, "peak memory",
         fmt::format("{:.1f} MiB resident (the whole process so far){}", r.peakMemoryBytes / 1048576.0,
                     r.prefaultedBytes ? fmt::format("; {:.0f} MiB of heap populated ahead of use by another thread",
                                                     r.prefaultedBytes / 1048576.0)
                                       : ""));
  return out;
}

}  // namespace qdot::rt
