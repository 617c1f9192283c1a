// Array comprehensions as flattening expands them: with two iterators the first is the first
// dimension, elements that are arrays add their shape after the iterators', and elements of
// different shapes are an error at the comprehension (as for an array literal).
#include <bit>
#include <cstdint>
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

// The start values of x[n, m] from {body for i in 1:n, j in 1:m}, as numbers (flatten folds a
// numeric body without symbolic intermediates).
std::vector<double> startValues(const std::string& body) {
  driver::Compilation c;
  std::string text = "model S\n  parameter Integer n = 7;\n  constant Real c = 0.7;\n  coordinate Real x[7, 5](start = {" + body +
                     " for i in 1:7, j in 1:5});\nmechanics\n  kinetic = sum(der(x[i, j])^2 for i in 1:7, j in 1:5);\nend S;\n";
  EXPECT_TRUE(driver::compileSource(c, "start.qd", text, "", driver::Stage::Flatten)) << text;
  std::vector<double> values;
  if (!c.flat) return values;
  for (const auto& v : c.flat->variables)
    if (v.role == flat::VarRole::Coordinate && v.start) values.push_back(v.start->value);
  return values;
}

// Reference: the same body lowered symbolically, element by element (`if i > 0 then body else 0`
// folds to the body's value, and an if-expression takes it out of the numeric path): the values
// must be the same bit for bit, non-finite ones included. The numeric path also takes names that
// are numbers (an Integer parameter, a constant) and the built-in functions of one number.
TEST(Comprehension, ANumericBodyGivesTheValuesOfItsSymbolicLowering) {
  for (const char* body : {"0.01*i", "i/3 - j/7", "1/(i - 2)", "(i - 2)/(i - 2)", "-(i - 0.3*j)^2/7 + i*0.1",
                           "2^(i/3) - j", "i*0.1 - 0.3", "+i - -j", "(1e308*i)*(1e10*j)", "i - i + 0.5/j",
                           "sin(3.14159265358979*i/(n + 1))*cos(c*j)", "exp(-i/n) + log(j) - log10(i*j)",
                           "sqrt(i - 3) + abs(j - 2.5)*sign(i - 4)", "tanh(c*i) + atan(j) + asin(1/i) + acos(1/j)",
                           "sinh(i/7)/cosh(j/5) + tan(c) + sin(0)"}) {
    std::vector<double> numeric = startValues(body);
    std::vector<double> symbolic = startValues(std::string("if i > 0 then (") + body + ") else 0");
    ASSERT_EQ(numeric.size(), 35u) << body;
    ASSERT_EQ(symbolic.size(), 35u) << body;
    for (size_t k = 0; k < numeric.size(); ++k) {
      if (std::isnan(numeric[k]) && std::isnan(symbolic[k])) continue;
      EXPECT_EQ(std::bit_cast<uint64_t>(numeric[k]), std::bit_cast<uint64_t>(symbolic[k]))
          << body << ", element " << k << ": " << numeric[k] << " against " << symbolic[k];
    }
  }
}

}  // namespace
}  // namespace qdot::test
