// NodeMap: the pointer-keyed table behind every memo. Its slots keep the arena's locality (a page of
// nodes maps to one window of slots), so check it on many neighbouring nodes: everything inserted is
// found, nothing else is, and growth, clear and move keep that.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {
namespace {

TEST(NodeMap, ManyNeighbouringNodes) {
  Context ctx;
  std::vector<Expr> nodes;
  Expr k = ctx.symbol("k");
  for (int i = 0; i < 20000; ++i) {
    Expr x = ctx.symbol("x" + std::to_string(i));
    nodes.push_back(x);
    nodes.push_back(ctx.mul(k, x));
    nodes.push_back(ctx.add(x, ctx.constant(i + 0.5)));
  }
  NodeMap<uint32_t> map;
  for (uint32_t i = 0; i < nodes.size(); i += 2) EXPECT_TRUE(map.insert(nodes[i], i).second);
  EXPECT_EQ(map.size(), (nodes.size() + 1) / 2);
  for (uint32_t i = 0; i < nodes.size(); ++i) {
    const uint32_t* v = map.find(nodes[i]);
    if (i % 2 == 0) {
      ASSERT_NE(v, nullptr);
      EXPECT_EQ(*v, i);
    } else {
      EXPECT_EQ(v, nullptr);
    }
  }
  auto [again, inserted] = map.insert(nodes[0], 7);
  EXPECT_FALSE(inserted);
  EXPECT_EQ(*again, 0u);

  NodeMap<uint32_t> moved = std::move(map);
  EXPECT_EQ(moved.size(), (nodes.size() + 1) / 2);
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(map.find(nodes[0]), nullptr);
  EXPECT_NE(moved.find(nodes[2]), nullptr);
  moved.clear();
  EXPECT_EQ(moved.size(), 0u);
  EXPECT_EQ(moved.find(nodes[2]), nullptr);
  EXPECT_TRUE(moved.insert(nodes[1], 1).second);
  EXPECT_EQ(*moved.find(nodes[1]), 1u);
}

}  // namespace
}  // namespace qdot::sym
