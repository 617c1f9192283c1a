// ProgramBuilder: the instruction shapes the lowering promises (x^2 -> mul, x^-1 -> div,
// sqrt, powi, pow, sums as add/sub chains, products then divisions), every function kind of
// ExprKinds.def mapped to its opcode and computing what sym::evaluate computes, and depth 10^5.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "kernel/Lowering.h"

namespace qdot::test {
namespace {

using kernel::Op;
using sym::Expr;
using sym::Kind;

class Lowering : public ::testing::Test {
 protected:
  sym::Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), z = ctx.symbol("z");
  Expr c(double v) { return ctx.constant(v); }

  kernel::Program lower(Expr e) {
    kernel::ProgramBuilder b("test");
    b.bindLoad(x, Op::LoadY, 0), b.bindLoad(y, Op::LoadY, 1), b.bindLoad(z, Op::LoadY, 2);
    b.store(0, b.lower(e));
    return b.finish(1);
  }
  // Mnemonics of the program, loads and the store left out: "mul", "ldk div", ...
  std::string shape(Expr e) {
    std::string s;
    for (const auto& ins : lower(e).code)
      if (ins.op != Op::LoadY && ins.op != Op::Store) s += (s.empty() ? "" : " ") + std::string(kernel::mnemonic(ins.op));
    return s;
  }
  double run(Expr e, double xv, double yv, double zv) {
    std::vector<double> in = {xv, yv, zv}, out(1);
    kernel::interpret(lower(e), {.y = in.data()}, out);
    return out[0];
  }
  double reference(Expr e, double xv, double yv, double zv) {
    std::vector<double> v(ctx.symbolCount(), 0.0);
    v[x->symbolId] = xv, v[y->symbolId] = yv, v[z->symbolId] = zv;
    return sym::evaluate(e, v);
  }
};

TEST_F(Lowering, PowersAndProducts) {
  EXPECT_EQ(shape(ctx.pow(x, c(2))), "mul");
  EXPECT_EQ(shape(ctx.pow(x, c(-1))), "ldk div");
  EXPECT_EQ(shape(ctx.pow(x, c(0.5))), "sqrt");
  EXPECT_EQ(shape(ctx.pow(x, c(-0.5))), "ldk sqrt div");
  EXPECT_EQ(shape(ctx.pow(x, c(3))), "powi");
  EXPECT_EQ(shape(ctx.pow(x, c(-3))), "powi");
  EXPECT_EQ(shape(ctx.pow(x, c(2.5))), "ldk pow");
  EXPECT_EQ(shape(ctx.pow(x, y)), "pow");
  EXPECT_EQ(shape(ctx.div(x, y)), "div");                                   // x*y^-1
  EXPECT_EQ(shape(ctx.div(ctx.mul(c(2), x), ctx.mul(y, y))), "ldk mul mul div");  // 2*x / (y*y)
  EXPECT_EQ(shape(ctx.neg(ctx.mul(x, y))), "mul neg");
  EXPECT_EQ(shape(ctx.mul(x, ctx.pow(y, c(3)))), "powi mul");
}

TEST_F(Lowering, SumsUseTheirCoefficients) {
  EXPECT_EQ(shape(ctx.sub(x, y)), "sub");
  EXPECT_EQ(shape(ctx.sub(y, x)), "sub");  // -x + y: no neg
  EXPECT_EQ(shape(ctx.add(ctx.add(x, y), z)), "add add");
  EXPECT_EQ(shape(ctx.add(c(3), ctx.scale(2, x))), "ldk ldk mul add");
  EXPECT_EQ(shape(ctx.sub(ctx.sub(x, y), z)), "sub sub");
}

TEST_F(Lowering, SharedNodesAreComputedOnce) {
  Expr s = ctx.unary(Kind::Sin, ctx.add(x, y));
  kernel::ProgramBuilder b("test");
  b.bindLoad(x, Op::LoadY, 0), b.bindLoad(y, Op::LoadY, 1);
  b.store(0, b.lower(ctx.mul(s, x)));
  b.store(1, b.lower(ctx.add(s, c(1))));
  kernel::Program p = b.finish(2);
  size_t sines = 0, loads = 0;
  for (const auto& ins : p.code) sines += ins.op == Op::Sin, loads += ins.op == Op::LoadY;
  EXPECT_EQ(sines, 1u);
  EXPECT_EQ(loads, 2u);
}

TEST_F(Lowering, ArithmeticMatchesEvaluate) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3, 3);
  Expr cases[] = {ctx.add({std::vector<Expr>{c(1.5), ctx.scale(-2, x), y, ctx.mul(x, z)}}),
                  ctx.mul({std::vector<Expr>{c(3), x, ctx.pow(y, c(2)), ctx.pow(z, c(-1))}}),
                  ctx.pow(ctx.add(x, c(5)), c(1.5)), ctx.pow(ctx.add(x, c(5)), y), ctx.pow(x, c(7))};
  for (Expr e : cases)
    for (int i = 0; i < 100; ++i) {
      double a = u(rng), b = u(rng), d = u(rng);
      double got = run(e, a, b, d), want = reference(e, a, b, d);
      // divisions replace multiplications by a reciprocal, powi repeated multiplication: <= 4 ulps
      EXPECT_LE(std::fabs(got - want), 4 * std::numeric_limits<double>::epsilon() * std::fabs(want))
          << sym::toString(ctx, e) << " at " << a << ", " << b << ", " << d;
    }
}

// Every kind after Pow in ExprKinds.def is a function with its own opcode.
TEST_F(Lowering, EveryFunctionKindHasItsOpcodeAndValue) {
  struct KindInfo {
    Kind kind;
    int arity;
  };
  std::vector<KindInfo> kinds;
  bool functions = false;
#define QDOT_EXPR_KIND(K, A, S)                              \
  if (functions) kinds.push_back({Kind::K, A});              \
  if (Kind::K == Kind::Pow) functions = true;
#include "symbolic/ExprKinds.def"
  ASSERT_EQ(kinds.size(), 24u);
  const double samples[] = {-2.5, -1, -0.5, 0, 0.25, 1, 3};
  for (auto [kind, arity] : kinds) {
    Expr e = arity == 1 ? ctx.unary(kind, x) : arity == 2 ? ctx.binary(kind, x, y) : ctx.select(x, y, z);
    ASSERT_NE(kernel::opcodeOf(kind), Op::Ret) << sym::kindSpelling(kind);
    bool found = false;
    for (const auto& ins : lower(e).code) found |= ins.op == kernel::opcodeOf(kind);
    EXPECT_TRUE(found) << sym::kindSpelling(kind);
    for (double a : samples)
      for (double b : samples) {
        double got = run(e, a, b, 0.5), want = reference(e, a, b, 0.5);
        EXPECT_EQ(std::bit_cast<uint64_t>(got), std::bit_cast<uint64_t>(want))
            << sym::kindSpelling(kind) << "(" << a << ", " << b << "): " << got << " vs " << want;
      }
  }
}

TEST_F(Lowering, DeepExpressionsNeedNoRecursion) {
  Expr e = x;
  for (int i = 0; i < 100000; ++i) e = ctx.unary(i % 2 ? Kind::Sin : Kind::Cos, e);
  kernel::Program p = lower(e);
  EXPECT_EQ(p.code.size(), 100002u);  // load, 10^5 functions, store
  double want = 0.3;
  for (int i = 0; i < 100000; ++i) want = i % 2 ? std::sin(want) : std::cos(want);
  EXPECT_EQ(run(e, 0.3, 0, 0), want);
}

}  // namespace
}  // namespace qdot::test
