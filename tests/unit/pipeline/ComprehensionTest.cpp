// Array comprehensions as flattening expands them: with two iterators the first is the first
// dimension, elements that are arrays add their shape after the iterators', and elements of
// different shapes are an error at the comprehension (as for an array literal).
#include <sstream>
#include <string>

#include "CompiledModel.h"

namespace qdot::test {
namespace {

// y = {...} of constants makes every y[...] an alias of its value: a result column.
double resultColumn(CompiledModel& m, const std::string& name) {
  for (const auto& o : m.dae().outputs)
    if (o.name == name) return m.eval(o.value);
  ADD_FAILURE() << "no result column " << name;
  return 0.0;
}

TEST(Comprehension, TwoIteratorsAreRowsAndColumns) {
  CompiledModel m("two", R"(
model Two
  Real y[2, 3];
equation
  y = {10*i + j for i in 1:2, j in 1:3};
end Two;)");
  ASSERT_TRUE(m.ok());
  for (int i = 1; i <= 2; ++i)
    for (int j = 1; j <= 3; ++j)
      EXPECT_EQ(resultColumn(m, "y[" + std::to_string(i) + "," + std::to_string(j) + "]"), 10 * i + j);
}

TEST(Comprehension, ArrayElementsAddTheirShape) {
  CompiledModel m("rows", R"(
model Rows
  Real z[3, 2];
equation
  z = {{i, 10*i} for i in 1:3};
end Rows;)");
  ASSERT_TRUE(m.ok());
  for (int i = 1; i <= 3; ++i) {
    EXPECT_EQ(resultColumn(m, "z[" + std::to_string(i) + ",1]"), i);
    EXPECT_EQ(resultColumn(m, "z[" + std::to_string(i) + ",2]"), 10 * i);
  }
}

TEST(Comprehension, ElementsOfDifferentShapesAreAnError) {
  driver::Compilation c;
  EXPECT_FALSE(driver::compileSource(c, "shapes.qd", R"(model Shapes
  Real w[3, 2];
equation
  w = {if i < 3 then {i, i} else {i, i, i} for i in 1:3};
end Shapes;)", "", driver::Stage::Dae));
  ASSERT_EQ(c.diags.diagnostics().size(), 1u);
  const Diagnostic& d = c.diags.diagnostics().front();
  EXPECT_EQ(d.code, DiagCode::E0307);
  EXPECT_EQ(d.message, "array elements have different shapes: [2] and [3]");
  LineCol at = c.sources.lineCol(d.range.file, d.range.begin);
  EXPECT_EQ(at.line, 4u);
  EXPECT_EQ(at.col, 7u);
}

}  // namespace
}  // namespace qdot::test
