// Sentences for IDA and IDALS return codes. Each names what went wrong, where (t and step size)
// and what usually causes it; model failures add the model's lastError text.
#include "ida/IdaFlags.h"

#include <fmt/format.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>

#include <cstdlib>
#include <memory>

namespace qdot::rt {
namespace {

std::string flagName(int flag, FlagFamily family) {
  if (family == FlagFamily::Allocation) return "allocation failed";
  char* raw = family == FlagFamily::Ida ? IDAGetReturnFlagName(flag) : IDAGetLinReturnFlagName(flag);
  if (!raw) return fmt::format("flag {}", flag);
  std::string name(raw);
  std::free(raw);  // SUNDIALS allocates the name with malloc
  return name;
}

std::string where(const FailureContext& c) {
  if (c.step != 0) return fmt::format("at t = {:.10g} (step size {:.3g})", c.time, c.step);
  return fmt::format("at t = {:.10g}", c.time);
}

std::string idaReason(int flag, const FailureContext& c) {
  switch (flag) {
    case IDA_TOO_MUCH_WORK:
      return fmt::format(
          "the solver took {} steps {} without reaching t = {:.10g}: the model may be very stiff or "
          "oscillate fast (a lightly damped fast mode: try --solver arkode), a variable may grow without bound, or "
          "its stiffnesses may lie more than about 1e15 apart, beyond double precision (model the stiff part as rigid)",
          c.maxSteps, where(c), c.tout);
    case IDA_TOO_MUCH_ACC:
      return fmt::format("the requested accuracy cannot be reached in double precision {}: increase --rtol/--atol",
                         where(c));
    case IDA_ERR_FAIL:
      return fmt::format("the error test failed repeatedly {}: the model may be singular or the tolerance too tight",
                         where(c));
    case IDA_CONV_FAIL:
      return fmt::format(
          "the Newton iteration failed to converge repeatedly {}: the model may be singular, "
          "discontinuous or its Jacobian wrong",
          where(c));
    case IDA_LINIT_FAIL:
      return fmt::format("the linear solver could not be initialised {}", where(c));
    case IDA_LSETUP_FAIL:
      if (!c.linearSolverNote.empty()) return fmt::format("the Newton matrix could not be factored {}", where(c));
      return fmt::format(
          "the Newton matrix could not be factored {}: it is singular (an unknown that no equation "
          "determines, or a higher-index system)",
          where(c));
    case IDA_LSOLVE_FAIL:
      return fmt::format("the linear solve failed {}", where(c));
    case IDA_RES_FAIL:
      return fmt::format("the model's residual failed unrecoverably {}", where(c));
    case IDA_REP_RES_ERR:
      return fmt::format("the model's residual failed repeatedly {}", where(c));
    case IDA_FIRST_RES_FAIL:
      return fmt::format("the model's residual failed at the first evaluation {}", where(c));
    case IDA_CONSTR_FAIL:
      return fmt::format("the inequality constraints could not be met {}", where(c));
    case IDA_LINESEARCH_FAIL:
      return fmt::format(
          "consistent initial values could not be found {} (the line search failed): the start "
          "values may be too far from a consistent point",
          where(c));
    case IDA_NO_RECOVERY:
      return fmt::format(
          "consistent initial values could not be found {}: the residual or the linear solver "
          "failed and did not recover",
          where(c));
    case IDA_BAD_EWT:
      return fmt::format("an error weight became zero or negative {} (an absolute tolerance of 0?)", where(c));
    case IDA_MEM_FAIL:
      return "out of memory";
    case IDA_ILL_INPUT:
      return fmt::format("invalid input {}", where(c));
    case IDA_NLS_INIT_FAIL:
    case IDA_NLS_SETUP_FAIL:
    case IDA_NLS_FAIL:
      return fmt::format("the nonlinear solver failed {}", where(c));
    default:
      return fmt::format("IDA failed {}", where(c));
  }
}

std::string lsReason(int flag, const FailureContext& c) {
  switch (flag) {
    case IDALS_MEM_FAIL:
      return "out of memory";
    case IDALS_ILL_INPUT:
      return "the linear solver and matrix do not fit the problem";
    case IDALS_JACFUNC_UNRECVR:
      return fmt::format("the Jacobian could not be evaluated {}", where(c));
    case IDALS_SUNMAT_FAIL:
      return fmt::format("a matrix operation failed {}", where(c));
    case IDALS_SUNLS_FAIL:
      return fmt::format("the linear solver failed {}", where(c));
    default:
      return fmt::format("the linear solver interface failed {}", where(c));
  }
}

std::string reason(int flag, FlagFamily family, const FailureContext& c) {
  switch (family) {
    case FlagFamily::Ida:
      return idaReason(flag, c);
    case FlagFamily::LinearSolverInterface:
      return lsReason(flag, c);
    case FlagFamily::Allocation:
      return "SUNDIALS could not allocate it (out of memory?)";
  }
  return "";
}

}  // namespace

std::string describeFailure(int flag, FlagFamily family, const FailureContext& context) {
  std::string text =
      fmt::format("{} failed ({}): {}", context.call, flagName(flag, family), reason(flag, family, context));
  if (!context.linearSolverNote.empty()) text += "; " + context.linearSolverNote;
  if (context.modelFailed) {
    text += fmt::format("; the model reported: {}", context.modelError.empty() ? "(no message)" : context.modelError);
  } else if (!context.solverMessage.empty() && (flag == IDA_ILL_INPUT || family != FlagFamily::Ida)) {
    text += fmt::format(" (IDA: {})", context.solverMessage);
  }
  return text;
}

}  // namespace qdot::rt
