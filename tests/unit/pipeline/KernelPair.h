// Test helper for comparing a model's looped and scalar kernels (issue 15): the model compiled to
// kernels with or without templates, and its residual, Jacobian and invariants on the reference interpreter
// at a reproducible state per trial.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "kernel/Kernel.h"

namespace qdot::test {

/// `text` compiled to kernels, keeping its repeated structure as loops or not (and solving explicit
/// algebraic unknowns out of the system, as `qdot run` does, or not).
struct CompiledKernels {
  driver::Compilation c;
  bool ok = false;
  CompiledKernels(const std::string& text, bool loops, bool eliminateAlgebraics = false) {
    c.options.keepLoops = loops;
    c.options.eliminateAlgebraics = eliminateAlgebraics;
    ok = driver::compileSource(c, "model.qd", text, driver::Stage::Kernel);
  }
  const kernel::KernelModule& kernels() const { return *c.kernels; }
  std::string diagnostics() const {
    std::ostringstream os;
    c.diags.render(os, c.sources);
    return os.str() + c.internalError;
  }
};

/// How many instructions of `p` are `op`.
inline size_t opCount(const kernel::Program& p, kernel::Op op);

/// Compiled with templates allowed, the model is compiled exactly as without: the same kernels,
/// byte for byte, and no loop in the residual.
inline void expectScalarFallback(const std::string& text) {
  CompiledKernels scalar(text, false), looped(text, true);
  ASSERT_TRUE(scalar.ok && looped.ok) << scalar.diagnostics() << looped.diagnostics();
  EXPECT_FALSE(looped.c.dae->templated());
  std::ostringstream a, b;
  kernel::printKernels(a, scalar.kernels());
  kernel::printKernels(b, looped.kernels());
  EXPECT_EQ(a.str(), b.str());
  EXPECT_EQ(opCount(looped.kernels().program(ModelProgram::Residual), kernel::Op::LoopBegin), 0u);
}

/// How many instructions of `p` are `op`.
inline size_t opCount(const kernel::Program& p, kernel::Op op) {
  size_t n = 0;
  for (const auto& i : p.code) n += i.op == op;
  return n;
}

inline size_t loopCount(const kernel::Program& p) { return opCount(p, kernel::Op::LoopBegin); }

/// Parameter values given at run time (as `qdot run -p name=value` gives them), by name.
using GivenParameters = std::vector<std::pair<std::string, double>>;

/// The residual F, the Jacobian's values J (CSC order), the invariants and the initial values
/// (y0, y'0, nominal) of a kernel module.
struct KernelValues {
  std::vector<double> F, J, invariants, start, outputs;
};

/// F, J and the invariants at trial state `trial` (y, y', cj and t fixed by it), with the default parameter values
/// except those `given`.
inline KernelValues evaluateAt(const kernel::KernelModule& k, int trial, const GivenParameters& givenValues = {}) {
  size_t n = k.variableCount(), nnz = k.description->jacobianRowIndices.size();
  const std::vector<std::string>& names = k.description->parameterNames;
  std::vector<double> p(names.size()), given(p.size(), 0.0);
  std::vector<uint8_t> overridden(p.size(), 0);
  for (const auto& [name, value] : givenValues) {
    auto at = std::find(names.begin(), names.end(), name);
    EXPECT_NE(at, names.end()) << "no parameter " << name;
    if (at == names.end()) continue;
    given[at - names.begin()] = value, overridden[at - names.begin()] = 1;
  }
  ModelCall call{.given = given.data(), .overridden = overridden.data()};
  kernel::interpret(k.program(ModelProgram::Parameters), call, p);
  std::vector<double> y(n), yp(n);
  for (size_t j = 0; j < n; ++j) {
    y[j] = 0.1 * std::sin(1.3 * j + trial);
    yp[j] = 0.2 * std::cos(0.7 * j + 2 * trial);
  }
  ModelCall in{.t = 0.3, .cj = 17.0 + trial, .y = y.data(), .yp = yp.data(), .p = p.data()};
  KernelValues v{std::vector<double>(n), std::vector<double>(nnz), std::vector<double>(k.description->invariantNames.size())};
  kernel::interpret(k.program(ModelProgram::Residual), in, v.F);
  kernel::interpret(k.program(ModelProgram::Jacobian), in, v.J);
  kernel::interpret(k.program(ModelProgram::Invariants), in, v.invariants);
  v.outputs.resize(k.description->outputNames.size());
  kernel::interpret(k.program(ModelProgram::Outputs), in, v.outputs);
  v.start.resize(3 * n);
  kernel::interpret(k.program(ModelProgram::InitialValues), ModelCall{.t = 0.0, .p = p.data()}, v.start);
  return v;
}

}  // namespace qdot::test
