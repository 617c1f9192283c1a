// Non-finite results: the compiled model returns 1 and lastError names the culprit operation,
// its equation and source line, exactly as the VM does; a NaN in an untaken branch is not blamed.
#include <gmock/gmock.h>

#include "KernelSource.h"

namespace qdot::test {
namespace {

using ::testing::HasSubstr;

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

TEST(JitDomainErrors, SqrtOfNegativeNamesTheEquationAndLine) {
  KernelSource m("domain.qd", kDomain);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 2.0;
  EXPECT_EQ(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "");
  s.y[0] = 0.75;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "sqrt of a negative number (-0.25) in equation 3 at domain.qd:9");
}

TEST(JitDomainErrors, JacobianErrorsSayWhichFunction) {
  KernelSource m("domain.qd", kDomain);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 0.75;
  std::vector<double> J(q->jacobianNonzeros);
  EXPECT_NE(q->jacobian(q, 0, s.y.data(), s.yp.data(), s.p.data(), 10.0, J.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("sqrt of a negative number (-0.25) in equation 3 at domain.qd:9"));
  EXPECT_THAT(q->lastError(q), HasSubstr("(computing jacobian)"));
}

TEST(JitDomainErrors, SplitProgramsDiagnoseTheSame) {
  llvmbackend::JitOptions options;
  options.maxInstructionsPerFunction = 2;
  KernelSource m("domain.qd", kDomain, options);
  ASSERT_TRUE(m.ok());
  EXPECT_GT(m.stats.functions[2], 1u);
  const QdotModel* q = m.model;
  State s(q);
  s.y[0] = 0.75;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_STREQ(q->lastError(q), "sqrt of a negative number (-0.25) in equation 3 at domain.qd:9");
}

TEST(JitDomainErrors, LogDivisionAndNaNInputs) {
  KernelSource m("log.qd", R"(model L
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
  s.y[0] = 0.0;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("log of zero in equation"));
  EXPECT_THAT(q->lastError(q), HasSubstr("log.qd:7"));
  s.y[0] = 2.0;
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("division by zero (1/0)"));
  EXPECT_THAT(q->lastError(q), HasSubstr("log.qd:8"));
  s.y[0] = std::nan("");
  EXPECT_NE(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0);
  EXPECT_THAT(q->lastError(q), HasSubstr("the value of x is nan"));
}

TEST(JitDomainErrors, UntakenBranchIsNotBlamed) {
  KernelSource m("branch.qd", R"(model B
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
  s.y[0] = 0.5;  // sqrt(-0.5) is computed (straight-line code) but not selected
  EXPECT_EQ(q->residual(q, 0, s.y.data(), s.yp.data(), s.p.data(), s.F.data()), 0) << q->lastError(q);
}

}  // namespace
}  // namespace qdot::test
