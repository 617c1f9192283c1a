// The Jacobian pattern checks every backend and the run time make before they use a compiled model
// (qdot/csc_pattern.hpp, ModelDescription::inconsistency, rt::checkModel): one tight pass, in two
// halves from 65 536 columns, that must refuse each kind of malformed pattern wherever it is — and
// the messages, found by a second walk, say which.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ida/ModelCheck.h"
#include "qdot/model_abi.h"
#include "qdot/csc_pattern.hpp"
#include "qdot/model_description.hpp"

namespace qdot {
namespace {

// A banded pattern of `columns` columns: column j holds rows j−1, j, j+1 (those in range).
struct Pattern {
  std::vector<int32_t> starts{0}, rows;
  explicit Pattern(int32_t columns) {
    for (int32_t j = 0; j < columns; ++j) {
      for (int32_t r = j - 1; r <= j + 1; ++r)
        if (r >= 0 && r < columns) rows.push_back(r);
      starts.push_back(static_cast<int32_t>(rows.size()));
    }
  }
  size_t columns() const { return starts.size() - 1; }
  bool valid(size_t rowCount) const {
    return cscPatternValid(starts.data(), rows.data(), columns(), rows.size(), rowCount);
  }
};

// A model of as many differential unknowns as the pattern has columns.
ModelDescription describing(const Pattern& p) {
  ModelDescription d;
  d.variableNames.assign(p.columns(), "x");
  d.isDifferential.assign(p.columns(), 1);
  d.fixed.assign(p.columns(), 0);
  d.jacobianColumnStarts = p.starts;
  d.jacobianRowIndices = p.rows;
  return d;
}

TEST(PatternCheck, AWellFormedPatternPassesSmallAndLarge) {
  for (int32_t n : {1, 5, 70000, 200001}) {
    Pattern p(n);
    EXPECT_TRUE(p.valid(p.columns())) << n;
  }
  Pattern empty(0);
  EXPECT_TRUE(cscPatternValid(empty.starts.data(), static_cast<const int32_t*>(nullptr), 0, 0, 0));
}

// Each defect in a column of the first half, of the second half, and in the last column of a
// large pattern (two threads), and of a small one (one).
TEST(PatternCheck, EveryKindOfDefectIsFoundInEitherHalf) {
  for (int32_t n : {7, 200001}) {
    Pattern good(n);
    for (int32_t j : {1, n / 2 + 3, n - 2}) {
      Pattern p = good;
      p.rows[p.starts[j]] = n;  // a row index past the last row
      EXPECT_FALSE(p.valid(n)) << "row out of range, n " << n << " column " << j;
      p = good;
      p.rows[p.starts[j]] = -1;  // negative
      EXPECT_FALSE(p.valid(n)) << "negative row, n " << n << " column " << j;
      p = good;
      std::swap(p.rows[p.starts[j]], p.rows[p.starts[j] + 1]);  // not ascending within the column
      EXPECT_FALSE(p.valid(n)) << "descending rows, n " << n << " column " << j;
      p = good;
      p.rows[p.starts[j] + 1] = p.rows[p.starts[j]];  // a row twice
      EXPECT_FALSE(p.valid(n)) << "repeated row, n " << n << " column " << j;
      p = good;
      std::swap(p.starts[j], p.starts[j + 1]);  // column starts that decrease
      EXPECT_FALSE(p.valid(n)) << "decreasing starts, n " << n << " column " << j;
    }
    Pattern p = good;
    p.starts.back() += 1;  // the last start is not the number of nonzeros
    EXPECT_FALSE(p.valid(n));
    p = good;
    p.starts[0] = 1;
    EXPECT_FALSE(p.valid(n));
  }
}

// A start past the nonzeros in the middle (monotone up to it, then back): refused without reading
// past the row array, and named by both messages.
TEST(PatternCheck, AStartPastTheNonzerosIsRefusedWithoutReadingPastThem) {
  Pattern p(100000);
  p.starts[50000] = static_cast<int32_t>(p.rows.size()) + 1000;
  EXPECT_FALSE(p.valid(p.columns()));
  EXPECT_EQ(describing(p).inconsistency(), "Jacobian column starts exceed the nonzeros");
}

TEST(PatternCheck, TheDescriptionNamesTheColumnOfABadRow) {
  ModelDescription d = describing(Pattern(70000));
  EXPECT_EQ(d.inconsistency(), "");
  d.jacobianRowIndices[d.jacobianColumnStarts[60000] + 1] = 70000;
  EXPECT_EQ(d.inconsistency(), "Jacobian row indices out of range or not ascending in column 60000");
}

TEST(PatternCheck, TheRunTimeNamesTheColumnOfABadRow) {
  Pattern p(70000);
  QdotModel m{};
  m.abiVersion = QDOT_MODEL_ABI_VERSION;
  auto noop = [](const QdotModel*, double, const double*, const double*, const double*, double*) { return 0; };
  m.parameters = [](const QdotModel*, const double*, const uint8_t*, double*) { return 0; };
  m.initialValues = [](const QdotModel*, const double*, double, double*, double*, double*) { return 0; };
  m.residual = noop;
  m.jacobian = [](const QdotModel*, double, const double*, const double*, const double*, double, double*) { return 0; };
  std::vector<const char*> names(p.columns(), "x");
  std::vector<int32_t> differential(p.columns(), 1);
  m.nVariables = static_cast<uint32_t>(p.columns());
  m.variableNames = names.data();
  m.isDifferential = differential.data();
  m.jacobianNonzeros = static_cast<uint32_t>(p.rows.size());
  m.jacobianColumnStarts = p.starts.data();
  m.jacobianRowIndices = p.rows.data();
  EXPECT_EQ(rt::checkModel(m), std::nullopt);
  p.rows[p.starts[40000] + 2] = p.rows[p.starts[40000] + 1];
  EXPECT_EQ(rt::checkModel(m),
            "the model table is invalid: Jacobian column 40000 has row indices that are not strictly ascending");
}

}  // namespace
}  // namespace qdot
