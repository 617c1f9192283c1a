// Looped and scalar kernels compute the same model (issue 15): a model compiled with its repeated
// structure kept as templates (CompileOptions::keepLoops: loops in the residual and Jacobian) and
// the same model compiled element by element give the same residual and the same Jacobian (same
// CSC pattern, values equal to rounding) at random states, on the reference interpreter.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "unit/pipeline/KernelPair.h"

namespace qdot {
namespace {

using test::loopCount;

struct Compiled : test::CompiledKernels {
  Compiled(const std::string& text, bool loops) : CompiledKernels(text, loops) { EXPECT_TRUE(ok) << diagnostics(); }
};

// Residual and Jacobian of both at a few random states; returns the loops the templated one has.
size_t expectSameKernels(const std::string& text) {
  Compiled scalar(text, false), looped(text, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(a.description.variableNames, b.description.variableNames);
  EXPECT_EQ(a.description.jacobianColumnStarts, b.description.jacobianColumnStarts);
  EXPECT_EQ(a.description.jacobianRowIndices, b.description.jacobianRowIndices);
  size_t n = a.variableCount(), nnz = a.description.jacobianRowIndices.size();
  for (int trial = 0; trial < 3; ++trial) {
    test::KernelValues va = test::evaluateAt(a, trial), vb = test::evaluateAt(b, trial);
    for (size_t i = 0; i < n; ++i) EXPECT_NEAR(vb.F[i], va.F[i], 1e-13 * (1 + std::abs(va.F[i]))) << "F[" << i << "]";
    for (size_t k = 0; k < nnz; ++k) EXPECT_NEAR(vb.J[k], va.J[k], 1e-13 * (1 + std::abs(va.J[k]))) << "J[" << k << "]";
  }
  EXPECT_EQ(loopCount(a.program(ModelProgram::Residual)), 0u);
  return loopCount(b.program(ModelProgram::Residual));
}

TEST(LoopedKernels, SpringChainGivesTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(R"(model Chain
  parameter Integer n = 9;
  parameter Real m = 1.5, k = 1000, c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end Chain;
)");
  EXPECT_EQ(loops, 2u);  // the interior's Euler–Lagrange rows and the kinematic rows
}

TEST(LoopedKernels, GridOfMassesGivesTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(R"(model Grid
  parameter Integer n = 6, m = 5;
  parameter Real k = 10, c = 0.1, mass = 2;
  coordinate Real z[n, m](start = {{0.01*i*j for j in 1:m} for i in 1:n});
mechanics
  kinetic = sum(0.5*mass*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k*(z[i, j+1] - z[i, j])^2 + 0.1*k*z[i, j]^4 for i in 1:n, j in 1:m-1);
  dissipation = sum(0.5*c*(der(z[i+1, j]) - der(z[i, j]))^2 for i in 1:n-1, j in 1:m);
end Grid;
)");
  EXPECT_EQ(loops, 6u);  // 5 regions of Euler–Lagrange rows and the kinematic rows
}

TEST(LoopedKernels, NonlinearInertiaAndSecondNeighboursGiveTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(R"(model Skip
  parameter Integer n = 12;
  parameter Real k = 100;
  coordinate Real x[n](start = {sin(i) for i in 1:n});
  coordinate Real w(start = 0.2);
mechanics
  kinetic = sum(0.5*(1 + 0.1*x[i]^2)*der(x[i])^2 for i in 1:n) + 0.5*der(w)^2;
  potential = sum(0.5*k*(x[i+2] - x[i])^2 for i in 1:n-2) + sum(k*(1 - cos(x[i])) for i in 2:n-1)
            + 0.5*k*(w - x[5])^2;
  force(x[7]) = sin(time);
end Skip;
)");
  EXPECT_GE(loops, 3u);  // interior regions split around the peeled x[5] and x[7], and the kinematic rows
}

// Found by the fuzzer: the first mass has no kinetic energy (a first-order coordinate whose velocity
// is algebraic), so the array of accelerations the interior's template reads is y' only from x[2] on.
TEST(LoopedKernels, MasslessFirstElementGivesTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(R"(model Chain
  parameter Integer n = 9;
  parameter Real m = 1, k = 1000, c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 2:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end Chain;
)");
  EXPECT_GE(loops, 1u);
}

// A large array's start values are loops (kernel/KernelBuilder.cpp, numberRuns) that store the very
// numbers flattening folded: 0.01*i for x[i], 0 for every velocity, derivative and nominal.
TEST(LoopedKernels, StartValuesOfALargeArrayAreLoopsWithTheSameBits) {
  Compiled c(R"(model Chain
  parameter Integer n = 50;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real y(start = 0.3);
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n) + 0.5*der(y)^2;
  potential = sum(0.5*(x[i+1] - x[i])^2 for i in 1:n-1) + 0.5*(y - x[1])^2;
end Chain;
)", true);
  const kernel::Program& init = c.kernels().program(ModelProgram::InitialValues);
  EXPECT_GE(loopCount(init), 2u);
  EXPECT_LT(init.code.size(), 40u);  // not 3 stores per unknown
  size_t n = c.kernels().variableCount();
  ASSERT_EQ(n, 102u);
  std::vector<double> out(3 * n, -1.0);
  kernel::interpret(init, ModelCall{}, out);
  for (size_t i = 1; i <= 50; ++i) EXPECT_EQ(out[i - 1], 0.01 * static_cast<double>(i)) << "x[" << i << "]";
  EXPECT_EQ(out[50], 0.3);
  for (size_t j = n; j < 3 * n; ++j) EXPECT_EQ(out[j], 0.0) << j;
}

TEST(LoopedKernels, PendulumWithoutRepeatedStructureHasNoLoops) {
  EXPECT_EQ(expectSameKernels(R"(model Pendulum
  parameter Real m = 1, l = 1, g = 9.81;
  coordinate Real th(start = 0.5);
mechanics
  kinetic = 0.5*m*l^2*der(th)^2;
  potential = -m*g*l*cos(th);
end Pendulum;
)"), 0u);
}

}  // namespace
}  // namespace qdot
