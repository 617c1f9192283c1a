// ProgramBuilder with loops: a stencil template lowered once into a loop body computes what the
// direct C++ loop computes (kernel::interpret); what was lowered before the loop is reused inside
// and after it, what was first lowered inside is forgotten at endLoop (lowered again after it,
// constants sharing their pool entry); ldidx and stx through the index table.
#include <gtest/gtest.h>

#include <array>
#include <bit>

#include "kernel/Lowering.h"

namespace qdot::test {
namespace {

using kernel::Op;
using sym::Expr;

class LoopLowering : public ::testing::Test {
 protected:
  sym::Context ctx;
  Expr next = ctx.symbol("u[i+1]"), here = ctx.symbol("u[i]"), prev = ctx.symbol("u[i-1]"), k = ctx.symbol("k"),
       i = ctx.symbol("i");
  Expr c(double v) { return ctx.constant(v); }

  // out[L] = 2 * (load `op` at base + L) for L = first, first+1, ... (count iterations), 4 outputs.
  kernel::Program doubledInLoop(Op op, uint32_t base, uint32_t count, int32_t first) {
    kernel::ProgramBuilder b("residual");
    b.bindLoopedLoad(here, op, base);
    b.beginLoop(kernel::Loop{.count = count, .first = first, .stride = 1});
    b.storeLooped(0, b.lower(ctx.mul(c(2), here)));
    b.endLoop();
    return b.finish(4);
  }

  static size_t count(const kernel::Program& p, Op op) {
    size_t n = 0;
    for (const auto& ins : p.code) n += ins.op == op;
    return n;
  }
};

// F[j] = k*k*(u[j+1] - 2u[j] + u[j-1]) + 3 for j = 1 .. n-2, then F[0] = k*k + 3 after the loop.
TEST_F(LoopLowering, StencilTemplateInALoopBody) {
  const uint32_t n = 9;
  kernel::ProgramBuilder b("residual");
  b.bindLoad(k, Op::LoadP, 0);
  b.bindLoopedLoad(next, Op::LoadYLooped, 2), b.bindLoopedLoad(here, Op::LoadYLooped, 1);
  b.bindLoopedLoad(prev, Op::LoadYLooped, 0);
  uint32_t kReg = b.lower(k);  // hoisted: loaded once, before the loop
  Expr kk = ctx.mul(k, k);
  uint32_t id = b.beginLoop(kernel::Loop{.count = n - 2, .first = 0, .stride = 1});
  EXPECT_EQ(id, 0u);
  Expr stencil = ctx.add(ctx.mul(kk, ctx.add(std::array<Expr, 3>{next, ctx.mul(c(-2), here), prev})), c(3));
  b.storeLooped(1, b.lower(stencil));
  b.endLoop();
  uint32_t after = b.lower(ctx.add(kk, c(3)));
  b.store(0, after);
  b.store(n - 1, b.lower(k));
  kernel::Program p = b.finish(n);

  EXPECT_EQ(b.lower(k), kReg);
  EXPECT_EQ(count(p, Op::LoadP), 1u);  // k: once, before the loop, used inside and after
  EXPECT_EQ(count(p, Op::Mul), 4u);  // k*k, -2*u[i], (k*k)*(...) in the body, k*k again after it
  EXPECT_EQ(count(p, Op::LoadConst), 3u);  // -2 and 3 for the body, 3 again after it
  EXPECT_EQ(p.constants.size(), 2u);       // ... sharing the pool entry
  ASSERT_EQ(p.loops.size(), 1u);
  // The body's constants are loaded once, between k and the loop (hoistLoopConstants).
  EXPECT_EQ(p.code[kReg + 1].op, Op::LoadConst);
  EXPECT_EQ(p.code[kReg + 2].op, Op::LoadConst);
  EXPECT_EQ(p.code[kReg + 3].op, Op::LoopBegin);
  for (size_t i = kReg + 4; p.code[i].op != Op::LoopEnd; ++i) EXPECT_NE(p.code[i].op, Op::LoadConst) << i;

  std::vector<double> y = {0.3, -1.2, 2.5, 0.7, -0.1, 1.9, -2.2, 0.4, 1.1}, F(n, -7.0);
  double kv = 1.7;
  kernel::interpret(p, {.y = y.data(), .p = &kv}, F);
  for (uint32_t j = 1; j + 1 < n; ++j) {
    double s = kv * kv * (y[j + 1] + -2.0 * y[j] + y[j - 1]) + 3.0;
    EXPECT_EQ(std::bit_cast<uint64_t>(F[j]), std::bit_cast<uint64_t>(s)) << j;
  }
  EXPECT_EQ(F[0], kv * kv + 3.0);
  EXPECT_EQ(F[n - 1], kv);
}

// hoistLoopConstants on a hand-written program: two loops whose bodies load the same constants
// (one of them twice) and a select reading three registers; the constants move before each loop,
// once per loop, every operand is renamed, and the program computes the same bits.
TEST_F(LoopLowering, HoistedConstantsComputeTheSameBits) {
  using kernel::Instr;
  kernel::Program p;
  p.name = "residual";
  p.constants = {0.5, -3.0};
  p.loops = {kernel::Loop{.count = 4}, kernel::Loop{.count = 3, .first = 1, .stride = 1}};
  p.outputCount = 8;
  p.code = {Instr{Op::LoadP, 0, 0, 0, 0},          // %0 = p[0]
            Instr{Op::LoopBegin, 0, 0, 0, 0},      // loop 0
            Instr{Op::LoadYLooped, 0, 0, 0, 0},    // %2 = y[L]
            Instr{Op::LoadConst, 0, 0, 0, 0},      // %3 = 0.5
            Instr{Op::Mul, 2, 3, 0, 0},            // %4
            Instr{Op::LoadConst, 0, 0, 0, 1},      // %5 = -3
            Instr{Op::LoadConst, 0, 0, 0, 0},      // %6 = 0.5 again
            Instr{Op::Select, 4, 5, 6, 0},         // %7 = %4 ? -3 : 0.5
            Instr{Op::Add, 7, 0, 0, 0},            // %8 = %7 + p[0]
            Instr{Op::StoreLooped, 8, 0, 0, 0},    // out[L]
            Instr{Op::LoopEnd, 0, 0, 0, 0},
            Instr{Op::LoopBegin, 0, 0, 0, 1},      // loop 1
            Instr{Op::LoadConst, 0, 0, 0, 1},      // %12 = -3
            Instr{Op::LoadYLooped, 0, 0, 0, 0},    // %13 = y[L]
            Instr{Op::Mul, 12, 13, 0, 0},          // %14
            Instr{Op::StoreLooped, 14, 0, 0, 4},   // out[4 + L]
            Instr{Op::LoopEnd, 0, 0, 0, 1}};
  ASSERT_EQ(kernel::checkLoops(p, 4, 1), "");
  std::vector<double> y = {0.0, 2.0, -1.5, 0.25}, before(8, -1.0), after(8, -1.0);
  double pv = 0.75;
  kernel::interpret(p, {.y = y.data(), .p = &pv}, before);
  kernel::Program hoisted = p;
  kernel::hoistLoopConstants(hoisted);
  EXPECT_EQ(kernel::checkLoops(hoisted, 4, 1), "");
  kernel::interpret(hoisted, {.y = y.data(), .p = &pv}, after);
  for (size_t k = 0; k < 8; ++k) EXPECT_EQ(std::bit_cast<uint64_t>(after[k]), std::bit_cast<uint64_t>(before[k])) << k;
  EXPECT_EQ(count(hoisted, Op::LoadConst), 3u);  // 0.5 and -3 before loop 0, -3 before loop 1
  bool inBody = false;
  for (const auto& ins : hoisted.code) {
    inBody = ins.op == Op::LoopBegin || (inBody && ins.op != Op::LoopEnd);
    EXPECT_FALSE(inBody && ins.op == Op::LoadConst);
  }
  EXPECT_LT(kernel::executedInstructions(hoisted), kernel::executedInstructions(p));
}

// Start values 0.01*i over a table loop, stored through a permutation (stx).
TEST_F(LoopLowering, LoopOffsetAndIndexedStores) {
  kernel::ProgramBuilder b("initialValues");
  std::vector<uint32_t> offsets = {4, 0, 3}, slots = {2, 0, 1};
  uint32_t offsetBase = b.appendIndexTable(offsets), slotBase = b.appendIndexTable(slots);
  EXPECT_EQ(offsetBase, 0u);
  EXPECT_EQ(slotBase, 3u);
  b.bindLoopOffset(i);
  b.beginLoop(kernel::Loop{.count = 3, .offsetTable = offsetBase});
  b.storeIndexed(slotBase, b.lower(ctx.mul(c(0.01), i)));
  b.endLoop();
  kernel::Program p = b.finish(3);
  EXPECT_EQ(count(p, Op::LoadLoopOffset), 1u);
  std::vector<double> out(3, -1.0);
  kernel::interpret(p, {}, out);
  EXPECT_EQ(out[2], 0.01 * 4);
  EXPECT_EQ(out[0], 0.01 * 0);
  EXPECT_EQ(out[1], 0.01 * 3);
}

// A loop of count 0 runs nothing; a loop of count 1 runs its body once.
TEST_F(LoopLowering, CountZeroAndOne) {
  for (uint32_t iterations : {0u, 1u}) {
    kernel::ProgramBuilder b("residual");
    b.bindLoopedLoad(here, Op::LoadYLooped, 0);
    b.beginLoop(kernel::Loop{.count = iterations, .first = 2, .stride = 5});
    b.storeLooped(0, b.lower(ctx.mul(c(2), here)));
    b.endLoop();
    kernel::Program p = b.finish(4);
    std::vector<double> y = {1, 2, 3, 4}, out(4, -1.0);
    kernel::interpret(p, {.y = y.data()}, out);
    EXPECT_EQ(out[2], iterations ? 6.0 : -1.0);
    EXPECT_EQ(out[0] + out[1] + out[3], -3.0);
  }
}

// checkLoops (what the JIT relies on) accepts the builder's loops and names each broken rule;
// executedInstructions counts a body once per iteration.
TEST_F(LoopLowering, CheckLoopsAndExecutedInstructions) {
  auto build = [&](uint32_t count, int32_t first) { return doubledInLoop(Op::LoadYLooped, 1, count, first); };
  kernel::Program p = build(3, 0);  // y[1 + L], L = 0..2: y[1..3]; out[0..2]
  EXPECT_EQ(kernel::checkLoops(p, 4, 0), "");
  EXPECT_EQ(kernel::executedInstructions(p), 3 + 3u * 3);  // ldk (hoisted), loop, endloop; 3 x (ldyl, mul, stl)
  EXPECT_NE(kernel::checkLoops(build(4, 0), 4, 0).find("ldyl index out of range"), std::string::npos);  // y[4]
  EXPECT_NE(kernel::checkLoops(build(3, -2), 4, 0).find("index out of range"), std::string::npos);      // y[-1]
  EXPECT_EQ(kernel::checkLoops(build(0, -9), 4, 0), "");  // no iteration reaches anything
  kernel::Program escaped = p;
  escaped.code.push_back({Op::Store, 3, 0, 0, 3});  // %3 (the mul, in the body) after the loop
  EXPECT_NE(kernel::checkLoops(escaped, 4, 0).find("is read outside it"), std::string::npos);
  kernel::Program outside = p;
  outside.code.push_back({Op::LoadLoopOffset});
  EXPECT_NE(kernel::checkLoops(outside, 4, 0).find("ldidx outside a loop"), std::string::npos);
  kernel::Program nested = p;
  nested.loops.push_back(nested.loops[0]);
  nested.code.insert(nested.code.begin() + 1, {Op::LoopBegin, 0, 0, 0, 1});
  EXPECT_NE(kernel::checkLoops(nested, 4, 0).find("nested loop"), std::string::npos);
}

// A parameter array read in a loop (ldpl p[imm + L]) is checked against the parameters' count at
// the loop's smallest and largest offsets, and only inside a loop.
TEST_F(LoopLowering, CheckLoopsBoundsALoopedParameterLoad) {
  auto build = [&](uint32_t count, int32_t first) { return doubledInLoop(Op::LoadPLooped, 2, count, first); };
  kernel::Program p = build(3, 0);  // p[2 + L], L = 0..2: p[2..4]
  ASSERT_EQ(count(p, Op::LoadPLooped), 1u);
  EXPECT_EQ(kernel::checkLoops(p, 4, 5), "");
  EXPECT_NE(kernel::checkLoops(p, 4, 4).find("ldpl index out of range"), std::string::npos);  // p[4] of 4
  EXPECT_NE(kernel::checkLoops(build(2, -3), 4, 5).find("ldpl index out of range"), std::string::npos);  // p[-1]
  std::vector<double> params = {0, 0, 1.5, 2.5, 3.5}, out(4, -1.0);
  kernel::interpret(p, {.p = params.data()}, out);
  EXPECT_EQ(out, (std::vector<double>{3.0, 5.0, 7.0, -1.0}));
  kernel::Program outside = p;
  outside.code.push_back({Op::LoadPLooped, 0, 0, 0, 0});
  EXPECT_NE(kernel::checkLoops(outside, 4, 5).find("ldpl outside a loop"), std::string::npos);
}

// A table entry read as a number (ldx X[imm + c]) must lie in the index table for every iteration.
TEST_F(LoopLowering, CheckLoopsBoundsATableEntryReadAsANumber) {
  kernel::Program p = doubledInLoop(Op::LoadTable, 1, 3, 0);  // X[1 + c], c = 0..2
  p.indexTable = {9, 4, 5, 6};
  EXPECT_EQ(kernel::checkLoops(p, 4, 0), "");
  std::vector<double> out(4, -1.0);
  kernel::interpret(p, {}, out);
  EXPECT_EQ(out, (std::vector<double>{8.0, 10.0, 12.0, -1.0}));
  p.indexTable.pop_back();  // X[3] missing
  EXPECT_NE(kernel::checkLoops(p, 4, 0).find("ldx index out of range"), std::string::npos);
}

}  // namespace
}  // namespace qdot::test
