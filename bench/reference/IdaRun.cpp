// simulateReference: SUNDIALS IDA 6.4 over a hand-written ReferenceModel, call for call what
// qdot's runtime does — fused vector operations, IDAInit, per-variable atol (qdot's rule, rt::buildTolerances, with the
// velocities' time scale from this program's own linearization at the start), IDASetId,
// IDASetMaxNumSteps, dense or KLU with the analytic Jacobian, IDACalcIC(IDA_YA_YDP_INIT) towards
// the first output time when F(y0, y'0) != 0 followed by IDAReInit and rebuilt tolerances,
// IDASetStopTime, then IDASolve(IDA_NORMAL) to each output time with a CSV row after each.
#include "reference/IdaRun.h"

#include "arkode/StartLinearization.h"
#include "ida/DiagonalRates.h"
#include "ida/KluOrdering.h"
#include "ida/SerialVectorOps.h"
#include "sim/ProcessClock.h"

#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace qdot::bench {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void check(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string(call) + " failed with flag " + std::to_string(flag));
}

template <class Handle>
Handle created(Handle handle, const char* call) {
  if (!handle) throw std::runtime_error(std::string(call) + " returned null");
  return handle;
}

double* data(N_Vector v) { return N_VGetArrayPointer(v); }

/// The CSV rows: each line built in a buffer, written and flushed at once (as qdot's CsvWriter).
class CsvRows {
 public:
  explicit CsvRows(const std::string& path) : file_(path.empty() ? stdout : std::fopen(path.c_str(), "wb")) {
    if (!file_) throw std::runtime_error("cannot open " + path);
  }
  ~CsvRows() {
    if (file_ != stdout) std::fclose(file_);
  }
  CsvRows(const CsvRows&) = delete;
  CsvRows& operator=(const CsvRows&) = delete;

  void header(const std::vector<std::string>& names, const std::vector<uint32_t>& columns) {
    line_ = "time";
    for (uint32_t c : columns) line_ += "," + names[c];
    write();
  }

  // Kept out of line so that profiles (bench/profile_solve.py) can attribute the writing.
  [[gnu::noinline]] void row(double t, const double* y, const std::vector<uint32_t>& columns) {
    number(t);
    for (uint32_t c : columns) {
      line_ += ',';
      number(y[c]);
    }
    write();
  }

 private:
  void number(double v) {
    char buffer[32];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    line_.append(buffer, end);
  }
  void write() {
    line_ += '\n';
    if (std::fwrite(line_.data(), 1, line_.size(), file_) != line_.size() || std::fflush(file_) != 0)
      throw std::runtime_error("writing the results failed");
    line_.clear();
  }

  std::FILE* file_;
  std::string line_;
};

/// The SUNDIALS objects of one run and the two callbacks.
class Integrator {
 public:
  Integrator(const ReferenceModel& model, const RunSettings& settings);
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  /// qdot's IdaSession::initialize: IDACalcIC only when the start does not satisfy F = 0.
  void makeConsistent(double tout1);
  void setStopTime(double tstop) { check(IDASetStopTime(ida_, tstop), "IDASetStopTime"); }
  double advanceTo(double tout);
  const double* y() const { return data(y_); }
  void readCounters(RunResult& r) const;

 private:
  void applyTolerances();
  bool diagonalRates(std::vector<double>& F, double tout1);
  rt::TimeScale timeScale() const;
  void denseJacobian(double cj, const double* y, const double* yp, double* J) const;
  void attachLinearSolver();
  static int residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector F, void* self);
  static int jacobian(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector F, SUNMatrix J, void* self,
                      N_Vector, N_Vector, N_Vector);

  const ReferenceModel& model_;
  RunSettings settings_;
  sunindextype n_;
  SUNContext context_ = nullptr;
  void* ida_ = nullptr;
  N_Vector y_ = nullptr, yp_ = nullptr, id_ = nullptr, atol_ = nullptr;
  SUNMatrix matrix_ = nullptr;
  SUNLinearSolver solver_ = nullptr;
  rt::ToleranceVector tolerances_;
  std::optional<rt::TimeScale> timeScale_;  ///< computed once, from the start values, as qdot does
  std::optional<rt::BandOrdering> bandOrdering_;    ///< qdot's KLU ordering rule (ida/KluOrdering.h)
  bool calcIC_ = false, diagonal_ = false;
 public:
  std::optional<Clock::time_point> firstStepDone;  ///< seen at the first residual after step 1
};

Integrator::Integrator(const ReferenceModel& model, const RunSettings& settings)
    : model_(model), settings_(settings), n_(model.size()) {
  check(SUNContext_Create(nullptr, &context_), "SUNContext_Create");
  y_ = created(N_VNew_Serial(n_, context_), "N_VNew_Serial");
  N_VEnableFusedOps_Serial(y_, SUNTRUE);  // as qdot's runtime: IDA's clones do linear combinations in one pass
  yp_ = created(N_VNew_Serial(n_, context_), "N_VNew_Serial");
  id_ = created(N_VNew_Serial(n_, context_), "N_VNew_Serial");
  atol_ = created(N_VNew_Serial(n_, context_), "N_VNew_Serial");
  // The same vector operations as qdot's runtime (ida/SerialVectorOps.h: Debian's SUNDIALS is built
  // without optimization), so that the comparison measures qdot, not how the library was built;
  // QDOT_SUNDIALS_VECTOR_OPS=1 runs both on SUNDIALS' own.
  for (N_Vector v : {y_, yp_, id_, atol_}) rt::useOptimizedSerialOps(v);
  std::vector<double> y0 = model.startValues();
  std::copy(y0.begin(), y0.end(), data(y_));
  N_VConst(0.0, yp_);
  N_VConst(1.0, id_);  // every unknown of these models is differential
  ida_ = created(IDACreate(context_), "IDACreate");
  check(IDASetUserData(ida_, this), "IDASetUserData");
  check(IDAInit(ida_, &Integrator::residual, settings.start, y_, yp_), "IDAInit");
  applyTolerances();
  check(IDASetId(ida_, id_), "IDASetId");
  check(IDASetMaxNumSteps(ida_, settings.maxStepsPerOutput), "IDASetMaxNumSteps");
  attachLinearSolver();
}

Integrator::~Integrator() {
  if (ida_) IDAFree(&ida_);
  if (solver_) SUNLinSolFree(solver_);
  if (matrix_) SUNMatDestroy(matrix_);
  for (N_Vector v : {y_, yp_, id_, atol_})
    if (v) N_VDestroy(v);
  if (context_) SUNContext_Free(&context_);
}

// qdot's time scale for the velocities' automatic scales (runtime/arkode/StartLinearization.h), from
// this program's own residual and Jacobian at the start values: the same rule, not qdot's numbers.
rt::TimeScale Integrator::timeScale() const {
  if (settings_.atol || n_ > static_cast<sunindextype>(rt::kLargestWithFrequency)) return {};  // as qdot's
  std::vector<std::string> names = model_.variableNames();
  std::vector<const char*> pointers;
  for (const std::string& name : names) pointers.push_back(name.c_str());
  rt::TimeScale scale{0.0, rt::velocityPositions(pointers)};
  auto residual = [&](const double* y, const double* yp, double* F) { model_.residual(y, yp, F); };
  auto jacobian = [&](double cj, const double* y, const double* yp, double* J) { denseJacobian(cj, y, yp, J); };
  std::vector<double> y0 = model_.startValues();
  scale.frequency = rt::lowestStartFrequency(y0, residual, jacobian).value_or(0.0);
  return scale;
}

// J = dF/dy + cj dF/dy' column-major n × n into a zeroed J, from the dense or the sparse form.
void Integrator::denseJacobian(double cj, const double* y, const double* yp, double* J) const {
  if (!model_.sparse()) return model_.denseJacobian(cj, y, yp, J);
  std::vector<int64_t> starts(n_ + 1), rows(model_.jacobianNonzeros());
  std::vector<double> values(model_.jacobianNonzeros());
  model_.sparseJacobian(cj, y, yp, starts.data(), rows.data(), values.data());
  for (sunindextype c = 0; c < n_; ++c)
    for (int64_t k = starts[c]; k < starts[c + 1]; ++k) J[c * n_ + rows[k]] = values[k];
}

void Integrator::applyTolerances() {
  std::vector<double> nominal(n_, 0.0);  // the models give no nominal values
  std::vector<int32_t> differential(n_, 1);
  if (!timeScale_) timeScale_ = timeScale();
  tolerances_ = rt::buildTolerances(settings_.rtol, settings_.atol, {data(y_), static_cast<std::size_t>(n_)}, nominal,
                                    differential, {}, *timeScale_);
  std::copy(tolerances_.atol.begin(), tolerances_.atol.end(), data(atol_));
  // qdot's solver rtol (calibrated without --atol, runtime/ida/Tolerances.h): the same IDA settings
  check(IDASVtolerances(ida_, tolerances_.solverRtol, atol_), "IDASVtolerances");
}

void Integrator::attachLinearSolver() {
  if (model_.sparse()) {
    matrix_ = created(SUNSparseMatrix(n_, n_, model_.jacobianNonzeros(), CSC_MAT, context_), "SUNSparseMatrix");
    solver_ = created(SUNLinSol_KLU(y_, matrix_, context_), "SUNLinSol_KLU");
    // qdot's rule: reverse Cuthill–McKee without BTF when it leaves a narrow band, else COLAMD.
    std::vector<int64_t> starts(n_ + 1), rows(model_.jacobianNonzeros());
    {
      std::vector<double> values(rows.size());  // only the pattern is used: freed before the ordering
      model_.sparseJacobian(1.0, data(y_), data(yp_), starts.data(), rows.data(), values.data());
    }
    bandOrdering_ = rt::chooseBandOrdering({starts, rows});
    if (bandOrdering_) rt::useBandOrdering(*SUNLinSol_KLUGetCommon(solver_), *bandOrdering_);
  } else {
    matrix_ = created(SUNDenseMatrix(n_, n_, context_), "SUNDenseMatrix");
    solver_ = created(SUNLinSol_Dense(y_, matrix_, context_), "SUNLinSol_Dense");
  }
  check(IDASetLinearSolver(ida_, solver_, matrix_), "IDASetLinearSolver");
  check(IDASetJacFn(ida_, &Integrator::jacobian), "IDASetJacFn");
}

int Integrator::residual(sunrealtype, N_Vector y, N_Vector yp, N_Vector F, void* self) {
  auto* integrator = static_cast<Integrator*>(self);
  long steps = 0;
  if (!integrator->firstStepDone && IDAGetNumSteps(integrator->ida_, &steps) == IDA_SUCCESS && steps > 0)
    integrator->firstStepDone = Clock::now();
  integrator->model_.residual(data(y), data(yp), data(F));
  return 0;
}

int Integrator::jacobian(sunrealtype, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J, void* self,
                         N_Vector, N_Vector, N_Vector) {
  // IDA has zeroed J (for a sparse matrix its pattern too): the model writes entries and pattern.
  const ReferenceModel& model = static_cast<Integrator*>(self)->model_;
  if (model.sparse()) {
    model.sparseJacobian(cj, data(y), data(yp), SUNSparseMatrix_IndexPointers(J), SUNSparseMatrix_IndexValues(J),
                         SUNSparseMatrix_Data(J));
  } else {
    model.denseJacobian(cj, data(y), data(yp), SUNDenseMatrix_Data(J));
  }
  return 0;
}

void Integrator::makeConsistent(double tout1) {
  std::vector<double> F(n_);
  model_.residual(data(y_), data(yp_), F.data());
  if (std::all_of(F.begin(), F.end(), [](double f) { return std::abs(f) <= 1e-14; })) return;
  calcIC_ = true;
  if ((diagonal_ = diagonalRates(F, tout1))) return;
  check(IDACalcIC(ida_, IDA_YA_YDP_INIT, tout1), "IDACalcIC");
  check(IDAGetConsistentIC(ida_, y_, yp_), "IDAGetConsistentIC");
  check(IDAReInit(ida_, settings_.start, y_, yp_), "IDAReInit");
  applyTolerances();
}

// qdot's IdaSession: y' by one division when dF/dy' is diagonal up to its rows' order (every
// unknown of these models is differential), accepted by IDACalcIC's test (ida/DiagonalRates.h).
bool Integrator::diagonalRates(std::vector<double>& F, double tout1) {
  if (!model_.sparse()) return false;
  std::vector<int64_t> starts(n_ + 1), rows(model_.jacobianNonzeros());
  std::vector<double> at0(rows.size()), at1(rows.size());
  model_.sparseJacobian(0.0, data(y_), data(yp_), starts.data(), rows.data(), at0.data());
  model_.sparseJacobian(1.0, data(y_), data(yp_), starts.data(), rows.data(), at1.data());
  auto n = static_cast<std::size_t>(n_);
  std::optional<rt::DiagonalRates> rates = rt::diagonalRates<int64_t>(starts, rows, at0, at1);
  if (!rates) return false;
  std::vector<double> given(data(yp_), data(yp_) + n);
  rt::stepRates(*rates, F, {data(yp_), n});
  model_.residual(data(y_), data(yp_), F.data());
  if (!rt::ratesConverged(*rates, F, {data(y_), n}, tolerances_.solverRtol, tolerances_.atol, tout1 - settings_.start)) {
    std::copy(given.begin(), given.end(), data(yp_));
    return false;
  }
  check(IDAReInit(ida_, settings_.start, y_, yp_), "IDAReInit");
  applyTolerances();
  return true;
}

double Integrator::advanceTo(double tout) {
  sunrealtype reached = 0;
  check(IDASolve(ida_, tout, &reached, y_, yp_, IDA_NORMAL), "IDASolve");
  return reached;
}

void Integrator::readCounters(RunResult& r) const {
  IDAGetNumSteps(ida_, &r.steps);
  IDAGetNumResEvals(ida_, &r.residualEvaluations);
  IDAGetNumJacEvals(ida_, &r.jacobianEvaluations);
  IDAGetNumNonlinSolvIters(ida_, &r.nonlinearIterations);
  IDAGetNumErrTestFails(ida_, &r.errorTestFailures);
  IDAGetNumNonlinSolvConvFails(ida_, &r.convergenceFailures);
  IDAGetLastStep(ida_, &r.lastStep);
  IDAGetLastOrder(ida_, &r.lastOrder);
  r.computedInitialValues = calcIC_;
  r.diagonalRates = diagonal_;
  r.sparse = model_.sparse();
  if (bandOrdering_) r.bandwidth = bandOrdering_->bandwidth;
  r.tolerances = tolerances_.summary;
}

}  // namespace

std::vector<double> outputTimes(double start, double stop, double interval) {
  std::vector<double> times;
  double last = stop - 1e-9 * interval;
  for (std::size_t k = 0; start + static_cast<double>(k) * interval < last; ++k)
    times.push_back(start + static_cast<double>(k) * interval);
  times.push_back(stop);
  return times;
}

RunResult simulateReference(const ReferenceModel& model, const RunSettings& settings) {
  RunResult result;
  std::vector<uint32_t> columns = settings.columns;
  if (columns.empty())
    for (uint32_t i = 0; i < model.size(); ++i) columns.push_back(i);
  std::vector<double> grid = outputTimes(settings.start, settings.stop, settings.interval);
  CsvRows csv(settings.outputPath);
  csv.header(model.variableNames(), columns);

  Clock::time_point clock = Clock::now();
  Integrator ida(model, settings);
  ida.makeConsistent(grid[1]);  // the grid always has the start and the stop
  ida.setStopTime(settings.stop);
  result.setupSeconds = secondsSince(clock);

  clock = Clock::now();
  for (std::size_t k = 0; k < grid.size(); ++k) {
    double t = k == 0 ? settings.start : ida.advanceTo(grid[k]);
    csv.row(t, ida.y(), columns);
    ++result.rows;
  }
  result.solveSeconds = secondsSince(clock);
  result.firstStepSeconds =
      ida.firstStepDone ? std::chrono::duration<double>(*ida.firstStepDone - clock).count() : result.solveSeconds;
  if (ida.firstStepDone) result.firstStepSinceProcessStart = rt::secondsSinceProcessStart(*ida.firstStepDone);
  ida.readCounters(result);
  return result;
}

std::string formatStats(const RunResult& r) {
  char text[2048];
  const rt::ToleranceSummary& t = r.tolerances;
  std::string solver = !r.sparse     ? "dense"
                       : r.bandwidth ? "klu (band ordering, bandwidth " + std::to_string(*r.bandwidth) + ")"
                                     : "klu";
  char started[96] = "";
  if (r.firstStepSinceProcessStart)
    std::snprintf(started, sizeof started, ", done %.3f s after the process started", *r.firstStepSinceProcessStart);
  std::string sinceStart = started;
  std::snprintf(text, sizeof text,
                "statistics:\n"
                "  steps                  %ld (last step %.3g, order %d)\n"
                "  residual evaluations   %ld\n"
                "  Jacobian evaluations   %ld\n"
                "  nonlinear iterations   %ld\n"
                "  error-test failures    %ld\n"
                "  convergence failures   %ld\n"
                "  linear solver          %s\n"
                "  initial values         %s\n"
                "  tolerances             rtol %g, atol min %.3g, median %.3g, max %.3g\n"
                "  rows written           %zu\n"
                "  wall time              setup %.6f s, solve %.6f s (first step %.6f s%s)\n",
                r.steps, r.lastStep, r.lastOrder, r.residualEvaluations, r.jacobianEvaluations, r.nonlinearIterations,
                r.errorTestFailures, r.convergenceFailures, solver.c_str(),
                !r.computedInitialValues ? "consistent as given"
                : r.diagonalRates        ? "made consistent directly (dF/dy' diagonal: y' -= F/diag, checked)"
                                         : "made consistent by IDACalcIC",
                t.rtol, t.atolMin, t.atolMedian, t.atolMax, r.rows, r.setupSeconds, r.solveSeconds, r.firstStepSeconds,
                sinceStart.c_str());
  return text;
}

}  // namespace qdot::bench
