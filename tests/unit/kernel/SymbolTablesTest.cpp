// The tables the kernel stage keeps by symbol id: SymbolSlots (pages allocated on first write) and
// UnknownSymbols (which variable's y or y' a symbol is), and ProgramBuilder's use of the latter.
#include <gtest/gtest.h>

#include "kernel/Lowering.h"
#include "kernel/SymbolSlots.h"
#include "kernel/Unknowns.h"
#include "TinyDae.h"

namespace qdot::test {
namespace {

using kernel::Op;

TEST(SymbolSlots, UnwrittenIdsReadNoneAndWrittenOnesKeepTheirValue) {
  kernel::SymbolSlots<uint32_t> slots(7);
  EXPECT_EQ(slots.get(0), 7u);
  EXPECT_EQ(slots.find(5'000'000), nullptr);
  slots.at(5'000'000) = 42;
  slots.at(3) = 9;
  EXPECT_EQ(slots.get(5'000'000), 42u);
  EXPECT_EQ(slots.get(3), 9u);
  EXPECT_EQ(slots.get(4), 7u);          // same page as 3, not written
  EXPECT_EQ(slots.get(5'000'001), 7u);  // same page as 5'000'000
  EXPECT_EQ(slots.find(2'000'000), nullptr);  // between two written pages: never allocated
  ASSERT_NE(slots.find(4), nullptr);
  EXPECT_EQ(*slots.find(4), 7u);
  EXPECT_EQ(slots.get(UINT32_MAX), 7u);
}

TEST(SymbolSlots, EveryIdOfAPageBoundaryIsItsOwn) {
  kernel::SymbolSlots<int> slots(-1);
  for (uint32_t id = 1000; id < 1100; ++id) slots.at(id) = static_cast<int>(id);
  for (uint32_t id = 990; id < 1110; ++id) EXPECT_EQ(slots.get(id), id >= 1000 && id < 1100 ? static_cast<int>(id) : -1);
}

TEST(UnknownSymbols, NamesTheVariableAndWhetherTheSymbolIsItsDerivative) {
  TinyDae t;
  kernel::UnknownSymbols unknowns(t.dae);
  auto x = unknowns.find(t.x), dx = unknowns.find(t.dx), v = unknowns.find(t.v), a = unknowns.find(t.a);
  ASSERT_TRUE(x && dx && v && a);
  EXPECT_EQ(x->variable, 0u);
  EXPECT_FALSE(x->derivative);
  EXPECT_EQ(dx->variable, 0u);
  EXPECT_TRUE(dx->derivative);
  EXPECT_EQ(v->variable, 1u);
  EXPECT_FALSE(v->derivative);
  EXPECT_EQ(a->variable, 1u);
  EXPECT_TRUE(a->derivative);
  EXPECT_FALSE(unknowns.find(t.m));
  EXPECT_FALSE(unknowns.find(t.ctx.symbol("made later")));  // an id past the table
}

TEST(UnknownSymbols, ASymbolListedTwiceIsTheLastVariableNamingIt) {
  TinyDae t;
  t.dae.variables[1].y = t.dx;  // x's y' is also der(x)'s y
  kernel::UnknownSymbols unknowns(t.dae);
  auto dx = unknowns.find(t.dx);
  ASSERT_TRUE(dx);
  EXPECT_EQ(dx->variable, 1u);
  EXPECT_FALSE(dx->derivative);
}

// A builder given the unknowns loads y and y' where they are used; its own bindings win.
TEST(UnknownSymbols, ProgramBuilderLoadsThemAndItsOwnBindingsWin) {
  TinyDae t;
  kernel::UnknownSymbols unknowns(t.dae);
  kernel::ProgramBuilder b("test");
  b.bindUnknowns(unknowns);
  b.bindLoad(t.x, Op::LoadP, 0);
  b.store(0, b.lower(t.ctx.add(t.ctx.mul(t.x, t.a), t.v)));
  kernel::Program p = b.finish(1);
  EXPECT_TRUE(b.unboundSymbols().empty());
  std::vector<double> y = {10, 2}, yp = {20, 3}, params = {5}, out(1);
  kernel::interpret(p, {.y = y.data(), .yp = yp.data(), .p = params.data()}, out);
  EXPECT_EQ(out[0], 5.0 * 3 + 2);  // x from p[0], der(der(x)) = yp[1], der(x) = y[1]
}

}  // namespace
}  // namespace qdot::test
