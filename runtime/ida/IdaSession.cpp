// IdaSession: SUNDIALS IDA over a QdotModel. The model's residual and analytic Jacobian are called
// through static callbacks; every SUNDIALS call goes through Impl::check, which throws IdaError
// with a sentence from IdaFlags.cpp. Model failures are recorded (time, lastError) for that text.
#include "ida/IdaSession.h"

#include <fmt/format.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <future>

#include "arkode/StartLinearization.h"
#include "ida/DiagonalRates.h"
#include "ida/DummyDerivatives.h"
#include "ida/IdaFlags.h"
#include "ida/InitialSystem.h"
#include "ida/KluOrdering.h"
#include "ida/ModelCheck.h"
#include "ida/ReducedKlu.h"
#include "ida/SerialVectorOps.h"
#include "qdot/model_description.hpp"

namespace qdot::rt {

std::string_view linearSolverName(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::Auto:
      return "auto";
    case LinearSolverKind::Dense:
      return "dense";
    case LinearSolverKind::Klu:
      return "klu";
  }
  return "auto";
}

std::optional<LinearSolverKind> parseLinearSolver(std::string_view text) {
  for (auto kind : {LinearSolverKind::Auto, LinearSolverKind::Dense, LinearSolverKind::Klu})
    if (text == linearSolverName(kind)) return kind;
  return std::nullopt;
}

LinearSolverKind chooseLinearSolver(uint32_t n, uint32_t nonzeros) {
  if (n <= kDenseMaxAuto) return LinearSolverKind::Dense;
  double fill = static_cast<double>(nonzeros) / (static_cast<double>(n) * n);
  if (n <= 2000 && fill >= 0.3) return LinearSolverKind::Dense;
  return LinearSolverKind::Klu;
}

namespace {

/// Index of the first non-finite entry, or -1.
long firstNonFinite(const double* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i])) return static_cast<long>(i);
  return -1;
}

double* data(N_Vector v) { return N_VGetArrayPointer(v); }

/// Largest number of IDA warnings kept (IDA repeats some of them every step).
constexpr std::size_t kMaxWarnings = 10;

/// IDACalcIC attempts, each with the distance to its tout1 shrunk by kCalcICShrink.
constexpr int kCalcICAttempts = 4;
constexpr double kCalcICShrink = 1e-3;

/// |F_i| at or below this counts as zero when deciding whether IDACalcIC is needed.
constexpr double kConsistentResidual = 1e-14;


}  // namespace

/// How KLU factors a pattern: with its two-entry rows eliminated first (ida/ReducedKlu.h), or
/// whole, in a band ordering when RCM finds a narrow band.
struct KluChoice {
  std::optional<ReducedKluPlan> reduced;
  std::optional<BandOrdering> band;
};

KluChoice chooseKlu(CscPattern pattern, bool eliminate) {
  KluChoice choice;
  if (eliminate) choice.reduced = planReducedKlu(pattern);
  if (!choice.reduced) choice.band = chooseBandOrdering(pattern);
  return choice;
}

struct IdaSession::Impl {
  std::unique_ptr<DummyDerivativeModel> dummies;  ///< after index reduction: the square system's choice
  const QdotModel& model;                         ///< what IDA integrates (dummies->square() after index reduction)
  std::vector<double> p;
  SessionOptions options;
  uint32_t n;
  LinearSolverKind kind = LinearSolverKind::Dense;

  SUNContext context = nullptr;
  void* ida = nullptr;
  N_Vector y = nullptr, yp = nullptr, id = nullptr, atol = nullptr;
  N_Vector yStep = nullptr, ypStep = nullptr;  ///< after index reduction or when observed: the solution at IDA's last step
  IdaSession::StepObserver observer;
  double tStep = 0;
  SolverStats carried;  ///< counters of the integrations before the last restart (a new dummy choice)
  SUNMatrix matrix = nullptr;
  SUNLinearSolver solver = nullptr;

  std::vector<double> nominal;
  std::vector<double> start;  ///< the start values as the model gives them (automatic tolerance floors)
  std::vector<sunindextype> columnStarts, rowIndices;  // the CSC pattern in SUNDIALS' index type
  std::vector<double> jacobianValues;                  // dense only: values before scattering
  ToleranceVector tolerances;
  std::vector<double> tolerancesY;  ///< the y that `tolerances` were built from (applyTolerances)
  TimeScale timeScale;  ///< the velocities' time scale, from the linearization at the start
  double t;
  double tout = 0;
  InitialValueMethod initialValues = InitialValueMethod::AsGiven;
  std::optional<std::chrono::steady_clock::time_point> firstStepDone;
  bool blockTriangular = true;
  std::optional<BandOrdering> bandOrdering;  ///< KLU: the band ordering it was given (must outlive its analysis)
  bool reduced = false;  ///< KLU: the solver is reducedKluSolver (two-entry rows eliminated first)
  /// How KLU will factor columnStarts/rowIndices, being decided on another thread (orderAhead);
  /// declared after them, so that it is destroyed (joined) first.
  std::future<KluChoice> kluAhead;

  // What the last failure was, for the checking helper's message.
  bool modelFailed = false;
  std::string modelError;
  std::string solverMessage;
  std::vector<std::string> warnings;

  Impl(const QdotModel& m, std::vector<double> values, const SessionOptions& o)
      : dummies(m.nResiduals > m.nVariables ? std::make_unique<DummyDerivativeModel>(m) : nullptr),
        model(dummies ? dummies->square() : m),
        p(std::move(values)),
        options(o),
        n(m.nVariables),
        t(o.t0) {}
  ~Impl();

  void setup();
  void createVectors();
  void loadInitialValues();
  void createIntegrator();
  void attachLinearSolver();
  void orderAhead();
  void applyTolerances(bool calibrated = true, bool sameY = false);
  void initialize(double tout1);
  void calculateConsistentValues(double tout1);
  void restartFromConsistentValues(bool sameY = false);
  void estimateAlgebraicRates(double tout1);
  /// ∂F/∂y and J(cj = 1) at the start, in the Jacobian's CSC order (empty if J cannot be evaluated).
  struct StartJacobians {
    std::unique_ptr<double[]> own0, own1;  ///< where at0 and at1 live unless in the sparse matrix
    std::span<const double> at0, at1;
    /// ∂F/∂y' when it is diagonal (ida/DiagonalRates.h), found by checkStartMatrix for a model of
    /// differential unknowns only; ratesTried: looked for (rates then says whether it is).
    std::optional<DiagonalRates> rates;
    bool ratesTried = false;
  };
  StartJacobians checkStartMatrix();
  bool solveDiagonalRates(const StartJacobians& start, std::vector<double> F, double tout1);
  std::vector<std::string> dependentColumns(std::span<const double> at0, std::span<const double> at1) const;
  bool chooseDummyDerivatives(double time, N_Vector yv, N_Vector ypv, bool best);
  void solveInitialConditions();
  int initialNewtonIterations = -1;  ///< -1: no initialization system was solved
  /// The compiled model (with all rows, before the dummy derivative choice).
  const QdotModel& fullModel() const { return dummies ? *reinterpret_cast<const SquareTable*>(&model)->full : model; }
  void useChoice(double time, N_Vector yv, N_Vector ypv);
  double stepTo(double target);
  std::vector<double> startResidual();
  void noteChangedFixedStarts(const std::vector<double>& before);
  double advanceTo(double target);
  SolverStats stats();

  void check(int flag, std::string_view call, FlagFamily family = FlagFamily::Ida);
  template <class Handle>
  Handle created(Handle handle, std::string_view call) {
    check(handle ? 0 : -1, call, FlagFamily::Allocation);
    return handle;
  }
  [[noreturn]] void failOutsideIda(const std::string& what, double time);
  void clearFailure();
  std::string singularNote() const;
  int onModelFailure(double time, std::string message);
  int evaluateResidual(double time, const double* yv, const double* ypv, double* F);
  int evaluateJacobian(double time, double cj, N_Vector yv, N_Vector ypv, SUNMatrix J);
  void scatterDense(SUNMatrix J);
  void keepPattern(SUNMatrix J) const;

  static int residualCallback(sunrealtype time, N_Vector yv, N_Vector ypv, N_Vector F, void* self);
  static int jacobianCallback(sunrealtype time, sunrealtype cj, N_Vector yv, N_Vector ypv, N_Vector r, SUNMatrix J,
                              void* self, N_Vector, N_Vector, N_Vector);
  static void errorCallback(int code, const char* module, const char* function, char* message, void* self);
};

IdaSession::Impl::~Impl() {
  if (ida) IDAFree(&ida);
  if (solver) SUNLinSolFree(solver);
  if (matrix) SUNMatDestroy(matrix);
  for (N_Vector v : {y, yp, id, atol, yStep, ypStep})
    if (v) N_VDestroy(v);
  if (context) SUNContext_Free(&context);
}

// --- the checking helper --------------------------------------------------------------------

void IdaSession::Impl::check(int flag, std::string_view call, FlagFamily family) {
  bool ok = family == FlagFamily::Ida ? flag >= 0 : flag == 0;
  if (ok) return;
  FailureContext c;
  c.call = call;
  c.tout = tout;
  c.maxSteps = options.maxStepsPerOutput;
  c.time = t;
  if (ida) {  // plain getters: they fail only on a null ida, which is excluded here
    IDAGetCurrentTime(ida, &c.time);
    IDAGetLastStep(ida, &c.step);  // the last successful step (the attempted one may have shrunk to nothing)
  }
  c.modelFailed = modelFailed;
  c.modelError = modelError;
  c.solverMessage = solverMessage;
  c.linearSolverNote = singularNote();
  throw IdaError(describeFailure(flag, family, c), c.time);
}

void IdaSession::Impl::failOutsideIda(const std::string& what, double time) {
  throw IdaError(fmt::format("{} at t = {:.10g}: {}", what, time, modelError.empty() ? "(no message)" : modelError),
                 time);
}

std::string IdaSession::Impl::singularNote() const {
  // The last factorisation's outcome: a zero pivot names the unknown whose column is dependent.
  if (!solver) return "";
  long column = -1;
  if (kind == LinearSolverKind::Dense) {
    sunindextype pivot = SUNLinSolLastFlag(solver);  // 1-based column of a zero pivot, else 0
    if (pivot > 0 && pivot <= static_cast<sunindextype>(n)) column = static_cast<long>(pivot - 1);
  } else if (reduced) {
    column = static_cast<long>(reducedKluSingularColumn(solver));
  } else {
    // KLU's own status of its last call (the SUNDIALS flag only says "package failure")
    sun_klu_common* common = SUNLinSol_KLUGetCommon(solver);
    bool singular = common && common->status == KLU_SINGULAR;
    if (singular && common->singular_col >= 0 && common->singular_col < static_cast<sunindextype>(n))
      column = static_cast<long>(common->singular_col);
  }
  if (column < 0) return "";
  return fmt::format(
      "the Newton matrix is singular at the column of {} (no equation determines it, or the "
      "system has a higher index)",
      nameList(model.variableNames, n)[column]);
}

void IdaSession::Impl::clearFailure() {
  modelFailed = false;
  modelError.clear();
  solverMessage.clear();
}

// --- model callbacks ------------------------------------------------------------------------

// Keeps the first failure since the last reset: IDA's retries after it evaluate the model at states
// that the failure already poisoned (NaN inputs), and reporting those would hide the cause.
int IdaSession::Impl::onModelFailure(double time, std::string message) {
  if (!modelFailed) {  // time: IDA reports where it stopped (t_n), not this trial point
    modelFailed = true;
    modelError = std::move(message);
  }
  return 1;  // recoverable: IDA retries with a smaller step and gives up after repeated failures
}

int IdaSession::Impl::evaluateResidual(double time, const double* yv, const double* ypv, double* F) {
  int rc = model.residual(&model, time, yv, ypv, p.data(), F);
  if (rc != 0) {
    std::string text = modelLastError(model);
    return onModelFailure(time, text.empty() ? fmt::format("the residual returned {}", rc) : text);
  }
  long bad = firstNonFinite(F, n);
  if (bad >= 0) return onModelFailure(time, fmt::format("residual F[{}] evaluated to {}", bad, F[bad]));
  return 0;
}

int IdaSession::Impl::residualCallback(sunrealtype time, N_Vector yv, N_Vector ypv, N_Vector F, void* self) {
  auto* impl = static_cast<Impl*>(self);
  if (!impl->firstStepDone) {
    long steps = 0;
    if (IDAGetNumSteps(impl->ida, &steps) == IDA_SUCCESS && steps > 0) impl->firstStepDone = std::chrono::steady_clock::now();
  }
  return impl->evaluateResidual(time, data(yv), data(ypv), data(F));
}

// IDA zeroes the Jacobian before every evaluation (SUNMatZero: the values, and for a sparse matrix
// its row indices and column starts too). The model writes every value of its pattern on every
// call (the ABI's jacobian; the kernels' stores are unconditional), so the sparse matrix is zeroed
// and given the pattern once, here, and IDA's zeroing of it does nothing: at 10⁶ masses that was
// 144 MB cleared and 80 MB of pattern copied back per Jacobian. A value the model never writes
// stays the 0 it starts with, as before. (The dense matrix keeps IDA's zeroing: only the pattern's
// entries are scattered into it.)
void IdaSession::Impl::keepPattern(SUNMatrix J) const {
  // The values are zeros already (SUNSparseMatrix callocs its arrays: zeroing them again took
  // 5-10 ms at 10⁶ masses); the pattern copied over the index arrays (room for at least one entry
  // even without any: that slot is zeroed too).
  sunindextype room = SUNSparseMatrix_NNZ(J);
  std::copy(columnStarts.begin(), columnStarts.end(), SUNSparseMatrix_IndexPointers(J));
  sunindextype* rows = std::copy(rowIndices.begin(), rowIndices.end(), SUNSparseMatrix_IndexValues(J));
  std::fill(rows, SUNSparseMatrix_IndexValues(J) + room, sunindextype{0});
  J->ops->zero = [](SUNMatrix) -> int { return SUNMAT_SUCCESS; };
}

void IdaSession::Impl::scatterDense(SUNMatrix J) {
  for (uint32_t column = 0; column < n; ++column) {
    double* out = SUNDenseMatrix_Column(J, column);
    std::fill(out, out + n, 0.0);
    for (sunindextype k = columnStarts[column]; k < columnStarts[column + 1]; ++k)
      out[rowIndices[k]] = jacobianValues[k];
  }
}

int IdaSession::Impl::evaluateJacobian(double time, double cj, N_Vector yv, N_Vector ypv, SUNMatrix J) {
  double* values = kind == LinearSolverKind::Klu ? SUNSparseMatrix_Data(J) : jacobianValues.data();
  int rc = model.jacobian(&model, time, data(yv), data(ypv), p.data(), cj, values);
  if (rc != 0) {
    std::string text = modelLastError(model);
    return onModelFailure(time, text.empty() ? fmt::format("the Jacobian returned {}", rc) : text);
  }
  long bad = firstNonFinite(values, model.jacobianNonzeros);
  if (bad >= 0) return onModelFailure(time, fmt::format("Jacobian entry {} evaluated to {}", bad, values[bad]));
  if (kind == LinearSolverKind::Dense) scatterDense(J);
  return 0;
}

int IdaSession::Impl::jacobianCallback(sunrealtype time, sunrealtype cj, N_Vector yv, N_Vector ypv, N_Vector,
                                       SUNMatrix J, void* self, N_Vector, N_Vector, N_Vector) {
  return static_cast<Impl*>(self)->evaluateJacobian(time, cj, yv, ypv, J);
}

void IdaSession::Impl::errorCallback(int code, const char*, const char*, char* message, void* self) {
  auto& s = *static_cast<Impl*>(self);
  std::string text = message ? message : "";
  if (code != IDA_WARNING) {
    s.solverMessage = text;
  } else if (s.warnings.size() < kMaxWarnings) {
    s.warnings.push_back("IDA: " + text);
  }
}

// --- setup ----------------------------------------------------------------------------------

void IdaSession::Impl::setup() {
  if (auto problem = checkModel(fullModel())) throw IdaError(*problem, options.t0);
  if (p.size() != model.nParameters)
    throw IdaError(fmt::format("{} parameter values given, the model has {}", p.size(), model.nParameters), options.t0);
  check(SUNContext_Create(nullptr, &context), "SUNContext_Create", FlagFamily::Allocation);
  if (n == 0) return;  // nothing to integrate: the session only carries time
  orderAhead();
  createVectors();
  loadInitialValues();
  if (dummies) chooseDummyDerivatives(options.t0, y, yp, true);
  createIntegrator();
  attachLinearSolver();
}

// KLU's band ordering depends on the Jacobian's pattern only: for a large model its breadth-first
// searches (0.18 s at 2·10⁶ unknowns) run on the other core while the start values are computed and
// the integrator is made; attachLinearSolver takes the result. Not after index reduction (the
// dummy derivatives choose the pattern) and not for small models (a thread costs more than it saves).
constexpr uint32_t kOrderAheadFrom = 20000;

void IdaSession::Impl::orderAhead() {
  if (dummies || n < kOrderAheadFrom) return;
  LinearSolverKind k = options.linearSolver == LinearSolverKind::Auto ? chooseLinearSolver(n, model.jacobianNonzeros)
                                                                      : options.linearSolver;
  if (k != LinearSolverKind::Klu) return;
  columnStarts.assign(model.jacobianColumnStarts, model.jacobianColumnStarts + n + 1);
  rowIndices.assign(model.jacobianRowIndices, model.jacobianRowIndices + model.jacobianNonzeros);
  kluAhead = std::async(std::launch::async, [this] {
    return chooseKlu({columnStarts, rowIndices}, options.eliminateTwoEntryRows);
  });
}

void IdaSession::Impl::createVectors() {
  // Every vector with the operations compiled here (ida/SerialVectorOps.h: Debian's are unoptimized);
  // IDA clones its own from y, operations table included.
  auto vector = [&] {
    N_Vector v = created(N_VNew_Serial(n, context), "N_VNew_Serial");
    useOptimizedSerialOps(v);
    return v;
  };
  if (dummies || options.observeSteps) {
    yStep = vector();
    ypStep = vector();
  }
  y = created(N_VNew_Serial(n, context), "N_VNew_Serial");
  // With the fused operations a linear combination of k vectors (the predictor, the error
  // estimate) is one call instead of a N_VScale and k - 1 N_VLinearSum, and one pass over memory
  // (SerialVectorOps.cpp), which a large model's steps are bound by. The same sums in the same
  // order: every result is the same to the bit.
  N_VEnableFusedOps_Serial(y, SUNTRUE);
  useOptimizedSerialOps(y);
  yp = vector();
  id = vector();
  atol = vector();
  for (uint32_t i = 0; i < n; ++i)
    data(id)[i] = model.isDifferential[i] ? 1.0 : 0.0;
}

void IdaSession::Impl::loadInitialValues() {
  nominal.assign(n, 0.0);
  std::fill(data(y), data(y) + n, 0.0);
  std::fill(data(yp), data(yp) + n, 0.0);
  if (model.initialValues(&model, p.data(), options.t0, data(y), data(yp), nominal.data()) != 0) {
    modelError = modelLastError(model);
    failOutsideIda("the start values could not be computed", options.t0);
  }
  start.assign(data(y), data(y) + n);
  if (!options.atol) timeScale = modelTimeScale(fullModel(), p, options.t0);  // with --atol: no scales
  long bad = firstNonFinite(data(y), n);
  if (bad >= 0) {
    modelError = fmt::format("the start value of {} is {}", nameList(model.variableNames, n)[bad], data(y)[bad]);
    failOutsideIda("the start values are not finite", options.t0);
  }
}

void IdaSession::Impl::createIntegrator() {
  ida = created(IDACreate(context), "IDACreate");
  check(IDASetErrHandlerFn(ida, &Impl::errorCallback, this), "IDASetErrHandlerFn");
  check(IDASetUserData(ida, this), "IDASetUserData");
  check(IDAInit(ida, &Impl::residualCallback, options.t0, y, yp), "IDAInit");
  applyTolerances(false);
  check(IDASetId(ida, id), "IDASetId");
  check(IDASetMaxNumSteps(ida, options.maxStepsPerOutput), "IDASetMaxNumSteps");
}

// calibrated = false: the tolerances as the user gave them, for IDACalcIC, whose Newton test is
// relative to them (tighter weights made the line search fail on constrained models); the run
// itself uses the calibrated ones (Tolerances.h).
// sameY: y, the start values and the nominals are those of the last build (only y' changed, as
// after the diagonal rates): the scales are kept (useCalibrated) instead of computed again.
void IdaSession::Impl::applyTolerances(bool calibrated, bool sameY) {
  if (sameY && calibrated && tolerances.scale.size() == n && std::equal(tolerancesY.begin(), tolerancesY.end(), data(y))) {
    useCalibrated(tolerances);
  } else {
    tolerances = buildTolerances(options.rtol, options.atol, {data(y), n}, nominal, {model.isDifferential, n}, start,
                                 timeScale);
    tolerancesY.assign(data(y), data(y) + n);
    if (!calibrated) useAsGiven(tolerances);
  }
  std::copy(tolerances.atol.begin(), tolerances.atol.end(), data(atol));
  check(IDASVtolerances(ida, tolerances.solverRtol, atol), "IDASVtolerances");
}

void IdaSession::Impl::attachLinearSolver() {
  uint32_t nnz = model.jacobianNonzeros;
  kind = options.linearSolver == LinearSolverKind::Auto ? chooseLinearSolver(n, nnz) : options.linearSolver;
  if (kind == LinearSolverKind::Dense && n > kDenseMaxForced)
    throw IdaError(fmt::format("the dense linear solver would need a {} x {} matrix ({:.1f} GiB): use "
                               "--linear-solver klu",
                               n, n, 8.0 * n * n / (1u << 30)),
                   options.t0);
  if (solver) SUNLinSolFree(solver), solver = nullptr;  // a new dummy derivative choice: a new pattern
  if (matrix) SUNMatDestroy(matrix), matrix = nullptr;
  bandOrdering.reset();
  reduced = false;
  // made ahead of this from the same pattern, which orderAhead copied into columnStarts/rowIndices
  std::optional<KluChoice> ahead;
  if (kluAhead.valid()) ahead = kluAhead.get();
  if (!ahead) {
    columnStarts.assign(model.jacobianColumnStarts, model.jacobianColumnStarts + n + 1);
    rowIndices.assign(model.jacobianRowIndices, model.jacobianRowIndices + nnz);
  }
  if (kind == LinearSolverKind::Klu) {
    matrix = created(SUNSparseMatrix(n, n, std::max<uint32_t>(nnz, 1), CSC_MAT, context), "SUNSparseMatrix");
    keepPattern(matrix);
    KluChoice choice = ahead ? std::move(*ahead) : chooseKlu({columnStarts, rowIndices}, options.eliminateTwoEntryRows);
    if (choice.reduced) {  // the kinematic rows solved for first: KLU factors the rest (ida/ReducedKlu.h)
      blockTriangular = choice.reduced->blockTriangular;
      solver = created(reducedKluSolver(std::move(*choice.reduced), context), "reducedKluSolver");
      reduced = true;
      check(IDASetLinearSolver(ida, solver, matrix), "IDASetLinearSolver", FlagFamily::LinearSolverInterface);
      check(IDASetJacFn(ida, &Impl::jacobianCallback), "IDASetJacFn", FlagFamily::LinearSolverInterface);
      return;
    }
    solver = created(SUNLinSol_KLU(y, matrix, context), "SUNLinSol_KLU");
    // KLU's block triangular form starts with a maximum transversal (BTF's maxtrans): one pass
    // when the pattern's diagonal is zero-free, O(n · nnz) at worst otherwise — 92 s of the first
    // step of a 10⁵-mass chain whose rows came in another order than its unknowns. Without a
    // zero-free diagonal KLU factors the whole matrix instead (its fill-reducing ordering and
    // partial pivoting), which for such a model took 0.09 s.
    // A pattern that RCM turns into a narrow band is ordered so, without BTF (ida/KluOrdering.h):
    // a few breadth-first searches instead of BTF and COLAMD, most of the first step at 10⁶ masses.
    bandOrdering = std::move(choice.band);
    if (bandOrdering) useBandOrdering(*SUNLinSol_KLUGetCommon(solver), *bandOrdering);
    blockTriangular = !bandOrdering && zeroFreeDiagonal({columnStarts, rowIndices});
    if (!blockTriangular) SUNLinSol_KLUGetCommon(solver)->btf = 0;
  } else {
    jacobianValues.assign(nnz, 0.0);
    matrix = created(SUNDenseMatrix(n, n, context), "SUNDenseMatrix");
    solver = created(SUNLinSol_Dense(y, matrix, context), "SUNLinSol_Dense");
  }
  check(IDASetLinearSolver(ida, solver, matrix), "IDASetLinearSolver", FlagFamily::LinearSolverInterface);
  check(IDASetJacFn(ida, &Impl::jacobianCallback), "IDASetJacFn", FlagFamily::LinearSolverInterface);
}

// --- consistent initial values --------------------------------------------------------------

std::vector<double> IdaSession::Impl::startResidual() {
  std::vector<double> F(n);
  clearFailure();
  if (evaluateResidual(options.t0, data(y), data(yp), F.data()) != 0)
    failOutsideIda("the residual cannot be evaluated at the start", options.t0);
  return F;
}

namespace {

bool consistent(const std::vector<double>& F) {
  return std::all_of(F.begin(), F.end(), [](double f) { return std::abs(f) <= kConsistentResidual; });
}

}  // namespace

// Every unknown differential and ∂F/∂y' diagonal up to the order of its rows (ida/DiagonalRates.h):
// y' from one division per unknown instead of IDACalcIC, whose matrix (∂F/∂y + ∂F/∂y'/h) needs a
// factorization and usually more than one iteration — at 10⁶ unknowns a large part of the time to
// the first step. Accepted by IDACalcIC's own convergence test; otherwise (F not linear in y') the
// start values are restored and IDACalcIC runs as before.
bool IdaSession::Impl::solveDiagonalRates(const StartJacobians& start, std::vector<double> F, double tout1) {
  if (start.at0.empty()) return false;
  std::optional<DiagonalRates> found;
  if (!start.ratesTried)
    found = diagonalRates<int32_t>({model.jacobianColumnStarts, n + 1}, {model.jacobianRowIndices, start.at0.size()},
                                   start.at0, start.at1);
  const std::optional<DiagonalRates>& rates = start.ratesTried ? start.rates : found;  // not a copy: 24 MB at 10⁶ masses
  if (!rates) return false;
  std::vector<double> given(data(yp), data(yp) + n);
  stepRates(*rates, F, {data(yp), n});
  clearFailure();
  if (evaluateResidual(options.t0, data(y), data(yp), F.data()) == 0 &&
      ratesConverged(*rates, F, {data(y), n}, tolerances.solverRtol, tolerances.atol, tout1 - options.t0))
    return true;
  std::copy(given.begin(), given.end(), data(yp));
  clearFailure();
  return false;
}

// Consistent initialization changes only algebraic unknowns. One whose start was fixed — by default
// (a coordinate the constraints made dependent) or as written — is checked: as written and changed
// it contradicts the other conditions (an error naming it); as written and kept it was redundant (a
// note); by default and changed it was a guess (a note saying so); a fixed algebraic variable of a
// model without constraints that had to change is a warning, as before.
void IdaSession::Impl::noteChangedFixedStarts(const std::vector<double>& before) {
  if (!model.fixedStarts) return;
  std::vector<int32_t> fixed(n, 0);
  if (model.fixedStarts(&model, fixed.data()) != 0) return;
  auto names = nameList(model.variableNames, n);
  std::vector<std::string> redundant;
  for (uint32_t i = 0; i < n; ++i) {
    double now = data(y)[i];
    bool changed = std::abs(now - before[i]) > 1e-6 * std::max(1.0, std::abs(before[i]));
    if (model.isDifferential[i] || !fixed[i]) continue;
    if (dummies && fixed[i] == kFixedAsWritten && changed)
      throw IdaError(fmt::format("the initial conditions contradict each other: the start value of {} is fixed "
                                 "at {:.10g}, but the constraints and the other start values give {:.10g} (declare it "
                                 "a guess, {}(start = ..., fixed = false), or correct it)",
                                 names[i], before[i], now, names[i]),
                     options.t0);
    if (dummies && fixed[i] == kFixedAsWritten) redundant.emplace_back(names[i]);
    else if (dummies && changed)
      warnings.push_back(fmt::format("note: the start value of {} ({:.10g}) was a guess: the constraints give {:.10g}",
                                     names[i], before[i], now));
    else if (changed)
      warnings.push_back(
          fmt::format("the fixed start value of algebraic {} ({:.10g}) was changed to {:.10g} to make "
                      "the initial values consistent",
                      names[i], before[i], now));
  }
  if (!redundant.empty()) {
    std::string list;
    for (const auto& r : redundant) list += (list.empty() ? "" : ", ") + r;
    warnings.push_back(fmt::format("note: the fixed start value{} of {} {} redundant with the constraints (and "
                                   "consistent with them)",
                                   redundant.size() == 1 ? "" : "s", list, redundant.size() == 1 ? "is" : "are"));
  }
}

void IdaSession::Impl::calculateConsistentValues(double tout1) {
  // IDACalcIC takes its pseudo step from tout1 - t0. Its Newton matrix is exact only when that
  // step is short against the model's time scales, so a far first output time (Robertson: 1e10)
  // can make it fail; then it is retried from the start values with a step 1000 times shorter.
  double span = tout1 - options.t0;
  for (int attempt = 1;; ++attempt) {
    try {
      clearFailure();
      tout = options.t0 + span;
      check(IDACalcIC(ida, IDA_YA_YDP_INIT, tout), "IDACalcIC");
      return;
    } catch (const IdaError&) {
      if (attempt == kCalcICAttempts) throw;
    }
    span *= kCalcICShrink;
    check(IDAReInit(ida, options.t0, y, yp), "IDAReInit");  // y, yp still hold the start values
  }
}

// IDACalcIC leaves the rates of the algebraic unknowns as they were given (0). The first step's
// predictor then takes them as constant: the flows under a force F0 sin(wt) from rest change at
// F0 w from the start, the predicted change is 0, and with tight tolerances the error test fails
// at t0 however short the step. Their rates by a forward difference: the algebraic unknowns made
// consistent again a short time later, the differential ones moved along their rates. Only the
// predictor uses them; if that second solve fails they stay 0.
void IdaSession::Impl::estimateAlgebraicRates(double tout1) {
  double span = tout1 - options.t0;
  double eps = 1e-4 * span;
  if (!(eps > 0)) return;
  std::vector<double> y0(data(y), data(y) + n), yp0(data(yp), data(yp) + n);
  for (uint32_t i = 0; i < n; ++i)
    if (model.isDifferential[i]) data(y)[i] += eps * yp0[i];
  bool ok = true;
  try {
    clearFailure();
    check(IDAReInit(ida, options.t0 + eps, y, yp), "IDAReInit");
    check(IDACalcIC(ida, IDA_YA_YDP_INIT, options.t0 + eps + span), "IDACalcIC");
    check(IDAGetConsistentIC(ida, y, yp), "IDAGetConsistentIC");
  } catch (const IdaError&) {
    ok = false;
  }
  std::vector<double> later(data(y), data(y) + n);
  std::copy(y0.begin(), y0.end(), data(y));
  std::copy(yp0.begin(), yp0.end(), data(yp));
  if (ok)
    for (uint32_t i = 0; i < n; ++i)
      if (!model.isDifferential[i]) data(yp)[i] = (later[i] - y0[i]) / eps;
  clearFailure();
}

// Before anything is solved: the equations must contain, at the start, the derivative of every
// differential unknown and every algebraic unknown (the columns of ∂F/∂y' and ∂F/∂y that IDA's
// matrix needs). A column that is zero there — a mass or moment of inertia of 0 (`-p m=0`) leaves
// its coordinate's acceleration in no equation — is named here, instead of a Newton failure later.
// After index reduction a column can be non-zero and still dependent: with m = 0 the rows of a
// pendulum's x and y both contain only the multiplier. The matrix of the unknowns IDA solves for
// (y' of a differential unknown, y of an algebraic one) must be regular; QR with column pivoting
// names the columns beyond its numerical rank. Small systems only (dense).
std::vector<std::string> IdaSession::Impl::dependentColumns(std::span<const double> at0,
                                                            std::span<const double> at1) const {
  constexpr uint32_t kLargest = 400;
  if (n > kLargest) return {};
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (uint32_t c = 0; c < n; ++c)
    for (int32_t k = model.jacobianColumnStarts[c]; k < model.jacobianColumnStarts[c + 1]; ++k)
      A(model.jacobianRowIndices[k], c) = model.isDifferential[c] ? at1[k] - at0[k] : at0[k];
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  qr.setThreshold(1e-12);
  std::vector<std::string> dependent;
  auto names = nameList(model.variableNames, n);
  for (Eigen::Index k = qr.rank(); k < static_cast<Eigen::Index>(n); ++k) {
    auto c = static_cast<uint32_t>(qr.colsPermutation().indices()[k]);
    dependent.push_back(model.isDifferential[c] ? "der(" + std::string(names[c]) + ")" : std::string(names[c]));
  }
  return dependent;
}

IdaSession::Impl::StartJacobians IdaSession::Impl::checkStartMatrix() {
  uint32_t nnz = model.jacobianNonzeros;
  // The kernel writes every entry (IDA's Jacobian callback relies on it too): nothing is zeroed
  // first. J(cj = 1) goes where IDA's first Jacobian will, KLU's matrix, unused until then: at 10⁶
  // masses two fresh 64 MB arrays, zeroed, took 0.07 s.
  StartJacobians start;
  start.own0.reset(new double[nnz]);
  double* values1 = kind == LinearSolverKind::Klu && matrix && !dummies ? SUNSparseMatrix_Data(matrix) : nullptr;
  if (!values1) start.own1.reset(values1 = new double[nnz]);
  if (model.jacobian(&model, options.t0, data(y), data(yp), p.data(), 0.0, start.own0.get()) != 0 ||
      model.jacobian(&model, options.t0, data(y), data(yp), p.data(), 1.0, values1) != 0)
    return {};  // a failing Jacobian is reported where IDA meets it, with its message
  std::span<const double> at0(start.own0.get(), nnz), at1(values1, nnz);
  // Every unknown differential: where ∂F/∂y' is diagonal, each column has its entry (seen and
  // nonzero), so none is missing — the pass below would only confirm it (0.03 s at 10⁶ masses).
  if (!dummies && std::all_of(model.isDifferential, model.isDifferential + n, [](int32_t d) { return d != 0; })) {
    start.ratesTried = true;
    start.rates = diagonalRates<int32_t>({model.jacobianColumnStarts, n + 1}, {model.jacobianRowIndices, nnz}, at0, at1);
    if (start.rates) {
      start.at0 = at0, start.at1 = at1;
      return start;
    }
  }
  std::vector<std::string> missing;
  // dF/dy' is J(cj = 1) - J(cj = 0): where |dF/dy| is so large that adding 1 does not change it
  // (a stiffness of 1e300), the difference cannot see the entry, and the column is not declared
  // missing on its account.
  auto unseen = [](double at0) { return at0 + 1.0 == at0 || !std::isfinite(at0); };
  for (uint32_t c = 0; c < n; ++c) {
    bool zero = true;
    for (int32_t k = model.jacobianColumnStarts[c]; k < model.jacobianColumnStarts[c + 1]; ++k)
      zero &= model.isDifferential[c] ? at1[k] - at0[k] == 0 && !unseen(at0[k]) : at0[k] == 0;
    if (zero) missing.push_back(model.isDifferential[c] ? "der(" + std::string(model.variableNames[c]) + ")"
                                                        : std::string(model.variableNames[c]));
  }
  bool dependent = missing.empty() && dummies;
  if (dependent) missing = dependentColumns(at0, at1);
  if (missing.empty()) {
    start.at0 = at0, start.at1 = at1;
    return start;
  }
  std::string list;
  for (size_t i = 0; i < missing.size() && i < 8; ++i) list += (i ? ", " : "") + missing[i];
  if (missing.size() > 8) list += fmt::format(", … ({} more)", missing.size() - 8);
  std::string why = dependent ? "the equations are singular in " + std::string(missing.size() == 1 ? "it" : "them") +
                                     " there (dependent on the other unknowns)"
                              : "no equation contains " + std::string(missing.size() == 1 ? "it" : "them") + " there";
  throw IdaError(fmt::format("the equations do not determine {} at t = {:.10g}: {} (a mass or moment of inertia of 0 "
                             "makes the mass matrix singular; check the parameters)",
                             list, options.t0, why),
                 options.t0);
}

void IdaSession::Impl::initialize(double tout1) {
  if (n == 0) return;
  if (fullModel().nInitialRows > 0) solveInitialConditions();
  StartJacobians start = checkStartMatrix();
  bool hasAlgebraic = std::any_of(model.isDifferential, model.isDifferential + n, [](int32_t d) { return d == 0; });
  if (!hasAlgebraic) {
    std::vector<double> F = startResidual();
    // y is as createIntegrator built the tolerances from: only y' may change here
    if (consistent(F)) return applyTolerances(true, true);
    if (!dummies && solveDiagonalRates(start, std::move(F), tout1)) {
      initialValues = InitialValueMethod::DiagonalRates;
      return restartFromConsistentValues(true);
    }
  }
  start = {};
  std::vector<double> before(data(y), data(y) + n);
  calculateConsistentValues(tout1);
  check(IDAGetConsistentIC(ida, y, yp), "IDAGetConsistentIC");
  if (dummies && chooseDummyDerivatives(options.t0, y, yp, true)) {  // the start values were only a guess
    useChoice(options.t0, y, yp);
    calculateConsistentValues(tout1);
    check(IDAGetConsistentIC(ida, y, yp), "IDAGetConsistentIC");
  }
  initialValues = InitialValueMethod::CalcIC;
  noteChangedFixedStarts(before);
  if (hasAlgebraic) estimateAlgebraicRates(tout1);
  restartFromConsistentValues();
}

// Automatic scales from the consistent values. IDA binds its tolerance data during its initial
// setup (which IDACalcIC has done), so new tolerances need a restart from the consistent point.
void IdaSession::Impl::restartFromConsistentValues(bool sameY) {
  check(IDAReInit(ida, options.t0, y, yp), "IDAReInit");
  applyTolerances(true, sameY);
  if (yStep) {
    N_VScale(1.0, y, yStep);
    N_VScale(1.0, yp, ypStep);
    tStep = options.t0;
  }
}

// Initial equations that are not start values: the whole initialization system by Newton, then a
// restart from its solution (IDACalcIC after it finds nothing to change).
void IdaSession::Impl::solveInitialConditions() {
  std::vector<int32_t> fixed(n, 0);
  if (model.fixedStarts) model.fixedStarts(&model, fixed.data());
  try {
    InitialSystemResult r =
        solveInitialSystem(fullModel(), dummies->keptRows(), model.isDifferential, fixed.data(), p.data(), options.t0,
                           data(y), data(yp));
    initialNewtonIterations = r.iterations;
  } catch (const std::runtime_error& e) {
    throw IdaError(e.what(), options.t0);  // the run names the time
  }
  check(IDAReInit(ida, options.t0, y, yp), "IDAReInit");
}

// --- dummy derivatives (index reduction) ------------------------------------------------------

bool IdaSession::Impl::chooseDummyDerivatives(double time, N_Vector yv, N_Vector ypv, bool best) {
  try {
    bool changed = dummies->choose(time, data(yv), data(ypv), p.data(), best);
    if (changed && id)
      for (uint32_t i = 0; i < n; ++i) data(id)[i] = model.isDifferential[i] ? 1.0 : 0.0;
    return changed;
  } catch (const std::runtime_error& e) {
    throw IdaError(e.what(), time);  // the run names the time
  }
}

// After a new choice at `time`: the new states' rates are the derivatives their links name (the
// values are consistent already), and IDA restarts there with the new id vector and pattern.
void IdaSession::Impl::useChoice(double time, N_Vector yv, N_Vector ypv) {
  const QdotModel& full = fullModel();
  for (uint32_t k = 0; k < full.nDerivativeLinks; ++k) {
    const int32_t* l = full.derivativeLinks + 3 * k;
    if (model.isDifferential[l[1]]) data(ypv)[l[1]] = data(yv)[l[2]];
  }
  carried = stats();  // IDAReInit resets IDA's counters
  check(IDAReInit(ida, time, yv, ypv), "IDAReInit");
  check(IDASetId(ida, id), "IDASetId");
  attachLinearSolver();
}

// One step at a time, so that the choice of dummy derivatives is checked after every step; the
// output at `target` is interpolated from the last step (IDAGetDky), which is never across a restart.
double IdaSession::Impl::stepTo(double target) {
  while (tStep < target) {
    if (dummies && chooseDummyDerivatives(tStep, yStep, ypStep, false)) useChoice(tStep, yStep, ypStep);
    sunrealtype reached = tStep;
    check(IDASolve(ida, target, &reached, yStep, ypStep, IDA_ONE_STEP), "IDASolve");
    tStep = reached;
    // A step that ends before the output time is seen by the observer; one that passes it is not:
    // the rows interpolated inside it (written next) follow each other more closely than its ends.
    if (observer && tStep < target) observer(tStep, {N_VGetArrayPointer(yStep), n}, {N_VGetArrayPointer(ypStep), n});
  }
  check(IDAGetDky(ida, target, 0, y), "IDAGetDky");
  check(IDAGetDky(ida, target, 1, yp), "IDAGetDky");
  return t = target;
}

// --- integration ----------------------------------------------------------------------------

double IdaSession::Impl::advanceTo(double target) {
  tout = target;
  if (n == 0) return t = target;
  clearFailure();
  if (dummies || options.observeSteps) return stepTo(target);
  sunrealtype reached = t;
  bool atStart = t == options.t0 && stats().steps == 0;
  std::vector<double> y0(atStart ? n : 0), yp0(atStart ? n : 0);
  if (atStart) std::copy(data(y), data(y) + n, y0.begin()), std::copy(data(yp), data(yp) + n, yp0.begin());
  int flag = IDASolve(ida, target, &reached, y, yp, IDA_NORMAL);
  if (flag == IDA_ERR_FAIL && atStart && tolerances.solverRtol < options.rtol) {
    // Some models cannot take a first step at the calibrated rtol (the consistent start is not
    // that exact): they run at the rtol as given, and say so.
    warnings.push_back(fmt::format("note: the first step failed at the calibrated rtol {:.3g}; the run uses rtol {:g} "
                                   "as given, so its error may exceed rtol (docs/accuracy.md)",
                                   tolerances.solverRtol, options.rtol));
    std::copy(y0.begin(), y0.end(), data(y)), std::copy(yp0.begin(), yp0.end(), data(yp));
    check(IDAReInit(ida, options.t0, y, yp), "IDAReInit");
    applyTolerances(false);
    reached = t;
    clearFailure();
    flag = IDASolve(ida, target, &reached, y, yp, IDA_NORMAL);
  }
  check(flag, "IDASolve");
  t = reached;
  return t;
}

SolverStats IdaSession::Impl::stats() {
  SolverStats s;
  if (!ida) return s;
  check(IDAGetNumSteps(ida, &s.steps), "IDAGetNumSteps");
  check(IDAGetNumResEvals(ida, &s.residualEvaluations), "IDAGetNumResEvals");
  check(IDAGetNumJacEvals(ida, &s.jacobianEvaluations), "IDAGetNumJacEvals", FlagFamily::LinearSolverInterface);
  check(IDAGetNumNonlinSolvIters(ida, &s.nonlinearIterations), "IDAGetNumNonlinSolvIters");
  check(IDAGetNumErrTestFails(ida, &s.errorTestFailures), "IDAGetNumErrTestFails");
  check(IDAGetNumNonlinSolvConvFails(ida, &s.convergenceFailures), "IDAGetNumNonlinSolvConvFails");
  check(IDAGetLastStep(ida, &s.lastStep), "IDAGetLastStep");
  check(IDAGetLastOrder(ida, &s.lastOrder), "IDAGetLastOrder");
  if (!dummies) return s;
  s.steps += carried.steps;
  s.residualEvaluations += carried.residualEvaluations;
  s.jacobianEvaluations += carried.jacobianEvaluations;
  s.nonlinearIterations += carried.nonlinearIterations;
  s.errorTestFailures += carried.errorTestFailures;
  s.convergenceFailures += carried.convergenceFailures;
  s.dummyDerivatives = dummies->dummyNames();
  s.initialNewtonIterations = initialNewtonIterations;
  s.dummyChanges = dummies->changes();
  return s;
}

// --- the public face ------------------------------------------------------------------------

IdaSession::IdaSession(const QdotModel& model, std::vector<double> p, const SessionOptions& options)
    : impl_(std::make_unique<Impl>(model, std::move(p), options)) {
  impl_->setup();  // on a throw, impl_ is destroyed and frees what was created
}

IdaSession::~IdaSession() = default;

void IdaSession::initialize(double tout1) { impl_->initialize(tout1); }

void IdaSession::setStopTime(double tstop) {
  if (impl_->ida) impl_->check(IDASetStopTime(impl_->ida, tstop), "IDASetStopTime");
}

double IdaSession::advanceTo(double tout) { return impl_->advanceTo(tout); }
void IdaSession::setStepObserver(StepObserver observer) { impl_->observer = std::move(observer); }
double IdaSession::time() const { return impl_->t; }

std::span<const double> IdaSession::y() const {
  return impl_->y ? std::span<const double>(data(impl_->y), impl_->n) : std::span<const double>();
}

std::span<const double> IdaSession::yp() const {
  return impl_->yp ? std::span<const double>(data(impl_->yp), impl_->n) : std::span<const double>();
}

std::span<const double> IdaSession::parameters() const { return impl_->p; }
const QdotModel& IdaSession::model() const { return impl_->model; }
SolverStats IdaSession::stats() const { return impl_->stats(); }
const ToleranceSummary& IdaSession::tolerances() const { return summarize(impl_->tolerances); }
std::span<const double> IdaSession::absoluteTolerances() const { return impl_->tolerances.atol; }
LinearSolverKind IdaSession::linearSolver() const { return impl_->kind; }
bool IdaSession::computedInitialValues() const { return impl_->initialValues != InitialValueMethod::AsGiven; }
InitialValueMethod IdaSession::initialValueMethod() const { return impl_->initialValues; }
bool IdaSession::blockTriangular() const { return impl_->blockTriangular; }
std::optional<int64_t> IdaSession::bandwidth() const {
  if (impl_->reduced) {
    const auto& band = reducedKluPlan(impl_->solver).band;
    return band ? std::optional<int64_t>(band->bandwidth) : std::nullopt;
  }
  return impl_->bandOrdering ? std::optional<int64_t>(impl_->bandOrdering->bandwidth) : std::nullopt;
}
bool IdaSession::reducedAsBand() const { return impl_->reduced && reducedKluBanded(impl_->solver); }
int64_t IdaSession::eliminatedRows() const { return impl_->reduced ? reducedKluPlan(impl_->solver).rows.pairs() : 0; }
std::optional<std::chrono::steady_clock::time_point> IdaSession::firstStepDone() const { return impl_->firstStepDone; }
const std::vector<std::string>& IdaSession::warnings() const { return impl_->warnings; }

}  // namespace qdot::rt
