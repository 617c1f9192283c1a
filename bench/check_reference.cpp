// check_reference: verifies that the hand-written reference models (bench/reference/) are the
// DAE qdot derives, before their timings are compared. For each model and size it compiles the
// .qd file with qdot (DAE → kernels → bytecode → VM) and checks names, differential flags, start
// values and parameters, then evaluates both residuals and Jacobians at random states (random y,
// y', cj) and compares them entry by entry, the CSC pattern of the chain exactly.
//   check_reference   (from the repository root, or set QDOT_SOURCE_DIR); exit 1 on a mismatch
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bytecode/Emitter.h"
#include "driver/Pipeline.h"
#include "kernel/Kernel.h"
#include "reference/NLinkPendulum.h"
#include "reference/SpringChain.h"
#include "vm/Vm.h"

namespace {

using namespace qdot;
using ModelPtr = std::unique_ptr<QdotModel, void (*)(QdotModel*)>;

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path + " (run from the repository root)");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// qdot's VM model of `file` with `parameter Integer n` set to n.
ModelPtr compileWithSize(const std::string& file, int n) {
  std::string text = std::regex_replace(readFile(file), std::regex("parameter Integer n = [0-9]+"),
                                        "parameter Integer n = " + std::to_string(n));
  driver::Compilation c;
  if (!driver::compileSource(c, file, text, "", driver::Stage::Dae)) {
    c.diags.render(std::cerr, c.sources);
    throw std::runtime_error("qdot could not compile " + file);
  }
  kernel::KernelModule kernels = kernel::buildKernels(*c.dae, c.ctx, c.diags);
  if (c.diags.hasErrors()) {
    c.diags.render(std::cerr, c.sources);
    throw std::runtime_error("qdot could not compile " + file);
  }
  bc::Module module = bytecode::emitBytecode(kernels, c.sources);
  std::string error;
  QdotModel* model = vm::createModel(module, error);
  if (!model) throw std::runtime_error(error);
  return ModelPtr(model, model->destroy);
}

/// Largest |a_i − b_i| / (1 + |b_i|).
double largestDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]) / (1 + std::abs(b[i])));
  return worst;
}

/// qdot's CSC Jacobian as a dense column-major matrix.
std::vector<double> qdotJacobian(const QdotModel& q, const std::vector<double>& p, double cj,
                                 const std::vector<double>& y, const std::vector<double>& yp) {
  uint32_t N = q.nVariables;
  std::vector<double> values(q.jacobianNonzeros), dense(std::size_t(N) * N, 0.0);
  if (q.jacobian(&q, 0, y.data(), yp.data(), p.data(), cj, values.data()) != 0)
    throw std::runtime_error("qdot's Jacobian failed");
  for (uint32_t col = 0; col < N; ++col)
    for (int32_t k = q.jacobianColumnStarts[col]; k < q.jacobianColumnStarts[col + 1]; ++k)
      dense[std::size_t(col) * N + q.jacobianRowIndices[k]] = values[k];
  return dense;
}

/// The reference Jacobian as a dense column-major matrix; for a sparse model also whether its
/// CSC pattern is qdot's.
std::vector<double> referenceJacobian(const bench::ReferenceModel& r, const QdotModel& q, double cj,
                                      const std::vector<double>& y, const std::vector<double>& yp, bool& samePattern) {
  uint32_t N = r.size();
  std::vector<double> dense(std::size_t(N) * N, 0.0);
  samePattern = true;
  if (!r.sparse()) {
    r.denseJacobian(cj, y.data(), yp.data(), dense.data());
    return dense;
  }
  std::vector<int64_t> starts(N + 1), rows(r.jacobianNonzeros());
  std::vector<double> values(r.jacobianNonzeros());
  r.sparseJacobian(cj, y.data(), yp.data(), starts.data(), rows.data(), values.data());
  samePattern = r.jacobianNonzeros() == q.jacobianNonzeros &&
                std::equal(starts.begin(), starts.end(), q.jacobianColumnStarts) &&
                std::equal(rows.begin(), rows.end(), q.jacobianRowIndices);
  for (uint32_t col = 0; col < N; ++col)
    for (int64_t k = starts[col]; k < starts[col + 1]; ++k) dense[std::size_t(col) * N + rows[k]] = values[k];
  return dense;
}

/// Everything but F and J: sizes, names, differential flags, start values (y'0 = 0), no nominals.
bool sameInterface(const bench::ReferenceModel& r, const QdotModel& q, const std::vector<double>& p) {
  uint32_t N = r.size();
  if (q.nVariables != N) return false;
  std::vector<std::string> names = r.variableNames();
  std::vector<double> y0(N), yp0(N), nominal(N);
  if (q.initialValues(&q, p.data(), 0, y0.data(), yp0.data(), nominal.data()) != 0) return false;
  bool ok = y0 == r.startValues();
  for (uint32_t i = 0; i < N; ++i)
    ok = ok && names[i] == q.variableNames[i] && q.isDifferential[i] == 1 && yp0[i] == 0 && nominal[i] == 0;
  return ok;
}

/// Compares one model at `states` random points; prints a table row; returns whether it agrees.
bool compare(const char* title, const bench::ReferenceModel& r, const QdotModel& q, int n, int states) {
  std::vector<double> p(q.nParameters);
  std::vector<double> given(q.nParameters, 0.0);
  std::vector<uint8_t> overridden(q.nParameters, 0);
  q.parameters(&q, given.data(), overridden.data(), p.data());
  bool interface = sameInterface(r, q, p);
  std::mt19937_64 random(12345);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  double worstF = 0, worstJ = 0;
  bool pattern = true;
  uint32_t N = r.size();
  for (int s = 0; s < states; ++s) {
    std::vector<double> y(N), yp(N), Fq(N), Fr(N);
    for (uint32_t i = 0; i < N; ++i) y[i] = uniform(random), yp[i] = uniform(random);
    double cj = std::exp(uniform(random) * 5);  // 1/h for steps between ~1e-4 and 1e4
    if (q.residual(&q, 0, y.data(), yp.data(), p.data(), Fq.data()) != 0)
      throw std::runtime_error("qdot's residual failed");
    r.residual(y.data(), yp.data(), Fr.data());
    worstF = std::max(worstF, largestDifference(Fr, Fq));
    bool samePattern = true;
    std::vector<double> Jr = referenceJacobian(r, q, cj, y, yp, samePattern);
    pattern = pattern && samePattern;
    worstJ = std::max(worstJ, largestDifference(Jr, qdotJacobian(q, p, cj, y, yp)));
  }
  bool ok = interface && pattern && worstF < 1e-12 && worstJ < 1e-12;
  std::printf("| %s | %d | %u | %s | %.1e | %.1e | %s | %s |\n", title, n, N, interface ? "same" : "DIFFERENT", worstF,
              worstJ, r.sparse() ? (pattern ? "same" : "DIFFERENT") : "dense", ok ? "yes" : "**NO**");
  return ok;
}

}  // namespace

int main() {
  const char* root = std::getenv("QDOT_SOURCE_DIR");
  std::string dir = root ? std::string(root) + "/" : "";
  constexpr int kStates = 20;
  bool ok = true;
  try {
    std::printf(
        "| model | n | unknowns | names, flags, start values | max rel. diff F | max rel. diff J | CSC pattern | "
        "agrees |\n");
    std::printf("|---|---:|---:|---|---:|---:|---|---|\n");
    for (int n : {2, 3, 8}) {
      ModelPtr q = compileWithSize(dir + "examples/pendulum/nlink.qd", n);
      ok = compare("N-link pendulum", bench::NLinkPendulum(n), *q, n, kStates) && ok;
    }
    for (int n : {2, 3, 10, 1000}) {
      ModelPtr q = compileWithSize(dir + "examples/vibration/spring_chain.qd", n);
      ok = compare("spring chain", bench::SpringChain(n), *q, n, n > 100 ? 3 : kStates) && ok;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "check_reference: %s\n", e.what());
    return 1;
  }
  return ok ? 0 : 1;
}
