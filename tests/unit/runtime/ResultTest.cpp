// qdot::Result and ModelPtr (qdot/result.hpp): a value or the reason there is none; a model owned
// by a ModelPtr is destroyed exactly once, through its own destroy().
#include <gtest/gtest.h>

#include <memory>

#include "qdot/result.hpp"

namespace qdot::test {
namespace {

Result<std::unique_ptr<int>> half(int x) {
  if (x % 2) return Error{"odd: " + std::to_string(x)};
  return std::make_unique<int>(x / 2);
}

TEST(Result, HoldsTheValueOrTheError) {
  Result<std::unique_ptr<int>> ok = half(8);
  ASSERT_TRUE(ok.ok());
  EXPECT_TRUE(static_cast<bool>(ok));
  EXPECT_EQ(*ok.value(), 4);
  EXPECT_EQ(ok.error(), "");
  std::unique_ptr<int> taken = std::move(ok).value();  // move-only values can be taken out
  EXPECT_EQ(*taken, 4);
  Result<std::unique_ptr<int>> bad = half(3);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.error(), "odd: 3");
}

TEST(Result, StatusIsSuccessOrAReason) {
  Status fine;
  EXPECT_TRUE(fine.ok());
  Status failed = Error{"no"};
  EXPECT_FALSE(failed);
  EXPECT_EQ(failed.error(), "no");
}

struct Counted : QdotModel {
  int* destroyed = nullptr;
};

TEST(ModelPtr, DestroysTheModelOnceThroughItsTable) {
  int destroyed = 0;
  {
    auto* m = new Counted();
    m->destroyed = &destroyed;
    m->destroy = [](QdotModel* s) {
      auto* self = static_cast<Counted*>(s);
      ++*self->destroyed;
      delete self;
    };
    ModelPtr owned(m);
    ModelPtr moved = std::move(owned);
    EXPECT_EQ(destroyed, 0);
  }
  EXPECT_EQ(destroyed, 1);
}

}  // namespace
}  // namespace qdot::test
