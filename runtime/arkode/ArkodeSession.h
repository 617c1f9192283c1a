// One SUNDIALS ARKODE integration (ARKStep, an L-stable ESDIRK method) of a model that is an ODE in
// its derivatives (ExplicitForm: y' = g(t, y)), with the same face as IdaSession so that simulate()
// runs either: vectors, tolerances (the same rule as IDA's), the exact Jacobian of g through a
// dense or KLU linear solver, and failures as IdaError sentences with the simulation time.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "ida/IdaSession.h"
#include "qdot/model_abi.h"

namespace qdot::rt {

/// The implicit method: Kennedy and Carpenter's ESDIRK4(3)7L[2]SA (2016), 7 stages, order 4 with
/// an embedded order-3 error estimate. L-stable (the stability function vanishes at infinity, so a
/// stiff mode near the imaginary axis is damped, not kept — BDF of order > 2 is unstable there) and
/// stiffly accurate (the last stage is the solution, no error from the explicit update); its
/// explicit first stage and stage order 2 make it cheaper and more accurate on stiff problems than
/// ARKODE's default order-4 SDIRK (Hairer–Wanner SDIRK 5-3-4).
inline constexpr const char* kArkodeMethodName = "ESDIRK437L2SA (ARKODE_ESDIRK437L2SA_7_3_4, order 4, L-stable)";

class ArkodeSession {
 public:
  /// p: the parameter values. Throws IdaError when the model is not an ODE in its derivatives
  /// (explicitFormObstacle) or a SUNDIALS call fails. The model must outlive the session.
  ArkodeSession(const QdotModel& model, std::vector<double> p, const SessionOptions& options);
  ~ArkodeSession();
  ArkodeSession(const ArkodeSession&) = delete;
  ArkodeSession& operator=(const ArkodeSession&) = delete;

  /// y'(t0) = g(t0, y0); fails (IdaError) when dF/dy' is singular at the start. tout1 is unused
  /// (the start of an ODE is consistent as given).
  void initialize(double tout1);
  void setStopTime(double tstop);
  /// Integrates to tout (ARK_NORMAL, interpolated); y' there is g(t, y). Returns the time reached.
  double advanceTo(double tout);

  double time() const;
  std::span<const double> y() const;
  std::span<const double> yp() const;
  std::span<const double> parameters() const;
  const QdotModel& model() const;

  SolverStats stats() const;  ///< residualEvaluations counts right-hand side evaluations
  const ToleranceSummary& tolerances() const;
  std::span<const double> absoluteTolerances() const;
  LinearSolverKind linearSolver() const;  ///< Dense or Klu
  bool computedInitialValues() const { return false; }
  InitialValueMethod initialValueMethod() const { return InitialValueMethod::AsGiven; }
  const std::vector<std::string>& warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace qdot::rt
