// Failures: a model whose residual fails after t = 0.5 (the run stops there with the model's
// message, the CSV keeps exactly the earlier rows), a singular model, a bad table, and the exit
// codes of runModel.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "HandModels.h"
#include "ida/IdaSession.h"
#include "output/CsvWriter.h"
#include "sim/Run.h"
#include "sim/Simulation.h"

namespace qdot::rt::test {
namespace {

constexpr const char* kDomainError = "sqrt of a negative number in equation 2 (failing.qd:7)";

/// x' = 1 (so x = t) whose residual fails with NaN and a message for t >= 0.5.
HandModel failingAfterHalf() {
  HandModel m;
  m.name = "failing";
  m.variables = {"x"};
  m.differential = {1};
  m.start = {0.0};
  m.entries = {{0, 0}};
  m.residual = [](double t, const double*, const double* yp, const double*, double* F) { return 0; };
  m.jacobian = [](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj;
    return 0;
  };
  return m;
}

std::vector<std::string> lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

std::filesystem::path tempPath(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("qdot_runtime_" + name + "_" + std::to_string(::getpid()) + ".csv");
}

// Reference: x = t until the model fails; rows at 0, 0.125, 0.25, 0.375 only, since the output at
// 0.5 needs a step that ends at or beyond 0.5.
TEST(ModelFailure, StopsWithTheModelMessageAndKeepsEarlierRows) {
  HandModel model = failingAfterHalf();
  model.residual = [&model](double t, const double*, const double* yp, const double*, double* F) {
    if (t >= 0.5) {
      F[0] = std::numeric_limits<double>::quiet_NaN();
      model.lastError = kDomainError;
      return 1;
    }
    F[0] = yp[0] - 1;
    return 0;
  };
  auto path = tempPath("failure");
  SimulationSettings s;
  s.stop = 1;
  s.interval = 0.125;
  SimulationResult r;
  {
    auto writer = CsvWriter::openFile(path.string());
    r = simulate(model.abi(), s, *writer);
  }
  EXPECT_FALSE(r.success);
  // The reported time is where IDA stopped: the last point where the solution is known, just
  // before the model starts failing at t = 0.5.
  EXPECT_NEAR(r.failureTime, 0.5, 1e-9);
  EXPECT_NE(r.message.find(kDomainError), std::string::npos) << r.message;
  EXPECT_EQ(r.rows, 4u);
  std::vector<std::string> csv = lines(path);
  EXPECT_EQ(csv, (std::vector<std::string>{"time,x", "0,0", "0.125,0.125", "0.25,0.25", "0.375,0.375"}));
  std::printf("  failure reported at t = %.17g: %s\n", r.failureTime, r.message.c_str());
  std::filesystem::remove(path);
}

// A residual that produces NaN without saying so is caught by the runtime itself.
TEST(ModelFailure, SilentNanIsReportedWithTheEquationIndex) {
  HandModel model = failingAfterHalf();
  model.residual = [](double t, const double*, const double* yp, const double*, double* F) {
    F[0] = t >= 0.5 ? std::numeric_limits<double>::quiet_NaN() : yp[0] - 1;
    return 0;
  };
  SimulationSettings s;
  s.interval = 0.125;
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), s, sink);
  EXPECT_FALSE(r.success);
  EXPECT_NEAR(r.failureTime, 0.5, 1e-9);  // where IDA stopped, just before the failures start
  EXPECT_NE(r.message.find("residual F[0] evaluated to nan"), std::string::npos) << r.message;
  EXPECT_EQ(sink.rows.size(), 4u);
  EXPECT_TRUE(sink.finished);
}

// --max-steps: the run stops with an error naming the limit; the rows before stay written.
TEST(ModelFailure, MaxStepsStopsTheRunAndKeepsTheRows) {
  HandModel model = failingAfterHalf();
  model.residual = [](double t, const double*, const double* yp, const double*, double* F) {
    F[0] = yp[0] - std::cos(50 * t);  // x = sin(50 t)/50: steps all the way
    return 0;
  };
  SimulationSettings s;
  s.interval = 0.05;
  s.maxSteps = 200;
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), s, sink);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("reached --max-steps 200"), std::string::npos) << r.message;
  EXPECT_GE(r.stats.steps, 200);
  EXPECT_LE(r.stats.steps, 400);  // checked at output times; IDA's own limit per interval is 200 too
  EXPECT_EQ(sink.rows.size(), r.rows);
  EXPECT_GT(sink.rows.size(), 1u) << r.message << " steps " << r.stats.steps;
  EXPECT_LT(r.failureTime, 1.0);
}

// A failure at the start time is reported before IDA runs, at t0.
TEST(ModelFailure, FailureAtTheStartIsReportedAtTheStartTime) {
  HandModel model = failingAfterHalf();
  model.residual = [&model](double, const double*, const double*, const double*, double*) {
    model.lastError = kDomainError;
    return 1;
  };
  SimulationSettings s;
  s.start = 2;
  s.stop = 3;
  s.interval = 0.5;
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), s, sink);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.failureTime, 2.0);
  EXPECT_NE(r.message.find(kDomainError), std::string::npos) << r.message;
  EXPECT_EQ(sink.names, (std::vector<std::string>{"x"}));  // the header is there
  EXPECT_TRUE(sink.rows.empty());
}

// y1' = y2, 0 = 0 (no equation determines the algebraic y2): the Newton matrix is singular, and
// the message names y2.
TEST(SolverFailure, SingularSystemGivesAReadableMessage) {
  HandModel m;
  m.variables = {"y1", "y2"};
  m.differential = {1, 0};
  m.start = {1.0, 0.0};
  m.entries = {{0, 0}, {0, 1}};
  m.residual = [](double, const double* y, const double* yp, const double*, double* F) {
    F[0] = yp[0] - y[1];
    F[1] = 0;
    return 0;
  };
  m.jacobian = [](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj;
    J(0, 1) = -1;
    return 0;
  };
  for (auto kind : {LinearSolverKind::Dense, LinearSolverKind::Klu}) {
    SimulationSettings s;
    s.linearSolver = kind;
    MemorySink sink;
    SimulationResult r = simulate(m.abi(), s, sink);
    EXPECT_FALSE(r.success);
    EXPECT_EQ(r.failureTime, 0.0);
    EXPECT_NE(r.message.find("IDACalcIC failed"), std::string::npos) << r.message;
    EXPECT_NE(r.message.find("the Newton matrix is singular at the column of y2"), std::string::npos) << r.message;
    std::printf("  singular model (%s): %s\n", std::string(linearSolverName(kind)).c_str(), r.message.c_str());
  }
}

TEST(ModelTable, WrongAbiVersionAndBadPatternAreRefused) {
  HandModel old = oscillator(1.0);
  old.abiVersion = QDOT_MODEL_ABI_VERSION + 1;
  try {
    IdaSession session(old.abi(), {1.0}, {});
    FAIL() << "accepted a model of another ABI version";
  } catch (const IdaError& e) {
    EXPECT_NE(std::string(e.what()).find("ABI version"), std::string::npos) << e.what();
  }
  HandModel bad = oscillator(1.0);
  QdotModel table = bad.abi();
  int32_t rows[] = {1, 0, 0, 1};  // column 0 descending
  table.jacobianRowIndices = rows;
  EXPECT_THROW(IdaSession(table, {1.0}, {}), IdaError);
}

TEST(ModelTable, DenseSolverIsRefusedForHugeSystems) {
  HandModel chain = heatChain(static_cast<int>(kDenseMaxForced) + 1);
  SessionOptions o;
  o.linearSolver = LinearSolverKind::Dense;
  try {
    IdaSession session(chain.abi(), {}, o);
    FAIL() << "built a dense matrix of more than 2 GiB";
  } catch (const IdaError& e) {
    EXPECT_NE(std::string(e.what()).find("--linear-solver klu"), std::string::npos) << e.what();
  }
}

TEST(RunModel, ExitCodesForSuccessFailureAndUsage) {
  HandModel ok = oscillator(1.0);
  RunOptions options;
  options.stop = 1;
  options.interval = 0.5;
  options.stats = true;
  std::ostringstream csv, log;
  EXPECT_EQ(runModel(ok.abi(), options, {}, csv, log), ExitCode::Success) << log.str();
  EXPECT_EQ(csv.str().substr(0, csv.str().find('\n')), "time,x,v,a");
  EXPECT_NE(log.str().find("residual evaluations"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("linear solver          dense (chosen automatically)"), std::string::npos) << log.str();

  options.rtol = -1;
  std::ostringstream csv2, log2;
  EXPECT_EQ(runModel(ok.abi(), options, {}, csv2, log2), ExitCode::Usage);
  EXPECT_NE(log2.str().find("--rtol must be positive"), std::string::npos) << log2.str();
  EXPECT_TRUE(csv2.str().empty());

  HandModel failing = failingAfterHalf();
  failing.residual = [&failing](double t, const double*, const double* yp, const double*, double* F) {
    failing.lastError = kDomainError;
    F[0] = yp[0] - 1;
    return t >= 0.5 ? 1 : 0;
  };
  RunOptions o2;
  o2.interval = 0.25;
  std::ostringstream csv3, log3;
  EXPECT_EQ(runModel(failing.abi(), o2, {}, csv3, log3), ExitCode::SimulationFailed);
  EXPECT_NE(log3.str().find("error: the simulation failed at t = 0.5"), std::string::npos) << log3.str();
  EXPECT_NE(log3.str().find("note: the 2 rows up to t = 0.25 were written"), std::string::npos) << log3.str();
}

}  // namespace
}  // namespace qdot::rt::test
