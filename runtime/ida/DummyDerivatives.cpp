// The dummy derivative choice (see DummyDerivatives.h). Level 1 holds the most differentiated form
// of every differentiated equation, and its candidates are the chain tops (highest derivatives)
// those rows contain; level k holds the (c - k + 1)-th derivatives of the equations differentiated
// at least k times, and its candidates are one order below the dummies chosen at level k - 1.
#include "ida/DummyDerivatives.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ida/ModelCheck.h"

namespace qdot::rt {
namespace {

/// A choice is replaced when its quality falls below this fraction of the best one's: the
/// hysteresis keeps a pendulum near 45° from switching back and forth every step.
constexpr double kSwitchRatio = 0.5;

// The forwarders: everything but the residual and Jacobian is the full model's own entry point.
const QdotModel& fullOf(const QdotModel* square) { return *reinterpret_cast<const SquareTable*>(square)->full; }

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const QdotModel& f = fullOf(s);
  return f.parameters(&f, given, overridden, p);
}
int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const QdotModel& f = fullOf(s);
  return f.initialValues(&f, p, t0, y0, yp0, nominal);
}
int fixedStarts(const QdotModel* s, int32_t* fixed) {
  const QdotModel& f = fullOf(s);
  return f.fixedStarts(&f, fixed);
}
int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  const QdotModel& f = fullOf(s);
  return f.outputs(&f, t, y, yp, p, out);
}
int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  const QdotModel& f = fullOf(s);
  return f.invariants(&f, t, y, yp, p, out);
}
const char* lastError(const QdotModel* s) {
  const QdotModel& f = fullOf(s);
  return f.lastError ? f.lastError(&f) : "";
}

}  // namespace

DummyDerivativeModel::DummyDerivativeModel(const QdotModel& full) : full_(full) {
  static_assert(std::is_standard_layout_v<SquareTable>);
  table_.model = full;
  table_.owner = this;
  table_.full = &full;
  QdotModel& m = table_.model;
  m.nResiduals = full.nVariables;
  m.nDerivativeLinks = 0;
  m.nDifferentiatedEquations = 0;
  m.parameters = parameters;
  m.initialValues = initialValues;
  m.fixedStarts = full.fixedStarts ? fixedStarts : nullptr;
  m.residual = residual;
  m.jacobian = jacobian;
  m.outputs = full.outputs ? outputs : nullptr;
  m.invariants = full.invariants ? invariants : nullptr;
  m.lastError = lastError;
  m.destroy = nullptr;  // the full model is its owner's to destroy
  linkOfDerivative_.assign(full.nVariables, -1);
  for (uint32_t k = 0; k < full.nDerivativeLinks; ++k) {
    const int32_t* l = full.derivativeLinks + 3 * k;
    links_.push_back({l[0], l[1], l[2]});
    linkOfDerivative_[l[2]] = static_cast<int>(k);
  }
  // The chain tops: derivatives that have no derivative themselves (computed once: choose() runs
  // after every step).
  std::vector<char> hasDerivative(full.nVariables, 0);
  for (const Link& l : links_) hasDerivative[l.variable] = 1;
  for (int v = 0; v < static_cast<int>(full.nVariables); ++v)
    if (linkOfDerivative_[v] >= 0 && !hasDerivative[v]) chainTops_.push_back(v);
  for (uint32_t e = 0; e < full.nDifferentiatedEquations; ++e) {
    rowsOfEquation_.emplace_back(full.differentiatedRows + full.differentiatedRowStarts[e],
                                 full.differentiatedRows + full.differentiatedRowStarts[e + 1]);
    levels_ = std::max(levels_, static_cast<int>(rowsOfEquation_.back().size()) - 1);
  }
  scratchF_.resize(full.nResiduals);
  scratchJ_.resize(full.jacobianNonzeros);
  jacobianYValues_.resize(full.jacobianNonzeros);
}

std::vector<int> DummyDerivativeModel::levelRows(int level) const {
  std::vector<int> rows;
  for (const auto& r : rowsOfEquation_) {
    int c = static_cast<int>(r.size()) - 1;
    if (c >= level) rows.push_back(r[c - level + 1]);
  }
  return rows;
}

namespace {

// Rows `rows` and columns `columns` of dF/dy (values in the full CSC pattern), dense.
Eigen::MatrixXd submatrix(const QdotModel& m, const std::vector<double>& values, const std::vector<int>& rows,
                          const std::vector<int>& columns) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(columns.size()));
  for (size_t j = 0; j < columns.size(); ++j)
    for (int32_t k = m.jacobianColumnStarts[columns[j]]; k < m.jacobianColumnStarts[columns[j] + 1]; ++k) {
      auto at = std::find(rows.begin(), rows.end(), m.jacobianRowIndices[k]);
      if (at != rows.end()) H(at - rows.begin(), static_cast<Eigen::Index>(j)) = values[k];
    }
  return H;
}

// |det(H_S)| / Π ‖row of H‖: 1 for orthogonal rows spanned by S, 0 when S is singular (Hadamard).
double conditionQuality(const Eigen::MatrixXd& H, const Eigen::MatrixXd& HS) {
  double q = std::abs(HS.determinant());
  for (Eigen::Index i = 0; i < H.rows(); ++i) {
    double norm = H.row(i).norm();
    if (norm == 0) return 0;
    q /= norm;
  }
  return q;
}

}  // namespace

std::vector<int> DummyDerivativeModel::candidatesBelow(const std::vector<int>* chosenAbove) const {
  std::vector<int> candidates;
  if (!chosenAbove) return chainTops_;  // level 1
  for (int d : *chosenAbove) {  // one order lower, where that is itself a derivative
    int below = links_[linkOfDerivative_[d]].variable;
    if (linkOfDerivative_[below] >= 0) candidates.push_back(below);
  }
  return candidates;
}

std::vector<std::vector<int>> DummyDerivativeModel::bestChoice(double& quality) const {
  std::vector<std::vector<int>> choice;
  quality = 1;
  for (int level = 1; level <= levels_; ++level) {
    std::vector<int> rows = levelRows(level);
    std::vector<int> candidates = candidatesBelow(level == 1 ? nullptr : &choice.back());
    Eigen::MatrixXd H = submatrix(full_, jacobianYValues_, rows, candidates);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(H);
    if (qr.rank() < static_cast<Eigen::Index>(rows.size()))
      throw std::runtime_error("the differentiated constraints cannot be solved for any of their derivatives "
                               "(the constraints are dependent here, or the mechanism is at a singular position)");
    std::vector<int> chosen;
    for (Eigen::Index k = 0; k < H.rows(); ++k) chosen.push_back(candidates[qr.colsPermutation().indices()[k]]);
    std::sort(chosen.begin(), chosen.end());
    quality *= conditionQuality(H, submatrix(full_, jacobianYValues_, rows, chosen));
    choice.push_back(std::move(chosen));
  }
  return choice;
}

double DummyDerivativeModel::qualityOf(const std::vector<std::vector<int>>& choice) const {
  double quality = 1;
  for (int level = 1; level <= levels_; ++level) {
    std::vector<int> rows = levelRows(level);
    const std::vector<int>& chosen = choice[level - 1];
    if (chosen.size() != rows.size()) return 0;
    std::vector<int> candidates = candidatesBelow(level == 1 ? nullptr : &choice[level - 2]);
    quality *= conditionQuality(submatrix(full_, jacobianYValues_, rows, candidates),
                                submatrix(full_, jacobianYValues_, rows, chosen));
  }
  return quality;
}

void DummyDerivativeModel::apply(const std::vector<std::vector<int>>& choice) {
  const uint32_t n = full_.nVariables;
  std::vector<char> dropped(full_.nResiduals, 0);
  for (uint32_t r = full_.nResiduals - full_.nInitialRows; r < full_.nResiduals; ++r) dropped[r] = 1;  // t0 only
  isDifferential_.assign(full_.isDifferential, full_.isDifferential + n);
  for (const Link& l : links_) isDifferential_[l.variable] = 1;
  for (const auto& level : choice)
    for (int d : level) {
      const Link& l = links_[linkOfDerivative_[d]];
      dropped[l.row] = 1;
      isDifferential_[l.variable] = 0;
    }
  squareRowOf_.assign(full_.nResiduals, -1);
  int32_t next = 0;
  for (uint32_t r = 0; r < full_.nResiduals; ++r)
    if (!dropped[r]) squareRowOf_[r] = next++;
  if (next != static_cast<int32_t>(n)) throw std::logic_error("dummy derivatives: the kept rows are not square");
  columnStarts_.assign(1, 0);
  rowIndices_.clear();
  fullEntryOf_.clear();
  for (uint32_t j = 0; j < n; ++j) {
    for (int32_t k = full_.jacobianColumnStarts[j]; k < full_.jacobianColumnStarts[j + 1]; ++k)
      if (int32_t row = squareRowOf_[full_.jacobianRowIndices[k]]; row >= 0) rowIndices_.push_back(row), fullEntryOf_.push_back(k);
    columnStarts_.push_back(static_cast<int32_t>(rowIndices_.size()));
  }
  QdotModel& m = table_.model;
  m.isDifferential = isDifferential_.data();
  m.jacobianNonzeros = static_cast<uint32_t>(rowIndices_.size());
  m.jacobianColumnStarts = columnStarts_.data();
  m.jacobianRowIndices = rowIndices_.data();
}

bool DummyDerivativeModel::choose(double t, const double* y, const double* yp, const double* p, bool best) {
  if (full_.jacobian(&full_, t, y, yp, p, 0.0, jacobianYValues_.data()) != 0)
    throw std::runtime_error("the Jacobian could not be evaluated to choose the dummy derivatives: " +
                             modelLastError(full_));
  double bestQuality = 0;
  std::vector<std::vector<int>> candidate = bestChoice(bestQuality);
  if (applied_ && candidate == choice_) return false;
  if (!choice_.empty() && !best && qualityOf(choice_) >= kSwitchRatio * bestQuality) return false;
  apply(candidate);
  choice_ = std::move(candidate);
  ++changes_;
  applied_ = true;
  return true;
}

std::vector<char> DummyDerivativeModel::keptRows() const {
  std::vector<char> kept(squareRowOf_.size());
  for (size_t r = 0; r < kept.size(); ++r) kept[r] = squareRowOf_[r] >= 0;
  return kept;
}

std::string DummyDerivativeModel::dummyNames() const {
  std::string s;
  for (const auto& level : choice_)
    for (int d : level) s += (s.empty() ? "" : ", ") + std::string(full_.variableNames[d]);
  return s;
}

int DummyDerivativeModel::residual(const QdotModel* self, double t, const double* y, const double* yp,
                                   const double* p, double* F) {
  DummyDerivativeModel& o = of(self);
  if (int rc = o.full_.residual(&o.full_, t, y, yp, p, o.scratchF_.data()); rc != 0) return rc;
  for (size_t r = 0; r < o.squareRowOf_.size(); ++r)
    if (o.squareRowOf_[r] >= 0) F[o.squareRowOf_[r]] = o.scratchF_[r];
  return 0;
}

int DummyDerivativeModel::jacobian(const QdotModel* self, double t, const double* y, const double* yp,
                                   const double* p, double cj, double* values) {
  DummyDerivativeModel& o = of(self);
  if (int rc = o.full_.jacobian(&o.full_, t, y, yp, p, cj, o.scratchJ_.data()); rc != 0) return rc;
  for (size_t k = 0; k < o.fullEntryOf_.size(); ++k) values[k] = o.scratchJ_[o.fullEntryOf_[k]];
  return 0;
}

}  // namespace qdot::rt
