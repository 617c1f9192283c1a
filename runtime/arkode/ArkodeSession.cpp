// ArkodeSession: ARKStep (implicit only) over ExplicitForm. The right-hand side and its Jacobian
// come through static callbacks; every SUNDIALS call goes through Impl::check, which throws IdaError
// with a sentence naming the call, ARKODE's flag, the time, the step size and a likely cause.
#include "arkode/ArkodeSession.h"

#include <arkode/arkode_arkstep.h>
#include <fmt/format.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <Eigen/Dense>

#include "arkode/ExplicitForm.h"
#include "arkode/StartLinearization.h"
#include "ida/ModelCheck.h"
#include "ida/SerialVectorOps.h"

namespace qdot::rt {
namespace {

double* data(N_Vector v) { return N_VGetArrayPointer(v); }

constexpr std::size_t kMaxWarnings = 10;

/// What a failed ARKODE call most likely means, as the end of a sentence.
std::string_view likelyCause(int flag) {
  switch (flag) {
    case ARK_TOO_MUCH_WORK:
      return "the step limit per output interval was reached: the model oscillates faster than the tolerance allows "
             "to follow, a velocity's tolerance lies below its round-off, or the stiffnesses lie more than about "
             "1e15 apart, beyond double precision (model the stiff part as rigid)";
    case ARK_TOO_MUCH_ACC:
      return "the tolerances ask for more accuracy than double precision gives: raise --rtol or --atol";
    case ARK_ERR_FAILURE:
      return "the error test failed repeatedly: the solution may be discontinuous or singular here, or the tolerance "
             "too tight";
    case ARK_CONV_FAILURE:
      return "Newton's iteration failed repeatedly: the model may be singular here";
    case ARK_LSETUP_FAIL:
    case ARK_LSOLVE_FAIL:
      return "the linear solver failed: the Newton matrix is singular";
    case ARK_RHSFUNC_FAIL:
    case ARK_FIRST_RHSFUNC_ERR:
    case ARK_REPTD_RHSFUNC_ERR:
    case ARK_UNREC_RHSFUNC_ERR:
      return "the right-hand side y' = g(t, y) could not be evaluated";
    case ARK_TOO_CLOSE:
      return "the output time is too close to the start";
    default:
      return "";
  }
}

}  // namespace

struct ArkodeSession::Impl {
  const QdotModel& model;
  std::vector<double> p;
  SessionOptions options;
  uint32_t n;
  LinearSolverKind kind = LinearSolverKind::Dense;
  std::unique_ptr<ExplicitForm> form;

  SUNContext context = nullptr;
  void* arkode = nullptr;
  N_Vector y = nullptr, yp = nullptr, atol = nullptr;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;
  Eigen::MatrixXd denseJacobian;
  Eigen::SparseMatrix<double> sparseJacobian, sparsePattern;  // the pattern only grows (KLU's analysis is kept)
  ToleranceVector tolerances;
  std::vector<double> nominal;
  double t;
  double tout = 0;
  std::string modelError;  // the first failure of g since the last call
  std::string solverMessage;
  std::vector<std::string> warnings;

  Impl(const QdotModel& m, std::vector<double> values, const SessionOptions& o)
      : model(m), p(std::move(values)), options(o), n(m.nVariables), t(o.t0) {}
  ~Impl();

  void setup();
  void loadInitialValues();
  void createIntegrator();
  void attachLinearSolver();
  double advanceTo(double target);
  SolverStats stats();
  void check(int flag, std::string_view call);
  int onFailure();
  int fillJacobian(double time, N_Vector yv, N_Vector fy, SUNMatrix J);
  void copySparse(SUNMatrix J);

  // --preserve invariants
  std::vector<double> invariantsAtStart;
  long projections = 0;
  void startProjection();
  bool invariantValues(double time, const double* yv, Eigen::VectorXd& out);
  int project(double time, N_Vector yv);
  static int projectCallback(sunrealtype time, N_Vector yv, void* self);

  static int rhsCallback(sunrealtype time, N_Vector yv, N_Vector ypv, void* self);
  static int jacobianCallback(sunrealtype time, N_Vector yv, N_Vector fy, SUNMatrix J, void* self, N_Vector,
                              N_Vector, N_Vector);
  static void errorCallback(int code, const char* module, const char* function, char* message, void* self);
};

ArkodeSession::Impl::~Impl() {
  if (arkode) ARKStepFree(&arkode);
  if (solver) SUNLinSolFree(solver);
  if (matrix) SUNMatDestroy(matrix);
  for (N_Vector v : {y, yp, atol})
    if (v) N_VDestroy(v);
  if (context) SUNContext_Free(&context);
}

void ArkodeSession::Impl::check(int flag, std::string_view call) {
  if (flag >= 0) return;
  double time = t, step = 0;
  if (arkode) {
    ARKStepGetCurrentTime(arkode, &time);
    ARKStepGetLastStep(arkode, &step);
  }
  std::string text = fmt::format("{} failed ({}) at t = {:.10g} (step size {:.3g})", call,
                                 ARKStepGetReturnFlagName(flag), time, step);
  if (flag == ARK_TOO_MUCH_WORK) text += fmt::format(" after {} steps towards t = {:.10g}", options.maxStepsPerOutput, tout);
  if (!likelyCause(flag).empty()) text += fmt::format(": {}", likelyCause(flag));
  if (!modelError.empty()) text += fmt::format("; {}", modelError);
  else if (!solverMessage.empty()) text += fmt::format(" (ARKODE: {})", solverMessage);
  throw IdaError(text, time);
}

int ArkodeSession::Impl::onFailure() {
  if (modelError.empty()) modelError = form->error();
  return 1;  // recoverable: ARKODE retries with a smaller step
}

int ArkodeSession::Impl::rhsCallback(sunrealtype time, N_Vector yv, N_Vector ypv, void* self) {
  auto* impl = static_cast<Impl*>(self);
  return impl->form->rhs(time, data(yv), data(ypv)) ? impl->onFailure() : 0;
}

int ArkodeSession::Impl::jacobianCallback(sunrealtype time, N_Vector yv, N_Vector fy, SUNMatrix J, void* self,
                                          N_Vector, N_Vector, N_Vector) {
  return static_cast<Impl*>(self)->fillJacobian(time, yv, fy, J);
}

void ArkodeSession::Impl::errorCallback(int code, const char*, const char* function, char* message, void* self) {
  auto* impl = static_cast<Impl*>(self);
  if (code == ARK_WARNING) {
    if (impl->warnings.size() < kMaxWarnings) impl->warnings.push_back(fmt::format("ARKODE ({}): {}", function, message));
    return;
  }
  impl->solverMessage = message;
}

int ArkodeSession::Impl::fillJacobian(double time, N_Vector yv, N_Vector fy, SUNMatrix J) {
  if (kind == LinearSolverKind::Dense) {
    if (form->denseJacobian(time, data(yv), data(fy), denseJacobian)) return onFailure();
    for (uint32_t c = 0; c < n; ++c)
      std::copy(denseJacobian.col(c).data(), denseJacobian.col(c).data() + n, SUNDenseMatrix_Column(J, c));
    return 0;
  }
  if (form->sparseJacobian(time, data(yv), data(fy), sparseJacobian)) return onFailure();
  copySparse(J);
  return 0;
}

// The values into the union of all patterns seen (and the diagonal, which ARKODE adds for I − γJ):
// KLU refactors with the symbolic analysis of the first matrix, so the pattern must not flicker
// when an entry happens to be 0; when it grows, KLU analyses again.
void ArkodeSession::Impl::copySparse(SUNMatrix J) {
  Eigen::SparseMatrix<double> merged = sparsePattern + sparseJacobian;
  merged.makeCompressed();
  bool grew = merged.nonZeros() != sparsePattern.nonZeros();
  if (grew) sparsePattern = 0.0 * merged;
  auto nnz = static_cast<sunindextype>(merged.nonZeros());
  if (SUNSparseMatrix_NNZ(J) < nnz) SUNSparseMatrix_Reallocate(J, nnz);
  std::copy(merged.outerIndexPtr(), merged.outerIndexPtr() + n + 1, SUNSparseMatrix_IndexPointers(J));
  std::copy(merged.innerIndexPtr(), merged.innerIndexPtr() + nnz, SUNSparseMatrix_IndexValues(J));
  std::copy(merged.valuePtr(), merged.valuePtr() + nnz, SUNSparseMatrix_Data(J));
  if (grew && solver) SUNLinSol_KLUReInit(solver, J, nnz, SUNKLU_REINIT_PARTIAL);
}

void ArkodeSession::Impl::setup() {
  std::string obstacle = explicitFormObstacle(model);
  if (!obstacle.empty())
    throw IdaError(fmt::format("--solver arkode integrates models that are ODEs in their derivatives (F linear in y' "
                               "with a regular dF/dy'); {} has none of that form: {} (use --solver ida)",
                               model.name ? model.name : "the model", obstacle),
                   options.t0);
  kind = options.linearSolver == LinearSolverKind::Auto ? chooseLinearSolver(n, model.jacobianNonzeros)
                                                        : options.linearSolver;
  form = std::make_unique<ExplicitForm>(model, p, kind == LinearSolverKind::Klu);
  if (SUNContext_Create(nullptr, &context) != 0) throw IdaError("SUNContext_Create failed", options.t0);
  y = N_VNew_Serial(n, context);
  if (y) N_VEnableFusedOps_Serial(y, SUNTRUE);  // as in IdaSession::createVectors: one pass per combination
  yp = N_VNew_Serial(n, context);
  atol = N_VNew_Serial(n, context);
  if (!y || !yp || !atol) throw IdaError("N_VNew_Serial failed (out of memory)", options.t0);
  for (N_Vector v : {y, yp, atol}) useOptimizedSerialOps(v);  // ida/SerialVectorOps.h: Debian's are unoptimized
  loadInitialValues();
  createIntegrator();
  attachLinearSolver();
}

void ArkodeSession::Impl::loadInitialValues() {
  nominal.assign(n, 0.0);
  std::fill(data(y), data(y) + n, 0.0);
  std::fill(data(yp), data(yp) + n, 0.0);
  if (model.initialValues(&model, p.data(), options.t0, data(y), data(yp), nominal.data()) != 0)
    throw IdaError(fmt::format("the start values could not be computed at t = {:.10g}: {}", options.t0,
                               modelLastError(model)),
                   options.t0);
  for (uint32_t i = 0; i < n; ++i)
    if (!std::isfinite(data(y)[i]))
      throw IdaError(fmt::format("the start value of {} is {}", nameList(model.variableNames, n)[i], data(y)[i]),
                     options.t0);
}

void ArkodeSession::Impl::createIntegrator() {
  arkode = ARKStepCreate(nullptr, &Impl::rhsCallback, options.t0, y, context);
  if (!arkode) throw IdaError("ARKStepCreate failed", options.t0);
  check(ARKStepSetErrHandlerFn(arkode, &Impl::errorCallback, this), "ARKStepSetErrHandlerFn");
  check(ARKStepSetUserData(arkode, this), "ARKStepSetUserData");
  check(ARKStepSetTableNum(arkode, ARKODE_ESDIRK437L2SA_7_3_4, ARKODE_ERK_NONE), "ARKStepSetTableNum");
  tolerances = buildTolerances(options.rtol, options.atol, {data(y), n}, nominal, {model.isDifferential, n}, {},
                               options.atol ? TimeScale{} : modelTimeScale(model, p, options.t0));
  useCalibration(tolerances, kArkodeCalibration);  // measured for this method, as IDA's for BDF
  std::copy(tolerances.atol.begin(), tolerances.atol.end(), data(atol));
  check(ARKStepSVtolerances(arkode, tolerances.solverRtol, atol), "ARKStepSVtolerances");
  check(ARKStepSetMaxNumSteps(arkode, options.maxStepsPerOutput), "ARKStepSetMaxNumSteps");
  // The Newton matrix I − γ dg/dy is rebuilt at every step. With ARKODE's default (every 20 steps,
  // or when γ changed by 20 %) the damped oscillator at rtol 1e-9 accepted steps whose Newton
  // iterates had not converged: errors of 2.7e-5 m against 1.8e-8 m with a fresh matrix, for about
  // the same cost (the model's Jacobian is cheap next to the steps saved).
  check(ARKStepSetLSetupFrequency(arkode, 1), "ARKStepSetLSetupFrequency");
}

void ArkodeSession::Impl::attachLinearSolver() {
  if (kind == LinearSolverKind::Dense && n > kDenseMaxForced)
    throw IdaError(fmt::format("the dense linear solver would need a {} x {} matrix: use --linear-solver klu", n, n),
                   options.t0);
  if (kind == LinearSolverKind::Klu) {
    sparsePattern.resize(n, n);
    sparsePattern.setIdentity();
    sparsePattern *= 0.0;
    matrix = SUNSparseMatrix(n, n, std::max<sunindextype>(n, model.jacobianNonzeros), CSC_MAT, context);
    solver = matrix ? SUNLinSol_KLU(y, matrix, context) : nullptr;
  } else {
    matrix = SUNDenseMatrix(n, n, context);
    solver = matrix ? SUNLinSol_Dense(y, matrix, context) : nullptr;
  }
  if (!solver) throw IdaError("creating the linear solver failed (out of memory)", options.t0);
  check(ARKStepSetLinearSolver(arkode, solver, matrix), "ARKStepSetLinearSolver");
  check(ARKStepSetJacFn(arkode, &Impl::jacobianCallback), "ARKStepSetJacFn");
}

double ArkodeSession::Impl::advanceTo(double target) {
  tout = target;
  if (n == 0) return t = target;
  modelError.clear();
  solverMessage.clear();
  sunrealtype reached = t;
  check(ARKStepEvolve(arkode, target, y, &reached, ARK_NORMAL), "ARKStepEvolve");
  t = reached;
  // the row is interpolated between steps: it is projected like the steps (else the interpolation
  // error, 1e-4 of the amplitude at rtol 1e-6 with steps of 0.3 rad, would show in the rows)
  if (!invariantsAtStart.empty() && project(t, y)) check(ARK_POSTPROCESS_STEP_FAIL, "the projection at the output time");
  if (form->rhs(t, data(y), data(yp))) {
    modelError = form->error();
    check(ARK_RHSFUNC_FAIL, "the right-hand side at the output time");
  }
  return t;
}

SolverStats ArkodeSession::Impl::stats() {
  SolverStats s;
  if (!arkode) return s;
  long explicitEvaluations = 0;
  ARKStepGetNumSteps(arkode, &s.steps);
  ARKStepGetNumRhsEvals(arkode, &explicitEvaluations, &s.residualEvaluations);
  ARKStepGetNumJacEvals(arkode, &s.jacobianEvaluations);
  ARKStepGetNumNonlinSolvIters(arkode, &s.nonlinearIterations);
  ARKStepGetNumErrTestFails(arkode, &s.errorTestFailures);
  ARKStepGetNumNonlinSolvConvFails(arkode, &s.convergenceFailures);
  ARKStepGetLastStep(arkode, &s.lastStep);
  s.lastOrder = 4;
  return s;
}

// --- --preserve invariants -------------------------------------------------------------------

bool ArkodeSession::Impl::invariantValues(double time, const double* yv, Eigen::VectorXd& out) {
  std::vector<double> rates(n);
  out.resize(model.nInvariants);
  return form->rhs(time, yv, rates.data()) == 0 &&
         model.invariants(&model, time, yv, rates.data(), p.data(), out.data()) == 0 && out.allFinite();
}

void ArkodeSession::Impl::startProjection() {
  Eigen::VectorXd values;
  if (!invariantValues(options.t0, data(y), values))
    throw IdaError(fmt::format("--preserve invariants: the invariants cannot be evaluated at the start: {}",
                               form->error().empty() ? modelLastError(model) : form->error()),
                   options.t0);
  invariantsAtStart.assign(values.data(), values.data() + values.size());
  check(ARKStepSetPostprocessStepFn(arkode, &Impl::projectCallback), "ARKStepSetPostprocessStepFn");
}

// The nearest point, in the error test's weighted norm, on the level set of the invariants: with
// G = dI/dy (forward differences) and D = diag((rtol·|y_i| + atol_i)²), Δy = −D Gᵀ (G D Gᵀ)⁻¹ (I − I0),
// by Newton's method until I is back at its start value to round-off. Each step's change is of the
// size of its local error, so the accuracy order is kept while the drift of the invariants is not.
int ArkodeSession::Impl::project(double time, N_Vector yv) {
  const auto m = static_cast<Eigen::Index>(invariantsAtStart.size());
  Eigen::Map<Eigen::VectorXd> state(data(yv), n);
  Eigen::Map<const Eigen::VectorXd> target(invariantsAtStart.data(), m);
  Eigen::VectorXd values, shifted, weight(n);
  for (uint32_t i = 0; i < n; ++i)
    weight[i] = std::pow(tolerances.solverRtol * std::abs(state[i]) + tolerances.atol[i], 2);
  for (int iteration = 0; iteration < 3; ++iteration) {
    if (!invariantValues(time, state.data(), values)) return onFailure();
    Eigen::VectorXd defect = values - target;
    if (defect.cwiseAbs().maxCoeff() <= 4 * DBL_EPSILON * target.cwiseAbs().maxCoeff()) break;
    Eigen::MatrixXd gradient(m, n);
    for (uint32_t j = 0; j < n; ++j) {
      double saved = state[j], h = std::sqrt(DBL_EPSILON) * std::max(std::abs(saved), std::sqrt(weight[j]) / tolerances.solverRtol);
      state[j] = saved + h;
      bool ok = invariantValues(time, state.data(), shifted);
      state[j] = saved;
      if (!ok) return onFailure();
      gradient.col(j) = (shifted - values) / h;
    }
    Eigen::MatrixXd scaled = gradient * weight.asDiagonal();
    Eigen::VectorXd multipliers = (scaled * gradient.transpose()).ldlt().solve(defect);
    if (!multipliers.allFinite()) return 0;  // a stationary invariant (all its derivatives 0): nothing to do
    state -= scaled.transpose() * multipliers;
  }
  ++projections;
  return 0;
}

int ArkodeSession::Impl::projectCallback(sunrealtype time, N_Vector yv, void* self) {
  return static_cast<Impl*>(self)->project(time, yv);
}

// --- the public face ------------------------------------------------------------------------

ArkodeSession::ArkodeSession(const QdotModel& model, std::vector<double> p, const SessionOptions& options)
    : impl_(std::make_unique<Impl>(model, std::move(p), options)) {
  impl_->setup();
}

ArkodeSession::~ArkodeSession() = default;

void ArkodeSession::initialize(double) {
  Impl& s = *impl_;
  if (s.n == 0) return;
  if (s.form->rhs(s.options.t0, data(s.y), data(s.yp)))
    throw IdaError(fmt::format("the derivatives cannot be computed at the start t = {:.10g}: {}", s.options.t0,
                               s.form->error()),
                   s.options.t0);
  if (s.options.preserveInvariants && s.model.nInvariants > 0) s.startProjection();
}

void ArkodeSession::setStopTime(double tstop) {
  if (impl_->arkode) impl_->check(ARKStepSetStopTime(impl_->arkode, tstop), "ARKStepSetStopTime");
}

double ArkodeSession::advanceTo(double tout) { return impl_->advanceTo(tout); }
double ArkodeSession::time() const { return impl_->t; }
std::span<const double> ArkodeSession::y() const { return {data(impl_->y), impl_->n}; }
std::span<const double> ArkodeSession::yp() const { return {data(impl_->yp), impl_->n}; }
std::span<const double> ArkodeSession::parameters() const { return impl_->p; }
const QdotModel& ArkodeSession::model() const { return impl_->model; }
SolverStats ArkodeSession::stats() const { return impl_->stats(); }
const ToleranceSummary& ArkodeSession::tolerances() const { return summarize(impl_->tolerances); }
std::span<const double> ArkodeSession::absoluteTolerances() const { return impl_->tolerances.atol; }
LinearSolverKind ArkodeSession::linearSolver() const { return impl_->kind; }
const std::vector<std::string>& ArkodeSession::warnings() const { return impl_->warnings; }

}  // namespace qdot::rt
