// DummyDerivativeModel: the square system IDA integrates for a model whose index was reduced
// (compiler/dae/IndexReduction.h), or whose F has rows used only at t0 (initial equations: always
// left out here). The compiled residual has more rows than unknowns: every
// equation, its differentiated forms and every link row der(x) = x1 of the derivative chains. The
// dummy derivative method (Mattsson & Söderlind 1993) keeps all rows but one link per derivative of
// an equation: the dropped link's derivative is a "dummy" (an algebraic unknown) and its variable
// is no longer a state. Which ones is chosen from the values, level by level from the most
// differentiated equations down, as the columns of the differentiated equations' Jacobian that
// are best conditioned (QR with column pivoting) — and chosen again during the run when the
// current choice becomes much worse than the best one (a pendulum passing the horizontal), as
// Modelica tools do with dynamic state selection.
#pragma once

#include <string>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot::rt {

class DummyDerivativeModel;

/// The square model's table: a QdotModel* of it is a SquareTable*, so the entry points reach the
/// object (residual, Jacobian) and the full model (everything else, forwarded unchanged).
struct SquareTable {
  QdotModel model;
  DummyDerivativeModel* owner;
  const QdotModel* full;
};

class DummyDerivativeModel {
 public:
  /// `full` must outlive this object and have nResiduals > nVariables.
  explicit DummyDerivativeModel(const QdotModel& full);
  DummyDerivativeModel(const DummyDerivativeModel&) = delete;
  DummyDerivativeModel& operator=(const DummyDerivativeModel&) = delete;

  /// The square model with the current choice: nVariables rows, its own id vector
  /// (isDifferential) and Jacobian pattern; every other entry point is the full model's.
  const QdotModel& square() const { return table_.model; }

  /// Chooses the dummy derivatives at (t, y, y'). With `best`, takes the best-conditioned choice;
  /// otherwise changes the current one only when it has become much worse (hysteresis). Returns
  /// true if the choice (and so the square model's id vector and pattern) changed. Throws
  /// std::runtime_error when the differentiated equations cannot be solved for any choice (the
  /// constraints are dependent there) or the Jacobian cannot be evaluated.
  bool choose(double t, const double* y, const double* yp, const double* p, bool best);

  /// Per row of the full model: whether the square model keeps it.
  std::vector<char> keptRows() const;
  /// The current dummy derivatives, e.g. "der(y), der(der(y))".
  std::string dummyNames() const;
  /// How many times choose() changed the choice after the first one.
  int changes() const { return changes_; }

 private:
  struct Link {
    int row, variable, derivative;
  };

  static DummyDerivativeModel& of(const QdotModel* m) { return *reinterpret_cast<const SquareTable*>(m)->owner; }
  static int residual(const QdotModel*, double t, const double* y, const double* yp, const double* p, double* F);
  static int jacobian(const QdotModel*, double t, const double* y, const double* yp, const double* p, double cj,
                      double* values);

  /// Rows of the equations differentiated at least `level` times, at their (c - level + 1)-th derivative.
  std::vector<int> levelRows(int level) const;
  /// Level 1's candidates (chosenAbove null), or those one order below the dummies chosen a level up.
  std::vector<int> candidatesBelow(const std::vector<int>* chosenAbove) const;
  /// Per level, the chosen derivatives (variables), best-conditioned first; and the choice's quality
  /// (product over levels of |det| / product of row norms, in [0, 1]).
  std::vector<std::vector<int>> bestChoice(double& quality) const;
  double qualityOf(const std::vector<std::vector<int>>& choice) const;
  void apply(const std::vector<std::vector<int>>& choice);

  const QdotModel& full_;
  SquareTable table_;
  std::vector<Link> links_;
  std::vector<int> linkOfDerivative_;             // per variable: the link whose derivative it is, or -1
  std::vector<int> chainTops_;                    // level 1's candidates
  std::vector<std::vector<int>> rowsOfEquation_;  // per differentiated equation: e, e', …
  int levels_ = 0;

  std::vector<std::vector<int>> choice_;  // current dummies per level
  std::vector<double> jacobianYValues_;   // dF/dy at the last choose(), full pattern
  std::vector<int32_t> isDifferential_, columnStarts_, rowIndices_;
  std::vector<int32_t> squareRowOf_;      // full row -> square row, -1 if dropped
  std::vector<int32_t> fullEntryOf_;      // square nonzero -> full nonzero
  mutable std::vector<double> scratchF_, scratchJ_;
  int changes_ = -1;
  bool applied_ = false;
};

}  // namespace qdot::rt
