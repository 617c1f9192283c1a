// Turns a SUNDIALS IDA return code into one readable sentence: the flag's name, the simulation
// time and step size, the likely reason, and the model's own lastError text when the model failed.
// Used only by IdaSession's checking helper.
#pragma once

#include <string>
#include <string_view>

namespace qdot::rt {

/// Which set of return codes a flag belongs to (the IDA and IDALS codes overlap numerically).
enum class FlagFamily { Ida, LinearSolverInterface, Allocation };

/// What was known when a call failed.
struct FailureContext {
  std::string_view call;         ///< e.g. "IDASolve"
  double time = 0;               ///< simulation time of the failure
  double step = 0;               ///< step size being attempted (0 if none)
  double tout = 0;               ///< requested output time (IDASolve)
  long maxSteps = 0;             ///< IDASetMaxNumSteps value
  bool modelFailed = false;      ///< the model's residual or Jacobian failed during the call
  std::string modelError;        ///< its lastError text (or the runtime's NaN message)
  std::string solverMessage;     ///< IDA's own error text, if it printed one
  std::string linearSolverNote;  ///< e.g. which column of the Newton matrix was singular
};

/// "IDASolve failed (IDA_ERR_FAIL): the error test failed repeatedly at t = 0.5123 (step size
/// 1e-14): the model may be singular or the tolerance too tight".
std::string describeFailure(int flag, FlagFamily family, const FailureContext& context);

}  // namespace qdot::rt
