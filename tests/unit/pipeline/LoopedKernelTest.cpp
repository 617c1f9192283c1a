// Looped and scalar kernels compute the same model (issue 15): a model compiled with its repeated
// structure kept as templates (CompileOptions::keepLoops: loops in the residual and Jacobian) and
// the same model compiled element by element give the same residual and the same Jacobian (same
// CSC pattern, values equal to rounding) and the same invariants at random states, on the
// reference interpreter.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "unit/pipeline/KernelPair.h"

namespace qdot {
namespace {

using test::loopCount;

struct Compiled : test::CompiledKernels {
  Compiled(const std::string& text, bool loops, bool eliminate = false) : CompiledKernels(text, loops, eliminate) {
    EXPECT_TRUE(ok) << diagnostics();
  }
};

// Residual and Jacobian of both at a few random states (parameters at their defaults except those
// `given`); returns the loops the templated one has.
size_t expectSameKernels(const std::string& text, const test::GivenParameters& given = {}) {
  Compiled scalar(text, false), looped(text, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(a.description->variableNames, b.description->variableNames);
  EXPECT_EQ(a.description->jacobianColumnStarts, b.description->jacobianColumnStarts);
  EXPECT_EQ(a.description->jacobianRowIndices, b.description->jacobianRowIndices);
  size_t n = a.variableCount(), nnz = a.description->jacobianRowIndices.size();
  for (int trial = 0; trial < 3; ++trial) {
    test::KernelValues va = test::evaluateAt(a, trial, given), vb = test::evaluateAt(b, trial, given);
    for (size_t i = 0; i < n; ++i) EXPECT_NEAR(vb.F[i], va.F[i], 1e-13 * (1 + std::abs(va.F[i]))) << "F[" << i << "]";
    for (size_t k = 0; k < nnz; ++k) EXPECT_NEAR(vb.J[k], va.J[k], 1e-13 * (1 + std::abs(va.J[k]))) << "J[" << k << "]";
  }
  EXPECT_EQ(loopCount(a.program(ModelProgram::Residual)), 0u);
  return loopCount(b.program(ModelProgram::Residual));
}

// The invariants of a conservative model: its Jacobi integral with the energy sums as loops
// (stadd) equals the scalar one, whose value the mechanics tests check against T + V.
void expectSameInvariants(const std::string& text, size_t sums) {
  Compiled scalar(text, false), looped(text, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(a.description->invariantNames, b.description->invariantNames);
  ASSERT_FALSE(a.description->invariantNames.empty());
  EXPECT_EQ(a.description->invariantNames.back(), "jacobi");
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> va = test::evaluateAt(a, trial).invariants, vb = test::evaluateAt(b, trial).invariants;
    for (size_t i = 0; i < va.size(); ++i) EXPECT_NEAR(vb[i], va[i], 1e-13 * (1 + std::abs(va[i]))) << "invariant " << i;
  }
  EXPECT_EQ(loopCount(a.program(ModelProgram::Invariants)), 0u);
  EXPECT_EQ(loopCount(b.program(ModelProgram::Invariants)), sums);
  EXPECT_EQ(test::opCount(b.program(ModelProgram::Invariants), kernel::Op::StoreAdd), sums);
}

// One pendulum: nothing repeated.
constexpr const char* kPendulum = R"(model Pendulum
  parameter Real m = 1, l = 1, g = 9.81;
  coordinate Real th(start = 0.5);
mechanics
  kinetic = 0.5*m*l^2*der(th)^2;
  potential = -m*g*l*cos(th);
end Pendulum;
)";

// The model with an equation of its own next to the mechanics (`der(y) = -y`): one whose
// templates do not apply, so that the fallback to scalars is what gets compiled.
std::string withAnEquation(std::string text) {
  text.replace(text.find("mechanics"), 9, "  Real y(start = 1);\nequation\n  der(y) = -y;\nmechanics");
  return text;
}

TEST(LoopedKernels, JacobiIntegralOfAChainIsTheScalarOneWithItsSumsAsLoops) {
  expectSameInvariants(R"(model Chain
  parameter Integer n = 9;
  parameter Real m[n] = {1 + 0.5*sin(i) for i in 1:n}, k = 1000;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z(start = 0.1);
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n) + 0.5*der(z)^2;
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 + k*(1 - cos(x[i])) for i in 1:n-1);
end Chain;
)", 2);
}

TEST(LoopedKernels, JacobiIntegralOfAGridIsTheScalarOneWithItsSumsAsLoops) {
  expectSameInvariants(R"(model Grid
  parameter Integer n = 6, m = 5;
  parameter Real k = 10, mass[n, m] = {{1 + 0.1*i*j for j in 1:m} for i in 1:n};
  coordinate Real z[n, m](start = {{0.01*i*j for j in 1:m} for i in 1:n});
mechanics
  kinetic = sum(0.5*mass[i, j]*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k*(z[i, j+1] - z[i, j])^2 + 0.1*k*z[i, j]^4 for i in 1:n, j in 1:m-1);
end Grid;
)", 3);
}

// Initial equations that are start values (a coordinate's, a velocity's) keep the loops, with the
// start values of the scalar kernels; one that is not keeps the model scalar.
TEST(LoopedKernels, InitialEquationsThatAreStartValuesKeepTheLoops) {
  std::string chain = R"(model Chain
  parameter Integer n = 9;
  parameter Real k = 1000, v0 = 0.3;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
initial equation
  der(x[n]) = v0;
  for i in 2:3 loop
    x[i] = 0.1*i;
  end for;
end Chain;
)";
  EXPECT_EQ(expectSameKernels(chain), 2u);
  Compiled scalar(chain, false), looped(chain, true);
  test::KernelValues a = test::evaluateAt(scalar.kernels(), 0), b = test::evaluateAt(looped.kernels(), 0);
  EXPECT_EQ(a.start, b.start);
  EXPECT_EQ(b.start[2], 0.1 * 3);
  EXPECT_EQ(b.start[17], 0.3);  // der(x[9])
  EXPECT_EQ(scalar.kernels().description->fixed, looped.kernels().description->fixed);
  chain.replace(chain.find("der(x[n]) = v0"), 14, "der(x[n]) = x[1]");
  Compiled implicit(chain, true);
  ASSERT_TRUE(implicit.ok) << implicit.diagnostics();
  EXPECT_FALSE(implicit.c.dae->templated());
}

// Forces in `for` loops are templates of the rows: a parameter array, time and neighbours' velocities
// in the loop; a loop whose force reads the scalar z gives scalar rows to the elements it pushes.
TEST(LoopedKernels, ForcesInLoopsGiveTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(R"(model Forced
  parameter Integer n = 12;
  parameter Real k = 1000, c = 0.1, F0 = 2, w = 5;
  parameter Real m[n] = {1 + 0.1*i for i in 1:n};
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z(start = 0.1);
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n) + 0.5*der(z)^2;
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1) + 0.5*k*(z - x[3])^2;
  for i in 2:n loop
    force(x[i]) = -c*der(x[i]) + F0*m[i]*sin(w*time + x[i]) - c*(der(x[i]) - der(x[i-1]));
  end for;
  for i in 1:n-1 loop
    force(x[i]) = 0.5*c*(der(x[i+1]) - der(x[i]));
  end for;
  for i in 1:2 loop
    force(x[i]) = -z*x[i];
  end for;
end Forced;
)");
  EXPECT_EQ(loops, 2u);  // x[4..11]: one loop; the kinematic rows
}

// The same physics written two ways: viscous damping to the ground as a force per mass in a loop,
// and as the dissipation function ½c Σ ẋᵢ². Both looped, their rows agree at random states.
TEST(LoopedKernels, DampingAsForcesInALoopEqualsDampingAsADissipationSum) {
  auto chain = [](const std::string& damping, const std::string& forces) {
    return R"(model Chain
  parameter Integer n = 10;
  parameter Real k = 1000, c = 0.3;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
)" + damping + forces + "end Chain;\n";
  };
  Compiled asForces(chain("", "  for i in 1:n loop\n    force(x[i]) = -c*der(x[i]);\n  end for;\n"), true);
  Compiled asSum(chain("  dissipation = sum(0.5*c*der(x[i])^2 for i in 1:n);\n", ""), true);
  EXPECT_GT(loopCount(asForces.kernels().program(ModelProgram::Residual)), 0u);
  for (int trial = 0; trial < 3; ++trial) {
    test::KernelValues a = test::evaluateAt(asForces.kernels(), trial), b = test::evaluateAt(asSum.kernels(), trial);
    ASSERT_EQ(a.F.size(), b.F.size());
    for (size_t i = 0; i < a.F.size(); ++i) EXPECT_NEAR(a.F[i], b.F[i], 1e-13 * (1 + std::abs(b.F[i]))) << "F[" << i << "]";
  }
}

// An iterator used as a number (masses 1 + 0.01 i, springs k(1 + 0.1 sin(w i)), a forcing with a
// phase 0.1 i): the loop computes it from its offset (ldidx), and the rows, the Jacobian and the
// Jacobi integral are the scalar ones.
constexpr const char* kGradedChain = R"(model Graded
  parameter Integer n = 12;
  parameter Real k = 1000, w = 2;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*(1 + 0.01*i)*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(1 + 0.1*sin(w*i))*(x[i+1] - x[i])^2 + (i + 1)^2*x[i]^4/(2*i) for i in 1:n-1);
end Graded;
)";

// The same in two dimensions: a grid whose masses and springs vary with both subscripts, read from
// tables of each point's subscripts (ldx) in the loops of the rows, the Jacobian and the Jacobi
// integral.
TEST(LoopedKernels, IteratorsAsNumbersInTwoDimensionsGiveTheScalarKernels) {
  const char* grid = R"(model GradedGrid
  parameter Integer n = 6, m = 5;
  parameter Real k = 10;
  coordinate Real z[n, m](start = {{0.01*i*j for j in 1:m} for i in 1:n});
mechanics
  kinetic = sum(0.5*(1 + 0.1*i + 0.01*j^2)*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k*(1 + 0.05*i*j)*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k*(z[i, j+1] - z[i, j])^2 + 0.1*k*sin(i - j)*z[i, j]^4 for i in 1:n, j in 1:m-1);
end GradedGrid;
)";
  EXPECT_GE(expectSameKernels(grid), 2u);
  expectSameInvariants(grid, 3);
  Compiled looped(grid, true);
  EXPECT_GT(test::opCount(looped.kernels().program(ModelProgram::Residual), kernel::Op::LoadTable), 0u);
  EXPECT_GT(test::opCount(looped.kernels().program(ModelProgram::Invariants), kernel::Op::LoadTable), 0u);
}

TEST(LoopedKernels, IteratorsAsNumbersGiveTheScalarResidualJacobianAndInvariants) {
  EXPECT_EQ(expectSameKernels(kGradedChain), 2u);
  expectSameInvariants(kGradedChain, 2);
  std::string forced = kGradedChain;
  forced.replace(forced.find("end Graded;"), 11, "  for i in 2:n loop\n    force(x[i]) = 2*sin(5*time + 0.1*i);\n  end for;\nend Graded;");
  EXPECT_EQ(expectSameKernels(forced), 2u);
  Compiled looped(forced, true);
  EXPECT_GT(test::opCount(looped.kernels().program(ModelProgram::Residual), kernel::Op::LoadLoopOffset), 0u);
}

// Where the templates do not apply (here: an equation section), a model whose templates read an
// iterator as a number is flattened again without them: the very kernels of the scalar lowering.
TEST(LoopedKernels, IteratorsAsNumbersFallBackToTheScalarLoweringExactly) {
  test::expectScalarFallback(withAnEquation(kGradedChain));
}

// Equations that define algebraic unknowns explicitly (a link's tension, a push that a force
// reads) next to the energies: with templates they become outputs before mechanics, as
// `qdot run` solves them out of the scalar system — the same unknowns, outputs (in the same
// order), rows and Jacobian. An equation that is not such a definition keeps the model scalar.
constexpr const char* kChainWithDefinitions = R"(model Defined
  parameter Integer n = 12;
  parameter Real k = 1000;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real tension "force in the first link [N]";
  Real push;
  output Real ends = x[n] - x[1];
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  force(x[n]) = -push;
equation
  tension = k*(x[2] - x[1]);
  2*sin(time) + 0.1*der(x[n]) = push;
end Defined;
)";

TEST(LoopedKernels, ExplicitDefinitionsBecomeOutputsAndKeepTheLoops) {
  Compiled scalar(kChainWithDefinitions, false, true), looped(kChainWithDefinitions, true, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(loopCount(b.program(ModelProgram::Residual)), 2u);
  EXPECT_EQ(a.description->variableNames, b.description->variableNames);
  EXPECT_EQ(b.description->outputNames, (std::vector<std::string>{"tension", "push", "ends"}));
  EXPECT_EQ(a.description->outputNames, b.description->outputNames);
  EXPECT_EQ(a.description->jacobianRowIndices, b.description->jacobianRowIndices);
  for (int trial = 0; trial < 3; ++trial) {
    test::KernelValues va = test::evaluateAt(a, trial), vb = test::evaluateAt(b, trial);
    for (size_t i = 0; i < va.F.size(); ++i) EXPECT_NEAR(vb.F[i], va.F[i], 1e-13 * (1 + std::abs(va.F[i]))) << "F[" << i << "]";
    for (size_t i = 0; i < va.J.size(); ++i) EXPECT_NEAR(vb.J[i], va.J[i], 1e-13 * (1 + std::abs(va.J[i]))) << "J[" << i << "]";
    for (size_t i = 0; i < va.outputs.size(); ++i) EXPECT_NEAR(vb.outputs[i], va.outputs[i], 1e-13 * (1 + std::abs(va.outputs[i])));
  }
  std::string implicit = kChainWithDefinitions;
  implicit.replace(implicit.find("tension = k*"), 12, "tension^3 = k*");
  Compiled stays(implicit, true, true);
  EXPECT_FALSE(stays.c.dae->templated());
}

// Outputs defined by sums (the chain's energy and dissipated power): each sum one loop adding to
// its output (stadd), the values those of the scalar outputs; an output over parameters only is
// expanded (no coordinates to give its loop a shape).
TEST(LoopedKernels, OutputSumsAreLoopsWithTheScalarValues) {
  const std::string text = R"(model Chain
  parameter Integer n = 7;
  parameter Real m = 1, k = 1000, c = 0.5, w[n] = {1 + 0.1*i for i in 1:n};
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  output Real E = sum(0.5*m*der(x[i])^2 for i in 1:n) + 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  output Real P = -sum(c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1) - c*der(x[1])^2;
  output Real centre = sum(w[i]*x[i] for i in 1:n)/sum(w[i] for i in 1:n);
  output Real ramp = sum(0.1*i*x[i] for i in 2:n);
  output Real weights = sum(w[i] for i in 1:n) + 1;
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end Chain;
)";
  Compiled scalar(text, false), looped(text, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(a.description->outputNames, (std::vector<std::string>{"E", "P", "centre", "ramp", "weights"}));
  EXPECT_EQ(b.description->outputNames, a.description->outputNames);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> va = test::evaluateAt(a, trial).outputs, vb = test::evaluateAt(b, trial).outputs;
    ASSERT_EQ(va.size(), 5u);
    for (size_t i = 0; i < va.size(); ++i) EXPECT_NEAR(vb[i], va[i], 1e-13 * (1 + std::abs(va[i]))) << "output " << i;
  }
  // E: 2 sums, P: 1, ramp: 1 (the iterator as a number); centre divides sums (not a summand) and
  // weights sums parameters only: expanded
  EXPECT_EQ(loopCount(a.program(ModelProgram::Outputs)), 0u);
  EXPECT_EQ(loopCount(b.program(ModelProgram::Outputs)), 4u);
  EXPECT_EQ(test::opCount(b.program(ModelProgram::Outputs), kernel::Op::StoreAdd), 4u);
  const flat::Output& E = looped.c.dae->outputs[0];
  ASSERT_EQ(E.sums.size(), 2u);
  EXPECT_EQ(E.sums[0].shape, (std::vector<int>{7}));
  EXPECT_TRUE(looped.c.dae->outputs[4].sums.empty());
}

// The ways of writing the same chain that users write: energies through definitions (`kinetic =
// T;` with `Real T = sum(…)`), sums scaled by factors (`0.5*m*sum(…)`, `0.5*k*(x[1]^2 + sum(…))`,
// `sum(…)/2`), an output that scales a definition (`P = -2*D`). Each keeps its sums as loops, with
// the scalar residual, Jacobian and outputs.
constexpr const char* kChainThroughDefinitions = R"(model Written
  parameter Integer n = 9;
  parameter Real m = 1.5, k = 800, c = 0.4;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real T = 0.5*m*sum(der(x[i])^2 for i in 1:n);
  Real V = 0.5*k*(x[1]^2 + sum((x[i+1] - x[i])^2 for i in 1:n-1));
  Real D = sum(c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1)/2 + 0.5*c*der(x[1])^2;
  output Real E = T + V;
  output Real P = -2*D;
mechanics
  kinetic = T;
  potential = V;
  dissipation = D;
end Written;
)";

TEST(LoopedKernels, EnergiesThroughDefinitionsAndFactorsKeepTheLoops) {
  EXPECT_EQ(expectSameKernels(kChainThroughDefinitions), 2u);  // the interior's rows, the kinematic rows
  Compiled scalar(kChainThroughDefinitions, false), looped(kChainThroughDefinitions, true);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(b.description->outputNames, (std::vector<std::string>{"E", "P"}));
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<double> va = test::evaluateAt(a, trial).outputs, vb = test::evaluateAt(b, trial).outputs;
    for (size_t i = 0; i < va.size(); ++i) EXPECT_NEAR(vb[i], va[i], 1e-13 * (1 + std::abs(va[i]))) << "output " << i;
  }
  EXPECT_EQ(loopCount(b.program(ModelProgram::Outputs)), 3u);  // E: T's and V's sums; P: D's
}

// A factor over a sum makes the expanded template equal to the scalar lowering to rounding only:
// where the templates do not apply (here: an equation of an unknown), the model is flattened again
// and compiles exactly as without templates.
TEST(LoopedKernels, FactoredSumsFallBackToTheScalarLoweringExactly) {
  test::expectScalarFallback(withAnEquation(kChainThroughDefinitions));
}

// Energies stated in `for` loops (`for i in 2:n loop potential = …; end for;`), next to a force
// in the same loop and a grid's nested loops: each statement one sum over the loop's box, the
// scalar kernels; where the templates do not apply, exactly the scalar lowering.
constexpr const char* kEnergiesInLoops = R"(model Looped
  parameter Integer n = 8;
  parameter Real m = 1.2, k = 900, c = 0.3;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z[3, 4](start = {{0.01*(i + j) for j in 1:4} for i in 1:3});
mechanics
  for i in 1:n loop
    kinetic = 0.5*m*der(x[i])^2;
  end for;
  potential = 0.5*k*x[1]^2;
  for i in 2:n loop
    potential = 0.5*k*(x[i] - x[i-1])^2;
    force(x[i]) = -c*der(x[i]);
  end for;
  for i in 1:3 loop
    for j in 1:4 loop
      kinetic = 0.5*der(z[i, j])^2;
      potential = 0.5*k*z[i, j]^2 + 0.1*k*z[i, j]^4;
    end for;
  end for;
end Looped;
)";

TEST(LoopedKernels, EnergiesInForLoopsAreSumsWithTheScalarKernels) {
  EXPECT_GE(expectSameKernels(kEnergiesInLoops), 3u);
  test::expectScalarFallback(withAnEquation(kEnergiesInLoops));
}

// `Real E; equation E = sum(…) + …;` next to the energies: E is defined explicitly, so it becomes an
// output with its sums as loops (as `qdot run` solves it out of the scalar system); a force that
// reads E reads the whole of it. Residual, Jacobian and outputs are the scalar ones.
TEST(LoopedKernels, AnUnknownDefinedBySumsIsAnOutputWithLoops) {
  std::string text = R"(model ChainEq
  parameter Integer n = 10;
  parameter Real m = 1, k = 1000;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real E "energy [J]";
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
equation
  E = sum(0.5*m*der(x[i])^2 for i in 1:n) + 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
end ChainEq;
)";
  for (bool forceReadsE : {false, true}) {
    if (forceReadsE) text.replace(text.find("equation"), 8, "  force(x[n]) = -0.001*E;\nequation");
    Compiled scalar(text, false, true), looped(text, true, true);
    const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
    EXPECT_EQ(loopCount(b.program(ModelProgram::Residual)), 2u) << forceReadsE;
    EXPECT_EQ(b.description->outputNames, (std::vector<std::string>{"E"}));
    EXPECT_EQ(a.description->outputNames, b.description->outputNames);
    EXPECT_EQ(a.description->variableNames, b.description->variableNames);
    EXPECT_EQ(loopCount(b.program(ModelProgram::Outputs)), 2u);
    for (int trial = 0; trial < 3; ++trial) {
      test::KernelValues va = test::evaluateAt(a, trial), vb = test::evaluateAt(b, trial);
      for (size_t i = 0; i < va.F.size(); ++i) EXPECT_NEAR(vb.F[i], va.F[i], 1e-13 * (1 + std::abs(va.F[i]))) << "F[" << i << "]";
      for (size_t i = 0; i < va.J.size(); ++i) EXPECT_NEAR(vb.J[i], va.J[i], 1e-13 * (1 + std::abs(va.J[i]))) << "J[" << i << "]";
      ASSERT_EQ(va.outputs.size(), 1u);
      EXPECT_NEAR(vb.outputs[0], va.outputs[0], 1e-13 * (1 + std::abs(va.outputs[0])));
    }
  }
}

// The same equation next to one that is no explicit definition: the templates do not apply, and
// the sums expand into the equation as the scalar lowering writes it.
TEST(LoopedKernels, AnEquationWithSumsInAScalarModelIsTheScalarOne) {
  test::expectScalarFallback(R"(model ChainEq
  parameter Integer n = 10;
  parameter Real m = 1, k = 1000;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real E, y(start = 1);
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
equation
  E = sum(0.5*m*der(x[i])^2 for i in 1:n) + 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  der(y) = -y*E;
end ChainEq;
)");
}

// `qdot run --stats` says whether the repeated structure became loops and, if not, why: what a
// user with a large model that runs slowly needs to know.
TEST(LoopedKernels, TheCompilationSaysWhyItsLoopsWereExpanded) {
  auto loops = [](const std::string& text, bool keep = true) {
    Compiled c(text, keep);
    return c.c.loops;
  };
  EXPECT_EQ(loops(kChainThroughDefinitions), std::optional<std::string>(""));
  EXPECT_EQ(loops(kEnergiesInLoops), std::optional<std::string>(""));
  EXPECT_EQ(loops(kPendulum), std::nullopt);
  EXPECT_NE(loops(kChainThroughDefinitions, false).value_or("").find("loops are off"), std::string::npos);
  std::string constrained = kChainThroughDefinitions;
  constrained.replace(constrained.find("end Written;"), 0, "  constraint x[1] = 0.01;\n");
  EXPECT_NE(loops(constrained).value_or("").find("it has a constraint (model.qd:14)"), std::string::npos) << *loops(constrained);
  std::string implicit = kChainWithDefinitions;
  implicit.replace(implicit.find("tension = k*"), 12, "tension^3 = k*");
  EXPECT_NE(loops(implicit, true).value_or("").find("the equation at model.qd:13 does not define"), std::string::npos)
      << loops(implicit).value_or("(none)");
}

// A component whose energies are sums (the Vibration library's String) in a model that connects
// nothing: no aliases, no flows, so its sums are loops as the model's own would be.
TEST(LoopedKernels, AComponentWithSumsAndNoConnectionsKeepsItsLoops) {
  const std::string text = R"(model Strung
  import Vibration.*;
  String str(n = 15, T = 100, rhoL = 0.01, L = 1, y(start = {0.001*sin(pi*i/16) for i in 1:15}));
end Strung;
)";
  EXPECT_EQ(expectSameKernels(text), 2u);
  Compiled c(text, true);
  EXPECT_EQ(c.c.loops, std::optional<std::string>(""));
}

// Positions stated as array definitions (`Real px[n] = {l*sin(th[i]) for i in 1:n}`, as the spec
// lets a model state positions) read inside sums: each element is the comprehension's body at the
// template's point, so the coupled pendulums' energies are loops over the angles. The definition's
// iterator may have the sum's name (it shadows it) or another, and an offset range (2:n+1).
TEST(LoopedKernels, ArrayDefinitionsReadInSumsAreTheirBodies) {
  const std::string text = R"(model CoupledPendulums
  parameter Integer n = 9;
  parameter Real m = 1, l = 1, g = 9.81, k = 50;
  coordinate Real th[n](start = {0.1*sin(3.14159*i/(n + 1)) for i in 1:n});
  Real px[n] = {l*sin(th[i]) for i in 1:n};
  Real py[n] = {-l*cos(th[j - 1]) for j in 2:n + 1};
mechanics
  kinetic = sum(0.5*m*(der(px[i])^2 + der(py[i])^2) for i in 1:n);
  potential = sum(m*g*py[i] for i in 1:n) + sum(0.5*k*(px[i+1] - px[i])^2 for i in 1:n-1);
end CoupledPendulums;
)";
  EXPECT_GE(expectSameKernels(text), 2u);
  Compiled c(text, true);
  EXPECT_EQ(c.c.loops, std::optional<std::string>(""));
  // Where the templates do not apply, exactly the scalar lowering (the definitions resolved whole).
  test::expectScalarFallback(withAnEquation(text));
}

// The spring–damper chain of n masses (m = 1.5, k = 1000, c = 0.5), the first tied to a wall.
std::string springChain(size_t n) {
  return R"(model Chain
  parameter Integer n = )" + std::to_string(n) + R"(;
  parameter Real m = 1.5, k = 1000, c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end Chain;
)";
}

TEST(LoopedKernels, SpringChainGivesTheScalarResidualAndJacobian) {
  size_t loops = expectSameKernels(springChain(9));
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

// Found by the fuzzer: the last element's own row has no acceleration of its own (v[n] only
// multiplies the last term, so its momentum does not contain it), but the interior's template
// reads der(der(x[n])): the DAE made der(x[n]) an algebraic unknown and the kernel stage stopped
// on "a template reads an array element that is not an unknown". What a template reads now counts
// as a row's: the unknowns are the scalar DAE's, and so are the kernels.
TEST(LoopedKernels, AnAccelerationOnlyATemplateReadsIsAState) {
  size_t loops = expectSameKernels(R"(model Cubic
  parameter Integer n = 9;
  parameter Real m = 1, c = 0.5, k = 10;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m*der(x[i])^2*c*(der(x[i+1]) - der(x[i])) for i in 1:n-1);
  potential = sum(0.5*k*x[i]^2 for i in 1:n);
end Cubic;
)");
  EXPECT_GE(loops, 1u);
}

// A chain of 70 001 masses — above the 65 536 elements from which the compile splits its passes
// over a large array between two threads (qdot/two_halves.hpp: the symbols, which variables are
// coordinates, the rates of the coordinate array, the model description, the start values and
// nominals) — against its equations of motion written out by hand: the unknowns in order, the
// start values, and at a state the residual m a_i + k (2 x_i − x_{i−1} − x_{i+1}) + c (2 v_i − v_{i−1}
// − v_{i+1}) with the ends' terms (x_0 = 0 a wall, no spring after x_n), and the kinematic rows.
TEST(LoopedKernels, ALargeChainsKernelsAreItsEquationsOfMotion) {
  const size_t n = 70001;
  Compiled c(springChain(n), true);
  ASSERT_TRUE(c.ok);
  const kernel::KernelModule& km = c.kernels();
  ASSERT_EQ(km.variableCount(), 2 * n);
  const auto& names = km.description->variableNames;
  EXPECT_EQ(names[0], "x[1]");
  EXPECT_EQ(names[n / 2], "x[" + std::to_string(n / 2 + 1) + "]");
  EXPECT_EQ(names[n - 1], "x[70001]");
  EXPECT_EQ(names[n], "der(x[1])");
  EXPECT_EQ(names[2 * n - 1], "der(x[70001])");
  EXPECT_GE(loopCount(km.program(ModelProgram::Residual)), 2u);
  for (size_t j = 0; j < 2 * n; ++j) ASSERT_EQ(km.description->isDifferential[j], 1) << j;
  test::KernelValues v = test::evaluateAt(km, 1);
  for (size_t j = 0; j < n; ++j) ASSERT_EQ(v.start[j], 0.01 * static_cast<double>(j + 1)) << "x[" << j + 1 << "]";
  for (size_t j = n; j < 6 * n; ++j) ASSERT_EQ(v.start[j], 0.0) << j;
  // evaluateAt's state (trial 1): y_j = 0.1 sin(1.3 j + 1), y'_j = 0.2 cos(0.7 j + 2)
  auto y = [](size_t j) { return 0.1 * std::sin(1.3 * static_cast<double>(j) + 1); };
  auto yp = [](size_t j) { return 0.2 * std::cos(0.7 * static_cast<double>(j) + 2); };
  const double m = 1.5, k = 1000, damping = 0.5;
  for (size_t i = 0; i < n; ++i) {
    double x = y(i), left = i > 0 ? y(i - 1) : 0.0, right = i + 1 < n ? y(i + 1) : x;
    double u = y(n + i), uLeft = i > 0 ? y(n + i - 1) : 0.0, uRight = i + 1 < n ? y(n + i + 1) : u;
    double expected = m * yp(n + i) + k * ((x - left) + (x - right)) + damping * ((u - uLeft) + (u - uRight));
    ASSERT_NEAR(v.F[i], expected, 1e-12 * (1 + std::abs(expected))) << "row of x[" << i + 1 << "]";
    ASSERT_NEAR(v.F[n + i], yp(i) - u, 1e-15) << "kinematic row of x[" << i + 1 << "]";
  }
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

// --- arrays of parameters read in loops (ldpl) ---

// Parameter loads inside the loop bodies of a program.
size_t loopedParameterLoads(const kernel::Program& p) { return test::opCount(p, kernel::Op::LoadPLooped); }

constexpr const char* kNonUniformChain = R"(model NonUniformChain
  parameter Integer n = 10;
  parameter Real m[n] = {1 + 0.5*sin(i) for i in 1:n};
  parameter Real k[n] = fill(1000, n);
  parameter Real c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n);
  potential = 0.5*k[1]*x[1]^2 + sum(0.5*k[i+1]*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end NonUniformChain;
)";

TEST(LoopedKernels, NonUniformChainReadsItsParameterArraysInTheLoop) {
  EXPECT_EQ(expectSameKernels(kNonUniformChain), 2u);  // the interior's rows and the kinematic rows
  Compiled looped(kNonUniformChain, true);
  const kernel::KernelModule& k = looped.kernels();
  EXPECT_EQ(loopedParameterLoads(k.program(ModelProgram::Residual)), 3u);  // m[%1], k[%1], k[%1+1]
  EXPECT_GE(loopedParameterLoads(k.program(ModelProgram::Jacobian)), 2u);  // m[%1] (cj·m), k[%1] + k[%1+1]
  EXPECT_EQ(k.description->parameterNames.size(), 21u);  // ldpl reads the p vector qdot run fills
}

// Values given at run time to an element (`-p m[3]=…`) and to a parameter the arrays' bindings use
// reach the loop: p is computed as before, the loop only reads it.
TEST(LoopedKernels, GivenElementsAndBindingsOverParametersReachTheLoop) {
  const char* text = R"(model Bound
  parameter Integer n = 8;
  parameter Real m0 = 2, k0 = 300;
  parameter Real m[n] = fill(m0, n);
  parameter Real k[n] = {k0*(1 + 0.1*i) for i in 1:n};
  coordinate Real x[n](start = {0.02*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n);
  potential = sum(0.5*k[i]*(x[i+1] - x[i])^2 + 0.01*k[i]*x[i]^4 for i in 1:n-1) + 0.5*k0*x[1]^2;
end Bound;
)";
  EXPECT_GE(expectSameKernels(text), 2u);
  EXPECT_GE(expectSameKernels(text, {{"m0", 3.5}, {"k[4]", 7.0}, {"m[2]", 0.25}}), 2u);
  // The given values change the residual: the comparison above is not of two unchanged kernels.
  Compiled looped(text, true);
  test::KernelValues plain = test::evaluateAt(looped.kernels(), 0);
  test::KernelValues given = test::evaluateAt(looped.kernels(), 0, {{"k[4]", 7.0}});
  EXPECT_NE(plain.F, given.F);
}

TEST(LoopedKernels, GridWithTwoDimensionalParameterArraysReadsThemInTheLoops) {
  const char* text = R"(model Grid
  parameter Integer n = 6, m = 5;
  parameter Real mass[n, m] = {{1 + 0.1*i + 0.05*j for j in 1:m} for i in 1:n};
  parameter Real k[n, m] = {{10 + sin(i*j) for j in 1:m} for i in 1:n};
  parameter Real c = 0.1;
  coordinate Real z[n, m](start = {{0.01*i*j for j in 1:m} for i in 1:n});
mechanics
  kinetic = sum(0.5*mass[i, j]*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k[i+1, j]*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k[i, j]*(z[i, j+1] - z[i, j])^2 + 0.1*k[i, j]*z[i, j]^4 for i in 1:n, j in 1:m-1);
  dissipation = sum(0.5*c*(der(z[i+1, j]) - der(z[i, j]))^2 for i in 1:n-1, j in 1:m);
end Grid;
)";
  EXPECT_EQ(expectSameKernels(text), 6u);  // 5 regions of Euler–Lagrange rows and the kinematic rows
  EXPECT_EQ(expectSameKernels(text, {{"mass[3,2]", 4.0}, {"k[2,4]", 1.5}}), 6u);
  Compiled looped(text, true);
  EXPECT_GE(loopedParameterLoads(looped.kernels().program(ModelProgram::Residual)), 5u);
}

// Compiled with templates allowed, the model compiles exactly as without: the same kernels, no loop.
void expectScalarFallback(const std::string& text) {
  Compiled scalar(text, false), looped(text, true);
  std::ostringstream a, b;
  kernel::printKernels(a, scalar.kernels());
  kernel::printKernels(b, looped.kernels());
  EXPECT_EQ(a.str(), b.str());
  EXPECT_EQ(loopCount(looped.kernels().program(ModelProgram::Residual)), 0u);
}

// What a loop cannot address as p[first + the row's index] keeps the model scalar: an array indexed
// by the iterators out of order, an array of one dimension in a template of two, an array of
// another shape than the coordinates', constant subscripts, an array of constants.
TEST(LoopedKernels, ParameterArraysALoopCannotAddressKeepTheModelScalar) {
  auto grid = [](const std::string& declaration, const std::string& factor) {
    return R"(model Grid
  parameter Integer n = 4, m = 4;
  )" + declaration + R"(
  coordinate Real z[n, m](start = {{0.01*i*j for j in 1:m} for i in 1:n});
mechanics
  kinetic = sum(0.5*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum()" + factor + R"(*(z[i, j+1] - z[i, j])^2 for i in 1:n, j in 1:m-1);
end Grid;
)";
  };
  expectScalarFallback(grid("parameter Real w[n, m] = {{i + 2*j for j in 1:m} for i in 1:n};", "w[j, i]"));
  expectScalarFallback(grid("parameter Real w[n] = {1 + i for i in 1:n};", "w[i]"));
  expectScalarFallback(grid("parameter Real w[n + 1, m] = {{i + 2*j for j in 1:m} for i in 1:n + 1};", "w[i, j]"));
  expectScalarFallback(grid("parameter Real w[n, m] = {{i + 2*j for j in 1:m} for i in 1:n};", "w[2, j]"));
  expectScalarFallback(grid("constant Real w[4, 4] = {{i + 2*j for j in 1:4} for i in 1:4};", "w[i, j]"));
}

TEST(LoopedKernels, PendulumWithoutRepeatedStructureHasNoLoops) {
  EXPECT_EQ(expectSameKernels(kPendulum), 0u);
}

}  // namespace
}  // namespace qdot
