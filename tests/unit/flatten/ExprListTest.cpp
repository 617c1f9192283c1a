// ExprList, the element list of a flattened Value: a scalar stays inline, more elements move to
// the heap; copies, moves and appends keep the elements in order across that boundary.
#include <gtest/gtest.h>

#include <vector>

#include "flatten/Flattener.h"

namespace qdot::flat {
namespace {

std::vector<sym::Expr> elements(const ExprList& list) { return {list.begin(), list.end()}; }

class ExprListTest : public ::testing::Test {
 protected:
  sym::Context ctx;
  sym::Expr a = ctx.symbol("a"), b = ctx.symbol("b"), c = ctx.symbol("c");
};

TEST_F(ExprListTest, GrowsFromEmptyThroughOneElement) {
  ExprList list;
  EXPECT_TRUE(list.empty());
  list.push_back(a);
  EXPECT_EQ(elements(list), (std::vector{a}));
  list.push_back(b);
  list.push_back(c);
  EXPECT_EQ(elements(list), (std::vector{a, b, c}));
  list[1] = c;
  EXPECT_EQ(list[1], c);
}

TEST_F(ExprListTest, ConstructorsFillAdoptAndList) {
  EXPECT_EQ(elements(ExprList(0, a)), (std::vector<sym::Expr>{}));
  EXPECT_EQ(elements(ExprList(1, a)), (std::vector{a}));
  EXPECT_EQ(elements(ExprList(3, b)), (std::vector{b, b, b}));
  EXPECT_EQ(elements(ExprList(std::vector{c})), (std::vector{c}));
  EXPECT_EQ(elements(ExprList(std::vector{a, c})), (std::vector{a, c}));
  EXPECT_EQ(elements(ExprList{b, a}), (std::vector{b, a}));
}

TEST_F(ExprListTest, CopiesAndMovesAreIndependent) {
  for (ExprList original : {ExprList{a}, ExprList{a, b, c}}) {
    std::vector<sym::Expr> expected = elements(original);
    ExprList copy = original;
    copy[0] = c;
    EXPECT_EQ(elements(original), expected);
    ExprList moved = std::move(original);
    EXPECT_EQ(elements(moved), expected);
    EXPECT_TRUE(original.empty());  // NOLINT(bugprone-use-after-move): a moved-from list is empty
    original = moved;
    EXPECT_EQ(elements(original), expected);
  }
}

TEST_F(ExprListTest, AppendCrossesFromInlineToHeap) {
  ExprList list{a};
  list.append(ExprList{b});
  list.append(ExprList{});
  list.append(ExprList{c, a});
  EXPECT_EQ(elements(list), (std::vector{a, b, c, a}));
}

}  // namespace
}  // namespace qdot::flat
