// One SUNDIALS IDA integration of a compiled model (model_abi.h): vectors, tolerances, the
// analytic Jacobian through a dense or KLU linear solver, consistent initial values, and one
// checking helper that turns every SUNDIALS return code into a sentence with the time (IdaError).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "ida/Tolerances.h"
#include "qdot/model_abi.h"

namespace qdot::rt {

/// Which direct linear solver factors the Newton matrix.
enum class LinearSolverKind { Auto, Dense, Klu };

/// How the session made y'(t0) (and algebraic y(t0)) consistent with F = 0.
enum class InitialValueMethod {
  AsGiven,       ///< F(t0, y0, y'0) = 0 already
  DiagonalRates, ///< every unknown differential and dF/dy' diagonal: y' from one exact division, verified
  CalcIC,        ///< IDACalcIC (IDA_YA_YDP_INIT)
};

/// "auto", "dense" or "klu".
std::string_view linearSolverName(LinearSolverKind kind);
/// Inverse of linearSolverName; nullopt for anything else.
std::optional<LinearSolverKind> parseLinearSolver(std::string_view text);
/// What Auto becomes: dense for n <= kDenseMaxAuto or a pattern at least 30 % full (up to
/// n = 2000), KLU otherwise.
LinearSolverKind chooseLinearSolver(uint32_t n, uint32_t nonzeros);
inline constexpr uint32_t kDenseMaxAuto = 50;
/// Largest n for which a dense matrix is allowed at all (n*n doubles = 2 GiB).
inline constexpr uint32_t kDenseMaxForced = 16384;

/// Settings of one session.
struct SessionOptions {
  double t0 = 0;               ///< start time
  double rtol = 1e-6;          ///< relative tolerance
  std::optional<double> atol;  ///< user's absolute tolerance (before scaling); default rtol
  LinearSolverKind linearSolver = LinearSolverKind::Auto;
  long maxStepsPerOutput = 100000;  ///< IDASetMaxNumSteps: steps allowed per advanceTo call
  /// Integrate step by step (IDA_ONE_STEP, interpolating to each output time) so that a step
  /// observer sees every internal step: angle outputs are unwrapped along the whole trajectory,
  /// not only at output times that may not resolve a fast rotation.
  bool observeSteps = false;
  bool preserveInvariants = false;  ///< --preserve invariants (ArkodeSession only): project after each step
  /// KLU: eliminate the Newton matrix's two-entry rows (kinematic rows der(q) = v) before the LU
  /// (ida/ReducedKlu.h); false with --no-row-elimination.
  bool eliminateTwoEntryRows = true;
};

/// Counters read from IDA after (or during) a run.
struct SolverStats {
  long steps = 0;
  long residualEvaluations = 0;  ///< residual calls counted by IDA (IDAGetNumResEvals)
  long jacobianEvaluations = 0;
  long nonlinearIterations = 0;
  long errorTestFailures = 0;
  long convergenceFailures = 0;  ///< nonlinear solver convergence failures
  double lastStep = 0;           ///< last step size taken
  int lastOrder = 0;             ///< BDF order of the last step
  std::string dummyDerivatives;  ///< after index reduction: the dummy derivatives at the end ("" if none)
  int dummyChanges = 0;          ///< how often the run chose other dummy derivatives (IDA restarted)
  int initialNewtonIterations = -1;  ///< Newton iterations of the initialization system (-1: none solved)
};

/// A failed SUNDIALS call or model evaluation: message with the reason, and the simulation time.
class IdaError : public std::runtime_error {
 public:
  /// message: the full sentence; time: simulation time of the failure.
  IdaError(const std::string& message, double time) : std::runtime_error(message), time_(time) {}
  /// Simulation time at which the failure happened.
  double time() const { return time_; }

 private:
  double time_;
};

/// An IDA integrator over one model. Construction sets everything up (and throws IdaError when a
/// SUNDIALS call fails or the model table is invalid); initialize() then advanceTo() repeatedly.
class IdaSession {
 public:
  /// p: the parameter values (from QdotModel::parameters). The model must outlive the session.
  IdaSession(const QdotModel& model, std::vector<double> p, const SessionOptions& options);
  ~IdaSession();
  IdaSession(const IdaSession&) = delete;
  IdaSession& operator=(const IdaSession&) = delete;

  /// Makes (y, y') consistent at t0: IDACalcIC(IDA_YA_YDP_INIT) when there are algebraic
  /// unknowns or F(t0, y0, y'0) != 0 (differential y kept, algebraic y and all y' computed).
  /// tout1 is the first output time (IDA takes direction and scale from it). Rebuilds the
  /// tolerance vector from the consistent values.
  void initialize(double tout1);
  /// Integration will not step past tstop (IDASetStopTime).
  void setStopTime(double tstop);
  /// Integrates to tout (IDA_NORMAL, interpolated); returns the time reached.
  double advanceTo(double tout);
  /// Called after every internal step when SessionOptions::observeSteps is set, with the step's
  /// time, y and y' (the output rows are interpolated afterwards).
  using StepObserver = std::function<void(double t, std::span<const double> y, std::span<const double> yp)>;
  void setStepObserver(StepObserver observer);

  double time() const;                 ///< current time of y(), yp()
  std::span<const double> y() const;   ///< unknowns at time()
  std::span<const double> yp() const;  ///< their derivatives at time()
  std::span<const double> parameters() const;
  const QdotModel& model() const;

  SolverStats stats() const;                   ///< counters so far
  const ToleranceSummary& tolerances() const;  ///< the atol vector in use
  std::span<const double> absoluteTolerances() const;
  LinearSolverKind linearSolver() const;             ///< Dense or Klu (never Auto)
  /// KLU: whether it permutes the matrix to block triangular form first (not when the Jacobian's
  /// diagonal has structural zeros: finding the permutation could then cost O(n · nnz)).
  bool blockTriangular() const;
  /// KLU: the half bandwidth when it factors the matrix in reverse Cuthill–McKee order (a narrow
  /// band: ida/KluOrdering.h, without BTF); nullopt when it orders by COLAMD.
  std::optional<int64_t> bandwidth() const;
  /// KLU: how many two-entry rows (and as many unknowns) were eliminated before the LU (0: none).
  int64_t eliminatedRows() const;
  /// KLU with rows eliminated: whether the rest is factored as a band (ida/BandLu.h) instead of by KLU.
  bool reducedAsBand() const;
  bool computedInitialValues() const;                ///< whether the start values were changed
  InitialValueMethod initialValueMethod() const;
  /// When IDA had completed its first step (seen at the next residual evaluation), if it has: the
  /// time to the first step, which the setup alone does not show (IDA factors its first matrix there).
  std::optional<std::chrono::steady_clock::time_point> firstStepDone() const;
  const std::vector<std::string>& warnings() const;  ///< IDA warnings and initialisation notes

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace qdot::rt
