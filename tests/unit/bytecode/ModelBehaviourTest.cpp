// The VM model from source text: domain errors name the equation and its file:line, parameter
// bindings follow overrides in dependency order, initial equations set start values, a module
// survives serialisation, registers are reused, and the disassembly is deterministic.
#include <gmock/gmock.h>

#include <sstream>

#include "SourceModel.h"

namespace qdot::test {
namespace {

using ::testing::HasSubstr;

// Line 8 holds the user equation (equation 3: Euler-Lagrange row 1, kinematic row 2, then this).
const char* kDomain = R"(model Domain
  parameter Real m = 1;
  parameter Real c = 1;
  coordinate Real x(start = 2);
  Real r;
mechanics
  kinetic = 0.5*m*der(x)^2;
equation
  r = sqrt(x - c);
end Domain;
)";

struct State {
  std::vector<double> p, y, yp, F;
  explicit State(const QdotModel* q) : p(q->nParameters), y(q->nVariables), yp(q->nVariables), F(q->nVariables) {
    q->parameters(q, nullptr, nullptr, p.data());
  }
};

TEST(DomainErrors, SqrtOfNegativeNamesTheEquationAndLine) {
  SourceModel m("domain.qd", kDomain);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 1.5;  // x > c: fine
  EXPECT_EQ(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "");
  s.y[0] = 0.75;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "sqrt of a negative number (-0.25) in equation 3 at domain.qd:9");
}

TEST(DomainErrors, JacobianErrorsSayWhichFunction) {
  SourceModel m("domain.qd", kDomain);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 0.75;
  std::vector<double> J(q->jacobianNonzeros);
  EXPECT_NE(q->jacobian(q, 0, s.y.data(), s.yp.data(), s.p.data(), 10.0, J.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("sqrt of a negative number (-0.25) in equation 3 at domain.qd:9"));
  EXPECT_THAT(q->lastError(q), HasSubstr("(computing jacobian)"));
}

TEST(DomainErrors, LogDivisionAndNaNInputs) {
  SourceModel m("log.qd", R"(model L
  coordinate Real x(start = 1);
  Real a, b;
mechanics
  kinetic = 0.5*der(x)^2;
equation
  a = log(x);
  b = 1/(x - 2);
end L;
)");
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 0;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "log of zero in equation 3 at log.qd:7");
  s.y[0] = 2;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "division by zero (1/0) in equation 4 at log.qd:8");
  s.y[0] = std::nan("");
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("the value of x is nan in equation"));
}

TEST(DomainErrors, UntakenBranchIsNotAnError) {
  SourceModel m("branch.qd", R"(model B
  coordinate Real x(start = 1);
  Real r;
mechanics
  kinetic = 0.5*der(x)^2;
equation
  r = if x > 1 then sqrt(x - 1) else 0;
end B;
)");
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 0.5;  // sqrt(-0.5) is computed (both branches are) but not selected
  EXPECT_EQ(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0) << q->lastError(q);
  EXPECT_EQ(s.F[2], s.y[2]);
}

const char* kBindings = R"(model Bindings
  parameter Real k = 2*m "declared before what it uses";
  parameter Real m = 1;
  parameter Real w = sqrt(k/m);
  coordinate Real x(start = w);
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
end Bindings;
)";

TEST(Parameters, BindingsFollowOverridesInDependencyOrder) {
  SourceModel m("bindings.qd", kBindings);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  ASSERT_EQ(q->nParameters, 3u);
  ASSERT_STREQ(q->parameterNames[0], "k");
  ASSERT_STREQ(q->parameterNames[1], "m");
  std::vector<double> p(3), given = {0, 0, 0};
  std::vector<uint8_t> overridden = {0, 0, 0};
  ASSERT_EQ(q->parameters(q, given.data(), overridden.data(), p.data()), 0);
  EXPECT_EQ(p, (std::vector<double>{2, 1, std::sqrt(2.0)}));
  given[1] = 3, overridden[1] = 1;  // m = 3 -> k = 6, w = sqrt(2)
  ASSERT_EQ(q->parameters(q, given.data(), overridden.data(), p.data()), 0);
  EXPECT_EQ(p, (std::vector<double>{6, 3, std::sqrt(2.0)}));
  given[0] = 12, overridden[0] = 1;  // k given too -> w = 2
  ASSERT_EQ(q->parameters(q, given.data(), overridden.data(), p.data()), 0);
  EXPECT_EQ(p, (std::vector<double>{12, 3, 2}));
  std::vector<double> y0(2), yp0(2), nominal(2);
  ASSERT_EQ(q->initialValues(q, p.data(), 0, y0.data(), yp0.data(), nominal.data()), 0);
  EXPECT_EQ(y0[0], 2.0);  // start = w
  EXPECT_EQ(y0[1], 0.0);  // a velocity starts at rest
}

TEST(Parameters, BadGivenValueIsReported) {
  SourceModel m("bindings.qd", kBindings);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  std::vector<double> p(3), given = {-2, 1, 0};
  std::vector<uint8_t> overridden = {1, 0, 0};
  EXPECT_NE(q->parameters(q, given.data(), overridden.data(), p.data()), 0);
  EXPECT_STREQ(q->lastError(q),
               "sqrt of a negative number (-2) in parameter w at bindings.qd:4 (computing parameters)");
}

TEST(InitialValues, ExplicitInitialEquationSetsAVelocityStart) {
  SourceModel m("governor_free.qd", readFile(std::string(QDOT_SOURCE_DIR) + "/examples/textbook/governor_free.qd"));
  ASSERT_TRUE(m.ok());
  EXPECT_FALSE(m.diags.hasErrors());
  const QdotModel* q = m.model;
  std::vector<double> p(q->nParameters), y0(q->nVariables), yp0(q->nVariables), nominal(q->nVariables);
  std::vector<int32_t> fixed(q->nVariables);
  q->parameters(q, nullptr, nullptr, p.data());
  ASSERT_EQ(q->initialValues(q, p.data(), 0, y0.data(), yp0.data(), nominal.data()), 0);
  ASSERT_EQ(q->fixedStarts(q, fixed.data()), 0);
  for (uint32_t j = 0; j < q->nVariables; ++j) {
    std::string name = q->variableNames[j];
    double expected = name == "theta" ? 0.8 : name == "der(phi)" ? 10.0 : 0.0;  // phi and der(theta): 0
    EXPECT_EQ(y0[j], expected) << name;
    EXPECT_EQ(fixed[j], name == "der(phi)" ? kFixedAsWritten : kFixedByDefault) << name;  // set by the initial equation
  }
}

// An implicit initial equation is a row of F used only at t0, after the DAE's rows, with a label.
TEST(InitialValues, ImplicitInitialEquationIsAnInitialRow) {
  driver::Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "implicit.qd", R"(model I
  coordinate Real x(start = 1);
mechanics
  kinetic = 0.5*der(x)^2;
initial equation
  x^2 = 4;
end I;
)", "", driver::Stage::Kernel));
  const ModelDescription& d = c.kernels->description;
  EXPECT_EQ(d.initialRows, (std::vector<int32_t>{static_cast<int32_t>(c.dae->equations.size())}));
  EXPECT_EQ(d.initialRowLabels, (std::vector<std::string>{"initial equation x^2 = 4"}));
  EXPECT_EQ(d.fixed[0], 0);  // x is computed from the initial equation, its start is the guess
  EXPECT_EQ(d.residualCount(), d.variableCount() + 1);
}

TEST(Serialization, RoundTripGivesTheSameModuleAndResults) {
  SourceModel m("nlink.qd", readFile(std::string(QDOT_SOURCE_DIR) + "/examples/pendulum/nlink.qd"));
  ASSERT_TRUE(m.ok());
  std::vector<uint8_t> bytes = bc::serialize(m.module);
  Result<bc::Module> read = bc::deserialize(bytes);
  ASSERT_TRUE(read.ok()) << read.error();
  const bc::Module& back = read.value();
  EXPECT_EQ(bc::serialize(back), bytes);
  std::ostringstream a, b;
  vm::disassemble(a, m.module);
  vm::disassemble(b, back);
  EXPECT_EQ(a.str(), b.str());
  Result<ModelPtr> model2 = vm::createModelFromBytes(bytes);
  ASSERT_TRUE(model2.ok()) << model2.error();
  QdotModel* q2 = model2->get();
  const QdotModel* q = m.model;
  State s1(q), s2(q2);
  for (size_t j = 0; j < s1.y.size(); ++j) s1.y[j] = s2.y[j] = 0.1 * j, s1.yp[j] = s2.yp[j] = -0.05 * j;
  q->residual(q, 0.5, s1.y.data(), s1.yp.data(), s1.p.data(), s1.F.data());
  q2->residual(q2, 0.5, s2.y.data(), s2.yp.data(), s2.p.data(), s2.F.data());
  EXPECT_EQ(s1.F, s2.F);
}

TEST(Emitter, RegistersAreReused) {
  SourceModel m("nlink.qd", readFile(std::string(QDOT_SOURCE_DIR) + "/examples/pendulum/nlink.qd"));
  ASSERT_TRUE(m.ok());
  const auto& k = m.kernel.program(ModelProgram::Jacobian);
  const auto& f = m.module.function(ModelProgram::Jacobian);
  EXPECT_LT(f.registerCount * 4, k.code.size()) << f.registerCount << " registers for " << k.code.size()
                                                << " kernel values";
}

// The tiered run keeps the kernels (for the background JIT) and the VM's module alive together: they
// hold one description, not two (about 140 MB at 10⁶ masses). Editing a copy leaves the original.
TEST(Emitter, ModuleSharesTheKernelsDescription) {
  SourceModel m("nlink.qd", readFile(std::string(QDOT_SOURCE_DIR) + "/examples/pendulum/nlink.qd"));
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(m.module.description.sharesWith(m.kernel.description));
  EXPECT_EQ(&m.module.description->variableNames, &m.kernel.description->variableNames);
  bc::Module copy = m.module;
  ASSERT_TRUE(copy.description.sharesWith(m.kernel.description));
  copy.description.edit().variableNames.front() = "renamed";
  EXPECT_FALSE(copy.description.sharesWith(m.kernel.description));
  EXPECT_EQ(copy.description->variableNames.front(), "renamed");
  EXPECT_NE(m.kernel.description->variableNames.front(), "renamed");
  EXPECT_EQ(copy.description->variableNames.size(), m.kernel.description->variableNames.size());
}

TEST(Emitter, DisassemblyIsDeterministicAndNamesSources) {
  std::string first;
  for (int run = 0; run < 2; ++run) {
    SourceModel m("domain.qd", kDomain);
    ASSERT_TRUE(m.ok());
    std::ostringstream os;
    bytecode::printBytecode(os, m.module);
    if (run == 0) first = os.str();
    EXPECT_EQ(os.str(), first);
  }
  EXPECT_THAT(first, HasSubstr("function residual:"));
  EXPECT_THAT(first, HasSubstr("; equation 3 at domain.qd:9: r = sqrt(-c + x)"));
  EXPECT_THAT(first, HasSubstr("sqrt"));
}

}  // namespace
}  // namespace qdot::test
