// `for` equations kept as templates (issue 15, docs/loops.md, dae/TemplateOde.h): a model whose
// equations are an explicit ODE der(x) = f(x, p, t) keeps each `for` equation `der(x[i]) = …` as one
// template and one loop, and its kernels compute what the model's scalar kernels compute (residual
// and Jacobian at random states, to rounding). A model that is not such an ODE, or a loop that is
// not such a template, compiles exactly as without templates (the same kernels, the same
// diagnostics).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <vector>

#include "unit/pipeline/KernelPair.h"

namespace qdot {
namespace {

using Compiled = test::CompiledKernels;
using test::loopCount;

// Per row of the scalar DAE, the unknown it is matched to in a templated model: the one whose
// derivative it names (`der(x) = …`, `c*der(x) = …`), else its algebraic unknown (`f = …`).
std::vector<size_t> rowOfUnknown(const Compiled& scalar) {
  const dae::Dae& dae = *scalar.c.dae;
  std::vector<size_t> row;
  for (const auto& e : dae.equations) {
    std::vector<sym::Expr> symbols = scalar.c.ctx.freeSymbols(e.residual);
    auto reads = [&](sym::Expr s) { return s && std::find(symbols.begin(), symbols.end(), s) != symbols.end(); };
    size_t j = 0;
    while (j < dae.variables.size() && !reads(dae.variables[j].yp)) ++j;
    if (j == dae.variables.size())
      for (j = 0; j < dae.variables.size() && !(dae.variables[j].kind == dae::VarKind::Algebraic && reads(dae.variables[j].y));) ++j;
    EXPECT_LT(j, dae.variables.size()) << "a row matched to no unknown";
    row.push_back(j);
  }
  return row;
}

// (row, column) → entry of a CSC pattern, rows mapped by `row`.
std::map<std::pair<size_t, size_t>, size_t> entries(const ModelDescription& d, const std::vector<size_t>& row) {
  std::map<std::pair<size_t, size_t>, size_t> at;
  for (size_t col = 0; col + 1 < d.jacobianColumnStarts.size(); ++col)
    for (auto k = static_cast<size_t>(d.jacobianColumnStarts[col]); k < static_cast<size_t>(d.jacobianColumnStarts[col + 1]); ++k)
      at[{row.empty() ? d.jacobianRowIndices[k] : row[d.jacobianRowIndices[k]], col}] = k;
  return at;
}

// The model compiled with and without templates: the templated one is a templated ODE with
// `blocks` template blocks, and both give the same residual and Jacobian (rows matched by the
// derivative they define) at a few random states. Returns the residual's loops.
size_t expectSameKernels(const std::string& text, size_t blocks, const test::GivenParameters& given = {}) {
  Compiled scalar(text, false), looped(text, true);
  EXPECT_TRUE(scalar.ok && looped.ok) << scalar.diagnostics() << looped.diagnostics();
  if (!scalar.ok || !looped.ok) return 0;
  EXPECT_FALSE(scalar.c.dae->templated());
  EXPECT_EQ(looped.c.dae->templateBlocks.size(), blocks);
  const kernel::KernelModule &a = scalar.kernels(), &b = looped.kernels();
  EXPECT_EQ(a.description->variableNames, b.description->variableNames);
  EXPECT_EQ(a.description->fixed, b.description->fixed);
  std::vector<size_t> row = rowOfUnknown(scalar);
  auto ja = entries(a.description, row), jb = entries(b.description, {});
  EXPECT_EQ(ja.size(), jb.size());
  size_t n = a.variableCount();
  for (int trial = 0; trial < 3; ++trial) {
    test::KernelValues A = test::evaluateAt(a, trial, given), B = test::evaluateAt(b, trial, given);
    const std::vector<double>&fa = A.F, &fb = B.F, &va = A.J, &vb = B.J;
    for (size_t i = 0; i < n; ++i) EXPECT_NEAR(fb[row[i]], fa[i], 1e-13 * (1 + std::abs(fa[i]))) << "F[" << i << "]";
    EXPECT_EQ(A.start, B.start);  // start values, initial equations included
    for (const auto& [at, k] : ja) {
      auto other = jb.find(at);
      if (other == jb.end()) {
        ADD_FAILURE() << "no looped entry at (" << at.first << ", " << at.second << ")";
        continue;
      }
      EXPECT_NEAR(vb[other->second], va[k], 1e-13 * (1 + std::abs(va[k]))) << "J(" << at.first << ", " << at.second << ")";
    }
  }
  EXPECT_EQ(loopCount(a.program(ModelProgram::Residual)), 0u);
  return loopCount(b.program(ModelProgram::Residual));
}

constexpr const char* kRod = R"(model Rod
  parameter Integer n = 9;
  parameter Real a = 1.7;
  Real T[n](start = {sin(3.14159265358979*i/(n + 1)) for i in 1:n});
equation
  der(T[1]) = a*(T[2] - 2*T[1]);
  for i in 2:n-1 loop
    der(T[i]) = a*(T[i+1] - 2*T[i] + T[i-1]);
  end for;
  der(T[n]) = a*(T[n-1] - 2*T[n]);
end Rod;
)";

TEST(ForEquations, RodIsOneLoopWithTheScalarResidualAndJacobian) {
  EXPECT_EQ(expectSameKernels(kRod, 1), 1u);
  // Rows in the order of the unknowns is the order the rod is written in: the same pattern.
  Compiled scalar(kRod, false), looped(kRod, true);
  EXPECT_EQ(scalar.kernels().description->jacobianRowIndices, looped.kernels().description->jacobianRowIndices);
  const dae::TemplateBlock& block = looped.c.dae->templateBlocks[0];
  EXPECT_EQ(block.firstRow, 0);
  EXPECT_EQ(block.region, (flat::Box{{2, 8}}));
}

// A plate: the interior is one 2-D template (written with two iterators, or as nested loops), its
// edges are loops with a constant subscript (not of the template form: scalar rows).
std::string plate(const std::string& interior) {
  return R"(model Plate
  parameter Integer n = 6, m = 5;
  parameter Real a = 0.8, b = 0.3;
  Real T[n, m](start = {{sin(i)*cos(j) for j in 1:m} for i in 1:n});
equation
)" + interior + R"(
  for j in 1:m loop
    der(T[1, j]) = -b*T[1, j];
    der(T[n, j]) = -b*T[n, j] + sin(time);
  end for;
  for i in 2:n-1 loop
    der(T[i, 1]) = -b*T[i, 1]^3;
    der(T[i, m]) = -b*T[i, m];
  end for;
end Plate;
)";
}

TEST(ForEquations, PlateInteriorIsOneLoopWithTheScalarResidualAndJacobian) {
  EXPECT_EQ(expectSameKernels(plate(R"(  for i in 2:n-1, j in 2:m-1 loop
    der(T[i, j]) = a*(T[i+1, j] + T[i-1, j] + T[i, j+1] + T[i, j-1] - 4*T[i, j]) - b*T[i, j]^2;
  end for;)"), 1), 1u);
}

TEST(ForEquations, NestedLoopsAreOneTemplate) {
  EXPECT_EQ(expectSameKernels(plate(R"(  for i in 2:n-1 loop
    for j in 2:m-1 loop
      der(T[i, j]) = a*(T[i+1, j] + T[i-1, j] + T[i, j+1] + T[i, j-1] - 4*T[i, j]) - b*T[i, j]^2;
    end for;
  end for;)"), 1), 1u);
}

// Two arrays, one loop with two equations (their scalar rows interleave; the templates' rows go by
// unknown), reading each other's elements.
TEST(ForEquations, WaveAsTwoArraysGivesTheScalarResidualAndJacobian) {
  EXPECT_EQ(expectSameKernels(R"(model Wave
  parameter Integer n = 8;
  parameter Real c2 = 4, d = 0.05;
  Real u[n](start = {sin(3.14159265358979*i/(n + 1)) for i in 1:n}), v[n];
equation
  der(u[1]) = v[1];
  der(v[1]) = c2*(u[2] - 2*u[1]) - d*v[1];
  for i in 2:n-1 loop
    der(u[i]) = v[i];
    der(v[i]) = c2*(u[i+1] - 2*u[i] + u[i-1]) - d*v[i];
  end for;
  der(u[n]) = v[n];
  der(v[n]) = c2*(u[n-1] - 2*u[n]) - d*v[n] + cos(2*time);
end Wave;
)", 2), 2u);
}

// --- arrays of parameters read in loops (ldpl) ---

// A rod whose conductance varies along it, a[i] computed from another parameter.
constexpr const char* kVaryingRod = R"(model VaryingRod
  parameter Integer n = 9;
  parameter Real a0 = 1.7;
  parameter Real a[n] = {a0*(1 + 0.5*sin(i)) for i in 1:n};
  Real T[n](start = {sin(3.14159265358979*i/(n + 1)) for i in 1:n});
equation
  der(T[1]) = a[1]*(T[2] - 2*T[1]);
  for i in 2:n-1 loop
    der(T[i]) = a[i]*(T[i+1] - 2*T[i] + T[i-1]) - 0.1*a[i-1]*T[i];
  end for;
  der(T[n]) = a[n]*(T[n-1] - 2*T[n]);
end VaryingRod;
)";

TEST(ForEquations, RodWithVaryingConductanceReadsItInTheLoop) {
  EXPECT_EQ(expectSameKernels(kVaryingRod, 1), 1u);
  EXPECT_EQ(expectSameKernels(kVaryingRod, 1, {{"a0", 0.3}, {"a[4]", 5.0}}), 1u);
  Compiled looped(kVaryingRod, true);
  const kernel::KernelModule& k = looped.kernels();
  EXPECT_EQ(test::opCount(k.program(ModelProgram::Residual), kernel::Op::LoadPLooped), 2u);  // a[%1], a[%1-1]
  EXPECT_EQ(test::opCount(k.program(ModelProgram::Jacobian), kernel::Op::LoadPLooped), 2u);
}

TEST(ForEquations, PlateWithATwoDimensionalParameterArrayReadsItInTheLoop) {
  std::string text = plate(R"(  for i in 2:n-1, j in 2:m-1 loop
    der(T[i, j]) = kap[i, j]*(T[i+1, j] + T[i-1, j] + T[i, j+1] + T[i, j-1] - 4*T[i, j]) - kap[i+1, j-1]*T[i, j]^2;
  end for;)");
  text.insert(text.find("  Real T[n, m]"), "  parameter Real kap[n, m] = {{a + 0.1*i*j for j in 1:m} for i in 1:n};\n");
  EXPECT_EQ(expectSameKernels(text, 1), 1u);
  EXPECT_EQ(expectSameKernels(text, 1, {{"a", 2.0}, {"kap[3,3]", -1.0}}), 1u);
  Compiled looped(text, true);
  EXPECT_EQ(test::opCount(looped.kernels().program(ModelProgram::Residual), kernel::Op::LoadPLooped), 2u);
}

// Rows that name their derivative with a factor, on either side, in any order (`C*der(T[i]) = …`,
// `der(T[n])*C = …`, `0 = …`): still one derivative per row, ∂F/∂y' diagonal, one loop.
TEST(ForEquations, ImplicitRowsWithOneDerivativeAreOneLoop) {
  EXPECT_EQ(expectSameKernels(R"(model Capacities
  parameter Integer n = 9;
  parameter Real G = 2, C = 4;
  Real T[n](start = {sin(3.14159265358979*i/(n + 1)) for i in 1:n});
equation
  C*der(T[1]) = G*(T[2] - 2*T[1]);
  for i in 2:n-1 loop
    (C + 0.1*T[i]^2)*der(T[i]) = G*(T[i+1] - 2*T[i] + T[i-1]);
  end for;
  G*(T[n-1] - 2*T[n]) = der(T[n])*C;
end Capacities;
)", 1), 1u);
  // A chain of masses written as equations: m der(v) = forces, two arrays in one loop.
  EXPECT_EQ(expectSameKernels(R"(model EquationChain
  parameter Integer n = 8;
  parameter Real m = 1.5, k = 1000, c = 0.5;
  Real x[n](start = {0.01*i for i in 1:n}), v[n];
equation
  der(x[1]) = v[1];
  m*der(v[1]) = -k*x[1] + k*(x[2] - x[1]) - c*v[1] + c*(v[2] - v[1]);
  for i in 2:n-1 loop
    der(x[i]) = v[i];
    m*der(v[i]) = k*(x[i+1] - 2*x[i] + x[i-1]) + c*(v[i+1] - 2*v[i] + v[i-1]);
  end for;
  der(x[n]) = v[n];
  m*der(v[n]) = -k*(x[n] - x[n-1]) - c*(v[n] - v[n-1]);
end EquationChain;
)", 2), 2u);
}

using test::expectScalarFallback;

// A heat source whose strength depends on the node, q0·exp(−((i − c)/w)²): the iterator's value in
// a 1-D loop (from its offset); in a plate (two iterators) from a table of each point's subscripts
// (ldx).
TEST(ForEquations, IteratorsAsNumbersAreOneLoop) {
  std::string rod = R"(model HeatedRod
  parameter Integer n = 9;
  parameter Real a = 1.7, q0 = 3, w = 2;
  Real T[n](start = {sin(3.14159265358979*i/(n + 1)) for i in 1:n});
equation
  der(T[1]) = a*(T[2] - 2*T[1]);
  for i in 2:n-1 loop
    der(T[i]) = a*(T[i+1] - 2*T[i] + T[i-1]) + q0*exp(-((i - n/2)/w)^2);
  end for;
  der(T[n]) = a*(T[n-1] - 2*T[n]);
end HeatedRod;
)";
  EXPECT_EQ(expectSameKernels(rod, 1), 1u);
  std::string p = plate("  for i in 2:n-1, j in 2:m-1 loop\n    der(T[i, j]) = a*(T[i+1, j] + T[i-1, j] + T[i, j+1] + T[i, j-1] - 4*T[i, j]) + 0.01*i*j^2;\n  end for;");
  EXPECT_EQ(expectSameKernels(p, 1), 1u);
  Compiled looped(p, true);
  EXPECT_GT(test::opCount(looped.kernels().program(ModelProgram::Residual), kernel::Op::LoadTable), 0u);
}

// Initial equations that give states their start values (`T[1] = …`, also in a loop) keep the
// templates, with the same start values and fixed flags; one that is a condition on a derivative
// is a row of the initialization system, which the structural passes solve on scalars.
TEST(ForEquations, InitialEquationsThatAreStartValuesKeepTheLoop) {
  std::string rod = kRod;
  rod.replace(rod.find("end Rod;"), 8, R"(initial equation
  T[1] = 2*a;
  for i in 2:4 loop
    a*i = T[i];
  end for;
end Rod;)");
  EXPECT_EQ(expectSameKernels(rod, 1), 1u);
  Compiled looped(rod, true);
  ASSERT_TRUE(looped.ok);
  test::KernelValues v = test::evaluateAt(looped.kernels(), 0);
  EXPECT_EQ(v.start[0], 2 * 1.7);
  EXPECT_EQ(v.start[3], 1.7 * 4);
  EXPECT_EQ(looped.kernels().description->fixed[3], kFixedAsWritten);
}

TEST(ForEquations, AnInitialEquationOnADerivativeKeepsTheModelScalar) {
  std::string rod = kRod;
  rod.replace(rod.find("end Rod;"), 8, "initial equation\n  der(T[1]) = 0;\nend Rod;");
  expectScalarFallback(rod);
}

// A parameter array a loop cannot address (another shape than the plate's, iterators out of order)
// keeps the model scalar.
TEST(ForEquations, ParameterArraysALoopCannotAddressKeepTheModelScalar) {
  for (const char* read : {"kap[i, j]", "kap[j, i]"}) {
    std::string text =
        plate("  for i in 2:n-1, j in 2:m-1 loop\n    der(T[i, j]) = " + std::string(read) + "*T[i+1, j];\n  end for;");
    text.insert(text.find("  Real T[n, m]"),
                "  parameter Real kap[n + 1, n + 1] = {{i - j for j in 1:n + 1} for i in 1:n + 1};\n");
    expectScalarFallback(text);
  }
}

// A row without derivative matched to its one algebraic unknown (`q[i] = …`, `f[i] = …`): the
// algebraic unknowns' block of ∂F/∂y is diagonal, an index-1 DAE, and each loop stays one loop.
TEST(ForEquations, AlgebraicUnknownsDefinedByTheirOwnRowsAreLoopsToo) {
  EXPECT_EQ(expectSameKernels(R"(model Algebraic
  parameter Integer n = 7;
  Real x[n](start = {0.1*i for i in 1:n}), q[n];
equation
  for i in 1:n loop
    der(x[i]) = -q[i];
  end for;
  for i in 1:n loop
    q[i] = x[i]^3 + 0.5*x[i];
  end for;
end Algebraic;
)", 2), 2u);
  // The chain with its link forces as unknowns, read at offsets by the masses' rows.
  EXPECT_EQ(expectSameKernels(R"(model ForceChain
  parameter Integer n = 8;
  parameter Real m = 1.5, k = 1000, c = 0.5;
  Real x[n](start = {0.01*i for i in 1:n}), v[n], f[n];
equation
  f[1] = k*x[1] + c*v[1];
  for i in 2:n loop
    f[i] = k*(x[i] - x[i-1]) + c*(v[i] - v[i-1]);
  end for;
  for i in 1:n-1 loop
    der(x[i]) = v[i];
    m*der(v[i]) = f[i+1] - f[i];
  end for;
  der(x[n]) = v[n];
  m*der(v[n]) = -f[n];
end ForceChain;
)", 3), 3u);
}

// A row without derivative that reads two algebraic unknowns is not matched to one of them.
TEST(ForEquations, ARowOfTwoAlgebraicUnknownsKeepsTheModelScalar) {
  expectScalarFallback(R"(model Algebraic
  parameter Integer n = 7;
  Real x[n](start = {0.1*i for i in 1:n}), q[n];
equation
  for i in 1:n loop
    der(x[i]) = -q[i];
  end for;
  for i in 1:n-1 loop
    q[i] + 0.1*q[i+1] = x[i]^3 + 0.5*x[i];
  end for;
  q[n] = x[n];
end Algebraic;
)");
}

// A row naming two derivatives (a coupled mass matrix) is not one derivative per row.
TEST(ForEquations, TwoDerivativesInARowKeepTheModelScalar) {
  expectScalarFallback(R"(model Coupled
  parameter Integer n = 6;
  Real x[n](start = {0.1*i for i in 1:n}), y[n];
equation
  for i in 1:n loop
    der(x[i]) + 0.5*der(y[i]) = -x[i];
    der(y[i]) = x[i] - y[i];
  end for;
end Coupled;
)");
}

TEST(ForEquations, ANonAffineSubscriptKeepsTheLoopScalar) {
  expectScalarFallback(R"(model Reversed
  parameter Integer n = 7;
  Real x[n](start = {0.1*i for i in 1:n});
equation
  for i in 1:n loop
    der(x[i]) = -x[n + 1 - i] + 0.1*x[i];
  end for;
end Reversed;
)");
}

TEST(ForEquations, AnUnknownWithoutEquationKeepsTheModelScalar) {
  expectScalarFallback(R"(model Partial
  parameter Integer n = 5;
  Real x[n](start = {0.1*i for i in 1:n}), w;
equation
  for i in 1:n loop
    der(x[i]) = -x[i] + w;
  end for;
  w = sin(time);
end Partial;
)");
}

// An error inside a loop that could have been a template is reported as without templates.
TEST(ForEquations, ErrorsAreThoseOfTheScalarLowering) {
  const char* text = R"(model Bad
  parameter Integer n = 5;
  Real x[n];
equation
  for i in 1:n loop
    der(x[i]) = -x[i+1];
  end for;
end Bad;
)";
  Compiled scalar(text, false), looped(text, true);
  EXPECT_FALSE(scalar.ok);
  EXPECT_FALSE(looped.ok);
  EXPECT_FALSE(scalar.diagnostics().empty());
  EXPECT_EQ(scalar.diagnostics(), looped.diagnostics());
}

// At a size where one equation per element would show, flattening keeps one template.
TEST(ForEquations, ALargeRodIsOneTemplate) {
  std::string text = kRod;
  text.replace(text.find("n = 9"), 5, "n = 50000");
  Compiled looped(text, true);
  ASSERT_TRUE(looped.ok) << looped.diagnostics();
  ASSERT_EQ(looped.c.dae->templateBlocks.size(), 1u);
  EXPECT_EQ(looped.c.dae->templateBlocks[0].region, (flat::Box{{2, 49999}}));
  EXPECT_EQ(looped.kernels().variableCount(), 50000u);
  EXPECT_LT(looped.kernels().program(ModelProgram::Residual).code.size(), 100u);
}

}  // namespace
}  // namespace qdot
