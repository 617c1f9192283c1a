// buildKernels on hand-built DAEs: the exact residual and Jacobian programs of a tiny model
// (CSE shared between them), the CSC pattern, parameter bindings in dependency order with
// overrides, start values and initial equations, errors for unsupported constructs.
#include <gmock/gmock.h>

#include <sstream>

#include "TinyDae.h"

namespace qdot::test {
namespace {

using ::testing::HasSubstr;


std::string text(const kernel::KernelModule& m, ModelProgram id) {
  std::ostringstream os;
  kernel::printProgram(os, m.program(id), m);
  return os.str();
}

size_t count(const kernel::Program& p, kernel::Op op) {
  size_t n = 0;
  for (const auto& ins : p.code) n += ins.op == op;
  return n;
}

TEST(Kernel, TinyResidualIsExact) {
  TinyDae d;
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  EXPECT_FALSE(d.diags.hasErrors());
  EXPECT_EQ(text(m, ModelProgram::Residual), R"(
function residual: 2 outputs, 12 instructions, 0 constants
  ; equation 1 (Euler-Lagrange equation of x)
  %0 = ldy 1 (der(x))
  %1 = ldy 0 (x)
  %2 = sin %1
  %3 = mul %0, %2
  %4 = ldyp 1 (der(x))
  %5 = ldp 1 (m)
  %6 = mul %4, %5
  %7 = add %3, %6
  st out[0], %7
  ; equation 2 (velocity of x)
  %9 = ldyp 0 (x)
  %10 = sub %9, %0
  st out[1], %10
)");
}

// J = dF/dy + cj dF/dy': column x = (v cos x, cj), column v = (sin x + m cj, -1). sin(x) is the
// one subexpression residual and Jacobian share: one CSE temporary, computed once in each program.
TEST(Kernel, TinyJacobianIsExactAndSharesCse) {
  TinyDae d;
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  EXPECT_EQ(m.description->jacobianColumnStarts, (std::vector<int32_t>{0, 2, 4}));
  EXPECT_EQ(m.description->jacobianRowIndices, (std::vector<int32_t>{0, 1, 0, 1}));
  EXPECT_EQ(m.sharedTemporaries, 1u);
  EXPECT_EQ(text(m, ModelProgram::Jacobian), R"(
function jacobian: 4 outputs, 14 instructions, 1 constants
  ; equation 1 (Euler-Lagrange equation of x)
  %0 = ldy 1 (der(x))
  %1 = ldy 0 (x)
  %2 = cos %1
  %3 = mul %0, %2
  st out[0], %3
  ; equation 2 (velocity of x)
  %5 = ldcj
  st out[1], %5
  ; equation 1 (Euler-Lagrange equation of x)
  %7 = sin %1
  %8 = ldp 1 (m)
  %9 = mul %8, %5
  %10 = add %7, %9
  st out[2], %10
  ; equation 2 (velocity of x)
  %12 = ldk -1
  st out[3], %12
)");
  EXPECT_EQ(count(m.program(ModelProgram::Residual), kernel::Op::Sin), 1u);
  EXPECT_EQ(count(m.program(ModelProgram::Jacobian), kernel::Op::Sin), 1u);
  EXPECT_EQ(count(m.program(ModelProgram::Residual), kernel::Op::Cos), 0u);  // Jacobian-only work stays out
}

TEST(Kernel, ResidualAndJacobianValues) {
  TinyDae d;
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  std::vector<double> y = {0.3, -1.2}, yp = {0.7, 2.5}, p = {3.0, 1.5}, F(2), J(4);
  kernel::interpret(m.program(ModelProgram::Residual), {.t = 0, .cj = 0, .y = y.data(), .yp = yp.data(), .p = p.data()}, F);
  EXPECT_EQ(F[0], -1.2 * std::sin(0.3) + 2.5 * 1.5);
  EXPECT_EQ(F[1], 0.7 - -1.2);
  kernel::interpret(m.program(ModelProgram::Jacobian), {.t = 0, .cj = 40, .y = y.data(), .yp = yp.data(), .p = p.data()}, J);
  EXPECT_EQ(J, (std::vector<double>{-1.2 * std::cos(0.3), 40, std::sin(0.3) + 1.5 * 40, -1}));
}

// k = 2*m is declared before m: m must be computed first; an override of m flows into k.
TEST(Kernel, ParameterBindingsInDependencyOrderWithOverrides) {
  TinyDae d;
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  const kernel::Program& prog = m.program(ModelProgram::Parameters);
  std::vector<double> p(2), given = {0, 0};
  std::vector<uint8_t> overridden = {0, 0};
  auto run = [&] { kernel::interpret(prog, {.given = given.data(), .overridden = overridden.data()}, p); };
  run();
  EXPECT_EQ(p, (std::vector<double>{3.0, 1.5}));
  given[1] = 2, overridden[1] = 1;
  run();
  EXPECT_EQ(p, (std::vector<double>{4.0, 2.0}));
  given[0] = 7, overridden[0] = 1;
  run();
  EXPECT_EQ(p, (std::vector<double>{7.0, 2.0}));
}

TEST(Kernel, CyclicParameterBindingsAreReported) {
  TinyDae d;
  d.dae.parameters[1].value = d.ctx.add(d.k, d.ctx.one());  // m = k + 1, k = 2*m
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  ASSERT_TRUE(d.diags.hasErrors());
  EXPECT_THAT(d.diags.diagnostics()[0].message, HasSubstr("depends on itself"));
}

TEST(Kernel, StartValuesNominalsAndFixedFlags) {
  TinyDae d;
  d.dae.variables[0].declaration.nominal = d.ctx.constant(4);
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  std::vector<double> p = {3.0, 1.5}, out(6);
  kernel::interpret(m.program(ModelProgram::InitialValues), {.p = p.data()}, out);
  EXPECT_EQ(out, (std::vector<double>{1.5, 0, 0, 0, 4, 0}));  // y0 = (k/2, 0), yp0 = 0, nominal = (4, 0)
  EXPECT_EQ(m.description->fixed, (std::vector<int32_t>{1, 1}));
  EXPECT_EQ(m.description->isDifferential, (std::vector<int32_t>{1, 1}));
}

// Initial equations: `v = expression` over parameters sets a start value (then fixed); any other
// (here on an acceleration) is a row of F used only at t0, replacing a start that was fixed only by
// default (x's); one condition too many is E0606.
void addInitial(TinyDae& d, sym::Expr lhs, sym::Expr rhs) {
  dae::Equation e;
  e.lhs = lhs, e.rhs = rhs, e.residual = d.ctx.sub(lhs, rhs);
  e.origin.kind = flat::OriginKind::InitialEquation;
  d.dae.initialEquations.push_back(e);
}

TEST(Kernel, ExplicitInitialEquationsSetStartsOthersBecomeRows) {
  TinyDae d;
  addInitial(d, d.v, d.ctx.mul(d.ctx.constant(2), d.m));  // der(x) = 2*m: the velocity's start
  addInitial(d, d.ctx.constant(5), d.a);                    // 5 = der(der(x)): a condition at t0
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  ASSERT_EQ(d.diags.errorCount(), 0u);
  std::vector<double> p = {3.0, 1.5}, out(6);
  kernel::interpret(m.program(ModelProgram::InitialValues), {.p = p.data()}, out);
  EXPECT_EQ(out, (std::vector<double>{1.5, 3.0, 0, 0, 0, 0}));
  EXPECT_EQ(m.description->fixed, (std::vector<int32_t>{kStartGuess, kFixedAsWritten}));  // x from der(der(x)) = 5
  EXPECT_EQ(m.description->initialRows, (std::vector<int32_t>{2}));
  EXPECT_EQ(m.description->residualCount(), 3u);
}

TEST(Kernel, OverDeterminedInitialConditionsAreNamed) {
  TinyDae d;
  addInitial(d, d.v, d.ctx.mul(d.ctx.constant(2), d.m));
  addInitial(d, d.ctx.constant(5), d.a);
  addInitial(d, d.ctx.add(d.x, d.v), d.ctx.one());  // a third condition on two states
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  ASSERT_EQ(d.diags.errorCount(), 1u);
  EXPECT_EQ(d.diags.diagnostics()[0].code, DiagCode::E0606);
}

TEST(Kernel, SymbolsThatAreNotInputsAreReported) {
  TinyDae d;
  d.addEquation(d.ctx.sub(d.ctx.symbol("w"), d.x));
  d.dae.variables.push_back({.name = "z", .y = d.ctx.symbol("z")});  // keep the system square
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  ASSERT_EQ(d.diags.errorCount(), 1u);
  EXPECT_EQ(d.diags.diagnostics()[0].message, "'w' is not available in the residual");
}

// Every instruction serves a labelled source, except stores of a plain 0 start value.
TEST(Kernel, EverySourceIsLabelled) {
  TinyDae d;
  kernel::KernelModule m = kernel::buildKernels(d.dae, d.ctx, d.diags);
  for (const kernel::Program& p : m.programs)
    for (const kernel::Instr& ins : p.code) {
      if (ins.source == UINT32_MAX && &p == &m.program(ModelProgram::InitialValues)) continue;
      ASSERT_LT(ins.source, m.sources.size()) << p.name;
      EXPECT_FALSE(m.sources[ins.source].label.empty());
    }
}

TEST(Kernel, PrintingIsDeterministic) {
  std::string first;
  for (int run = 0; run < 3; ++run) {
    TinyDae d;
    std::ostringstream os;
    kernel::printKernels(os, kernel::buildKernels(d.dae, d.ctx, d.diags));
    if (run == 0) first = os.str();
    EXPECT_EQ(os.str(), first);
  }
  EXPECT_THAT(first, HasSubstr("column 1 (der(x)): rows 0 1"));
}

}  // namespace
}  // namespace qdot::test
