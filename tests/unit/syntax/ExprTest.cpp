// Expression tests: precedence and associativity, postfix forms, calls and comprehensions, and the
// toSource printer (round trips with minimal parentheses).
#include "SyntaxTestUtil.h"

namespace qdot::testing {
namespace {

using namespace ast;

TEST(Expr, UnaryMinusBindsLooserThanPower) {
  EXPECT_EQ(exprShape("-x^2"), "(neg (^ x 2))");
  EXPECT_EQ(exprShape("-a*b"), "(neg (* a b))");
  EXPECT_EQ(exprShape("-a + b"), "(+ (neg a) b)");
  EXPECT_EQ(exprShape("+a"), "(pos a)");
  EXPECT_EQ(exprShape("- -a"), "(neg (neg a))");
}

TEST(Expr, UnaryMinusAfterABinaryOperator) {
  EXPECT_EQ(exprShape("2*-3"), "(* 2 (neg 3))");
  EXPECT_EQ(exprShape("a - -b"), "(- a (neg b))");
  EXPECT_EQ(exprShape("a/-b^2"), "(/ a (neg (^ b 2)))");
  EXPECT_EQ(exprShape("x^-1"), "(^ x (neg 1))");
  EXPECT_EQ(exprShape("a < -b"), "(< a (neg b))");
}

TEST(Expr, ArithmeticPrecedence) {
  EXPECT_EQ(exprShape("a+b*c^d"), "(+ a (* b (^ c d)))");
  EXPECT_EQ(exprShape("a-b-c"), "(- (- a b) c)");
  EXPECT_EQ(exprShape("a/b/c"), "(/ (/ a b) c)");
  EXPECT_EQ(exprShape("a*b/c*d"), "(* (/ (* a b) c) d)");
  EXPECT_EQ(exprShape("(a+b)*c"), "(* (+ a b) c)");
  EXPECT_EQ(exprShape("(a^b)^c"), "(^ (^ a b) c)");
  EXPECT_EQ(exprShape("a^(b^c)"), "(^ a (^ b c))");
  EXPECT_EQ(exprShape("der(x)^2"), "(^ (call der x) 2)");
}

TEST(Expr, LogicalAndRelational) {
  EXPECT_EQ(exprShape("a < b and not c"), "(and (< a b) (not c))");
  EXPECT_EQ(exprShape("a or b and c"), "(or a (and b c))");
  EXPECT_EQ(exprShape("not a or b"), "(or (not a) b)");
  EXPECT_EQ(exprShape("not a < b"), "(not (< a b))");
  EXPECT_EQ(exprShape("a + 1 >= b*2"), "(>= (+ a 1) (* b 2))");
  EXPECT_EQ(exprShape("a == b"), "(== a b)");
  EXPECT_EQ(exprShape("a <> b"), "(<> a b)");
  EXPECT_EQ(exprShape("x <= 1 or x > 2"), "(or (<= x 1) (> x 2))");
  EXPECT_EQ(exprShape("true and false"), "(and true false)");
}

TEST(Expr, Ranges) {
  EXPECT_EQ(exprShape("1:n"), "(: 1 n)");
  EXPECT_EQ(exprShape("1:2:n"), "(: 1 2 n)");
  EXPECT_EQ(exprShape("a+1:b*2"), "(: (+ a 1) (* b 2))");
  EXPECT_EQ(exprShape("1:n or m"), "(: 1 (or n m))");
}

TEST(Expr, IfExpressions) {
  EXPECT_EQ(exprShape("if a then b else c"), "(if a b c)");
  EXPECT_EQ(exprShape("if a then b elseif c then d else e"), "(if a b c d e)");
  EXPECT_EQ(exprShape("if a then b else if c then d else e"), "(if a b (if c d e))");
  EXPECT_EQ(exprShape("1 + (if x > 0 then x else -x)"), "(+ 1 (if (> x 0) x (neg x)))");
}

TEST(Expr, Primaries) {
  EXPECT_EQ(exprShape("1.5e3"), "1500");
  EXPECT_EQ(exprShape("\"m/s\""), "\"m/s\"");
  EXPECT_EQ(exprShape("time"), "time");
  EXPECT_EQ(exprShape("pi"), "pi");
  EXPECT_EQ(exprShape("{1, 2, 3}"), "(array 1 2 3)");
  EXPECT_EQ(exprShape("{{1, 2}, {3, 4}}"), "(array (array 1 2) (array 3 4))");
  EXPECT_EQ(exprShape("{}"), "(array)");
}

TEST(Expr, NumbersKeepIntegerFlag) {
  auto p = parseText("model M Real a = 3; Real b = 3.0; Real c = 1e2; end M;");
  const auto& d = p->cls().declarations;
  EXPECT_TRUE(cast<NumberExpr>(d[0].binding.get())->isInteger);
  EXPECT_FALSE(cast<NumberExpr>(d[1].binding.get())->isInteger);
  EXPECT_FALSE(cast<NumberExpr>(d[2].binding.get())->isInteger);
  EXPECT_DOUBLE_EQ(cast<NumberExpr>(d[2].binding.get())->value, 100.0);
}

TEST(Expr, DottedNamesAreOneNameExpr) {
  auto p = parseText("model M Real v = Vibration.Mass.m; end M;");
  auto* n = dyn_cast<NameExpr>(p->cls().declarations[0].binding.get());
  ASSERT_NE(n, nullptr);
  EXPECT_EQ(n->parts, (std::vector<std::string>{"Vibration", "Mass", "m"}));
  ASSERT_EQ(n->partRanges.size(), 3u);
  EXPECT_EQ(p->sm.slice(n->partRanges[1]), "Mass");
  EXPECT_EQ(p->sm.slice(n->range), "Vibration.Mass.m");
}

TEST(Expr, SubscriptsAndMembers) {
  EXPECT_EQ(exprShape("x[i]"), "(index x i)");
  EXPECT_EQ(exprShape("M[i, j+1]"), "(index M i (+ j 1))");
  EXPECT_EQ(exprShape("ms[2].a.s"), "(. (. (index ms 2) a) s)");
  EXPECT_EQ(exprShape("a.b[1]"), "(index a.b 1)");
  EXPECT_EQ(exprShape("x[2:3]"), "(index x (: 2 3))");
  EXPECT_EQ(exprShape("y[:, 1]"), "(index y (:) 1)");
  EXPECT_EQ(exprShape("x[end]"), "(index x end)");
  EXPECT_EQ(exprShape("x[end - 1]"), "(index x (- end 1))");
  EXPECT_EQ(exprShape("x[2:end]"), "(index x (: 2 end))");
  EXPECT_EQ(exprShape("x[1][2]"), "(index (index x 1) 2)");
}

TEST(Expr, MemberRangesAndIndexRanges) {
  auto p = parseText("model M Real v = ms[2].a; end M;");
  auto* m = dyn_cast<MemberExpr>(p->cls().declarations[0].binding.get());
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->field, "a");
  EXPECT_EQ(p->sm.slice(m->range), "ms[2].a");
  EXPECT_EQ(p->sm.slice(m->fieldRange), "a");
  EXPECT_EQ(p->sm.slice(m->base->range), "ms[2]");
}

TEST(Expr, Calls) {
  EXPECT_EQ(exprShape("sin(x)"), "(call sin x)");
  EXPECT_EQ(exprShape("atan2(y, x)"), "(call atan2 y x)");
  EXPECT_EQ(exprShape("f()"), "(call f)");
  EXPECT_EQ(exprShape("Lib.f(1)"), "(call Lib.f 1)");
  EXPECT_EQ(exprShape("der(a.s)"), "(call der a.s)");
  EXPECT_EQ(exprShape("pre(x)"), "(call pre x)");
  EXPECT_EQ(exprShape("initial()"), "(call initial)");
  EXPECT_EQ(exprShape("experiment(StopTime = 10, Interval = 0.1)"), "(call experiment StopTime=10 Interval=0.1)");
  EXPECT_EQ(exprShape("f(1, x == 2)"), "(call f 1 (== x 2))");
  EXPECT_EQ(exprShape("fill(1, n)"), "(call fill 1 n)");
  EXPECT_EQ(exprShape("der(x)[1]"), "(index (call der x) 1)");
}

TEST(Expr, CallRangeAndCallee) {
  auto p = parseText("model M Real v = Lib.f(1, k = 2); end M;");
  auto* c = dyn_cast<CallExpr>(p->cls().declarations[0].binding.get());
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->callee->dotted(), "Lib.f");
  EXPECT_EQ(p->sm.slice(c->range), "Lib.f(1, k = 2)");
  ASSERT_EQ(c->namedArgs.size(), 1u);
  EXPECT_EQ(c->namedArgs[0].name, "k");
  EXPECT_EQ(p->sm.slice(c->namedArgs[0].nameRange), "k");
}

TEST(Expr, ReductionsAndComprehensions) {
  EXPECT_EQ(exprShape("sum(x[i] for i in 1:n)"), "(call sum (for (index x i) i=(: 1 n)))");
  EXPECT_EQ(exprShape("{i*j for i in 1:n, j in 1:2:m}"), "(for (* i j) i=(: 1 n) j=(: 1 2 m))");
  EXPECT_EQ(exprShape("product(a for a in v)"), "(call product (for a a=v))");
  EXPECT_EQ(exprShape("sum(0.5*m*(der(x[i])^2 + der(y[i])^2) for i in 1:2)"),
            "(call sum (for (* (* 0.5 m) (+ (^ (call der (index x i)) 2) (^ (call der (index y i)) 2))) i=(: 1 2)))");
}

TEST(Expr, ComprehensionRangeIncludesBraces) {
  auto p = parseText("model M Real v[3] = {i for i in 1:3}; end M;");
  const Expr* e = p->cls().declarations[0].binding.get();
  ASSERT_TRUE(isa<ComprehensionExpr>(e));
  EXPECT_EQ(p->sm.slice(e->range), "{i for i in 1:3}");
}

TEST(Expr, BinaryOperatorRange) {
  auto p = parseText("model M Real v = a  +  b; end M;");
  auto* b = dyn_cast<BinaryExpr>(p->cls().declarations[0].binding.get());
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(p->sm.slice(b->opRange), "+");
  EXPECT_EQ(p->sm.slice(b->range), "a  +  b");
}

// toSource prints with the fewest parentheses that keep the structure; printing and reparsing
// gives the same tree.
TEST(ToSource, RoundTrips) {
  const char* cases[] = {"-x^2", "a + b*c^d", "(a + b)*c", "a - (b - c)", "a - b - c", "2*(-3)", "(a^b)^c",
                         "a^(b^c)", "a < b and not c", "not (a and b)", "1:2:n", "if a then b elseif c then d else e",
                         "sum(x[i] for i in 1:n)", "{i for i in 1:3}", "{{1, 2}, {3, 4}}", "ms[2].a.s", "x[:, end]",
                         "f(1, k = 2)", "-(a + b)", "a*b/c", "a/(b*c)", "(-a)^2", "x^(-1)", "der(x)^2",
                         "\"a\\\"b\"", "(if a then 1 else 2) + 1", "a or b and c", "(a or b) and c", "time"};
  for (const char* c : cases) {
    auto p = parseText(std::string("model M Real v = ") + c + "; end M;");
    ASSERT_FALSE(p->diags.hasErrors()) << c << "\n" << p->rendered();
    const Expr* e = p->cls().declarations[0].binding.get();
    std::string printed = toSource(*e);
    EXPECT_EQ(printed, c);
    EXPECT_EQ(exprShape(printed), sexpr(e)) << c;
  }
}

// Regression (fuzz_frontend): postfix forms on literals print back to text that lexes the same.
TEST(ToSource, PostfixOnLiteralsRoundTrips) {
  for (const char* c : {"(1)[2]", "(1.5)[2]", "{1, 2}[1]", "\"s\"[1]", "(1)[2].a", "(1:3)[2]"}) {
    auto p = parseText(std::string("model M Real v = ") + c + "; end M;");
    ASSERT_FALSE(p->diags.hasErrors()) << c << "\n" << p->rendered();
    std::string printed = toSource(*p->cls().declarations[0].binding);
    EXPECT_EQ(exprShape(printed), sexpr(p->cls().declarations[0].binding.get())) << c << " -> " << printed;
  }
}

TEST(ToSource, NormalisesSpacingAndNumbers) {
  auto p = parseText("model M Real v = 0.50*rho  +x^ 2-1e-4; end M;");
  EXPECT_EQ(toSource(*p->cls().declarations[0].binding), "0.5*rho + x^2 - 0.0001");
  EXPECT_EQ(formatNumber(3, true), "3");
  EXPECT_EQ(formatNumber(2.5e4, false), "25000");
  EXPECT_EQ(formatNumber(1e-6, false), "0.000001");
  EXPECT_EQ(formatNumber(1e-12, false), "1e-12");
  EXPECT_EQ(formatNumber(6.02e23, false), "6.02e+23");
}

TEST(ToSource, CloneIsDeep) {
  auto p = parseText("model M Real v = sum(if a[i] > 0 then f(x, k = 1) else {1, 2}[1] for i in 1:n); end M;");
  const Expr& e = *p->cls().declarations[0].binding;
  ExprPtr copy = clone(e);
  EXPECT_EQ(sexpr(copy.get()), sexpr(&e));
  EXPECT_EQ(toSource(*copy), toSource(e));
  EXPECT_EQ(copy->range.begin, e.range.begin);
}

}  // namespace
}  // namespace qdot::testing
