// KLU's band ordering (ida/KluOrdering.h): reverse Cuthill–McKee finds the band hidden in a
// scrambled banded pattern, leaves a 2-D grid to COLAMD, copes with components, empty columns and
// the smallest sizes; KLU factors in the order it is given (whole matrix and BTF blocks); and a
// session solving a scrambled heat chain uses the band and still meets the closed-form solution.
#include <gtest/gtest.h>

#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "HandModels.h"
#include "ida/KluOrdering.h"
#include "sim/Simulation.h"

namespace qdot::rt::test {
namespace {

/// A pattern built from (row, column) entries, in CSC form.
struct Pattern {
  std::vector<int64_t> starts, rows;
  explicit Pattern(int64_t n, std::vector<std::pair<int64_t, int64_t>> entries) : starts(n + 1, 0) {
    std::sort(entries.begin(), entries.end(), [](auto a, auto b) { return std::pair(a.second, a.first) < std::pair(b.second, b.first); });
    for (auto [r, c] : entries) ++starts[c + 1], rows.push_back(r);
    for (int64_t c = 0; c < n; ++c) starts[c + 1] += starts[c];
  }
  CscPattern csc() const { return {starts, rows}; }
};

std::vector<int64_t> identity(int64_t n) {
  std::vector<int64_t> p(n);
  for (int64_t i = 0; i < n; ++i) p[i] = i;
  return p;
}

/// A random permutation of 0..n-1 (fixed seed): where each unknown of a banded model is stored.
std::vector<int64_t> scramble(int64_t n, unsigned seed = 7) {
  std::vector<int64_t> p = identity(n);
  std::shuffle(p.begin(), p.end(), std::mt19937(seed));
  return p;
}

/// Entries |i − j| <= band of an n × n matrix, both unknowns relabelled by `at`.
std::vector<std::pair<int64_t, int64_t>> banded(int64_t n, int64_t band, const std::vector<int64_t>& at) {
  std::vector<std::pair<int64_t, int64_t>> e;
  for (int64_t i = 0; i < n; ++i)
    for (int64_t j = std::max<int64_t>(0, i - band); j <= std::min(n - 1, i + band); ++j) e.emplace_back(at[i], at[j]);
  return e;
}

bool isPermutation(std::vector<int64_t> order, int64_t n) {
  std::sort(order.begin(), order.end());
  for (int64_t k = 0; k < n; ++k)
    if (order.size() != static_cast<std::size_t>(n) || order[k] != k) return false;
  return true;
}

TEST(ReverseCuthillMcKee, RecoversTheBandOfAScrambledBandedPattern) {
  const int64_t n = 2000;
  for (int64_t band : {1, 2, 3}) {
    Pattern a(n, banded(n, band, scramble(n)));
    ASSERT_GT(permutedBandwidth(a.csc(), identity(n)), 100);  // the scrambling hides the band
    std::vector<int64_t> order = reverseCuthillMcKee(a.csc());
    ASSERT_TRUE(isPermutation(order, n));
    EXPECT_EQ(permutedBandwidth(a.csc(), order), band) << "half bandwidth " << band;
  }
}

// Only the entries below the diagonal and on it: the ordering works on A + Aᵀ, a path.
TEST(ReverseCuthillMcKee, SymmetrizesAnUnsymmetricPattern) {
  const int64_t n = 500;
  std::vector<int64_t> at = scramble(n, 3);
  std::vector<std::pair<int64_t, int64_t>> e;
  for (int64_t i = 0; i < n; ++i) {
    e.emplace_back(at[i], at[i]);
    if (i > 0) e.emplace_back(at[i], at[i - 1]);
  }
  Pattern a(n, e);
  std::vector<int64_t> order = reverseCuthillMcKee(a.csc());
  EXPECT_EQ(permutedBandwidth(a.csc(), order), 1);
  ASSERT_TRUE(chooseBandOrdering(a.csc()));
}

// 5-point Laplacian on a 100 × 100 grid: RCM's band is about the side, far from bounded fill.
TEST(ReverseCuthillMcKee, LeavesATwoDimensionalGridToColamd) {
  const int64_t side = 100, n = side * side;
  std::vector<std::pair<int64_t, int64_t>> e;
  for (int64_t r = 0; r < side; ++r)
    for (int64_t c = 0; c < side; ++c) {
      int64_t v = r * side + c;
      e.emplace_back(v, v);
      if (r > 0) e.emplace_back(v, v - side), e.emplace_back(v - side, v);
      if (c > 0) e.emplace_back(v, v - 1), e.emplace_back(v - 1, v);
    }
  Pattern a(n, e);
  int64_t band = permutedBandwidth(a.csc(), reverseCuthillMcKee(a.csc()));
  EXPECT_GE(band, side - 1);
  EXPECT_LE(band, 2 * side);
  EXPECT_FALSE(bandIsNarrow(n, static_cast<int64_t>(a.rows.size()), band));
  EXPECT_FALSE(chooseBandOrdering(a.csc()));
}

// Two scrambled paths, an isolated unknown with its diagonal and one with an empty column: each
// component is numbered in one piece, and the band stays 1.
TEST(ReverseCuthillMcKee, NumbersEachComponentInOnePiece) {
  const int64_t n = 302;
  std::vector<int64_t> at = scramble(n, 11);
  std::vector<std::pair<int64_t, int64_t>> e;
  for (int64_t i = 0; i < 150; ++i) {
    e.emplace_back(at[i], at[i]), e.emplace_back(at[150 + i], at[150 + i]);
    if (i > 0) e.emplace_back(at[i - 1], at[i]), e.emplace_back(at[149 + i], at[150 + i]);
  }
  e.emplace_back(at[300], at[300]);  // at[301]: a column and a row without entries
  Pattern a(n, e);
  std::vector<int64_t> order = reverseCuthillMcKee(a.csc());
  ASSERT_TRUE(isPermutation(order, n));
  EXPECT_EQ(permutedBandwidth(a.csc(), order), 1);
  std::vector<int64_t> position(n);
  for (int64_t k = 0; k < n; ++k) position[order[k]] = k;
  for (int64_t first : {0, 150}) {
    auto [lo, hi] = std::minmax_element(at.begin() + first, at.begin() + first + 150,
                                        [&](int64_t u, int64_t v) { return position[u] < position[v]; });
    EXPECT_EQ(position[*hi] - position[*lo], 149) << "the path starting at " << first;
  }
}

TEST(ReverseCuthillMcKee, HandlesTheSmallestPatterns) {
  EXPECT_TRUE(reverseCuthillMcKee(Pattern(0, {}).csc()).empty());
  Pattern one(1, {{0, 0}});
  EXPECT_EQ(reverseCuthillMcKee(one.csc()), std::vector<int64_t>{0});
  auto band = chooseBandOrdering(one.csc());
  ASSERT_TRUE(band);
  EXPECT_EQ(band->bandwidth, 0);
  Pattern empty(1, {});  // a 1 × 1 pattern without its entry: nothing to factor, no band chosen
  EXPECT_EQ(reverseCuthillMcKee(empty.csc()), std::vector<int64_t>{0});
  EXPECT_FALSE(chooseBandOrdering(empty.csc()));
}

// A pattern whose own order already has the smallest possible bandwidth (⌈d/2⌉ for its densest row
// or column) keeps that order without RCM's searches; one that does not is searched as before.
TEST(ReverseCuthillMcKee, AnOwnOrderThatCannotBeBeatenIsKept) {
  const int64_t n = 200;
  Pattern tridiagonal(n, banded(n, 1, identity(n)));
  EXPECT_EQ(naturalBandwidth(tridiagonal.csc()), 1);
  EXPECT_EQ(bandwidthLowerBound(tridiagonal.csc()), 1);
  auto kept = chooseBandOrdering(tridiagonal.csc());
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->order, identity(n));
  EXPECT_EQ(kept->bandwidth, 1);
  Pattern pentadiagonal(n, banded(n, 2, identity(n)));  // 4 neighbours: no order below 2
  EXPECT_EQ(bandwidthLowerBound(pentadiagonal.csc()), 2);
  EXPECT_EQ(chooseBandOrdering(pentadiagonal.csc())->order, identity(n));
  // scrambled: its own bandwidth is far above the bound, RCM finds the band again
  Pattern scrambled(n, banded(n, 1, scramble(n)));
  EXPECT_GT(naturalBandwidth(scrambled.csc()), 1);
  auto searched = chooseBandOrdering(scrambled.csc());
  ASSERT_TRUE(searched);
  EXPECT_NE(searched->order, identity(n));
  EXPECT_EQ(searched->bandwidth, 1);
  // an arrow (row and column 0 full): the bound is ⌈(n − 1)/2⌉ from either side
  std::vector<std::pair<int64_t, int64_t>> arrow;
  for (int64_t i = 0; i < 9; ++i) arrow.emplace_back(i, i), arrow.emplace_back(0, i), arrow.emplace_back(i, 0);
  EXPECT_EQ(bandwidthLowerBound(Pattern(9, arrow).csc()), 4);
}

TEST(BandIsNarrow, BoundsTheFillOfPartialPivotingByTenTimesA) {
  // n (3b + 1) <= 10 nnz: at 3 entries per column b = 9 passes and b = 10 does not.
  EXPECT_TRUE(bandIsNarrow(100, 300, 9));
  EXPECT_FALSE(bandIsNarrow(100, 300, 10));
  EXPECT_TRUE(bandIsNarrow(2'000'000, 8'000'000, 3));  // the spring chain at 10⁶ masses
}

// --- KLU takes the ordering ------------------------------------------------------------------

/// KLU (through SUNDIALS) on a CSC matrix: solves A x = b and exposes what it analysed.
struct KluSystem {
  SUNContext context = nullptr;
  SUNMatrix A = nullptr;
  N_Vector x = nullptr, b = nullptr;
  SUNLinearSolver solver = nullptr;
  KluSystem(const Pattern& p, const std::vector<double>& values) {
    auto n = static_cast<sunindextype>(p.starts.size() - 1);
    SUNContext_Create(nullptr, &context);
    A = SUNSparseMatrix(n, n, static_cast<sunindextype>(p.rows.size()), CSC_MAT, context);
    std::copy(p.starts.begin(), p.starts.end(), SUNSparseMatrix_IndexPointers(A));
    std::copy(p.rows.begin(), p.rows.end(), SUNSparseMatrix_IndexValues(A));
    std::copy(values.begin(), values.end(), SUNSparseMatrix_Data(A));
    x = N_VNew_Serial(n, context);
    b = N_VNew_Serial(n, context);
    solver = SUNLinSol_KLU(x, A, context);
  }
  ~KluSystem() {
    SUNLinSolFree(solver);
    N_VDestroy(x), N_VDestroy(b);
    SUNMatDestroy(A);
    SUNContext_Free(&context);
  }
  klu_l_common& common() { return *SUNLinSol_KLUGetCommon(solver); }
  /// x from A x = A·expected; false if KLU failed.
  bool solve(const Pattern& p, const std::vector<double>& values, const std::vector<double>& expected) {
    double* rhs = N_VGetArrayPointer(b);
    std::fill(rhs, rhs + expected.size(), 0.0);
    for (std::size_t c = 0; c + 1 < p.starts.size(); ++c)
      for (int64_t k = p.starts[c]; k < p.starts[c + 1]; ++k) rhs[p.rows[k]] += values[k] * expected[c];
    return SUNLinSolSetup(solver, A) == 0 && SUNLinSolSolve(solver, A, x, b, 0.0) == 0;
  }
  double error(const std::vector<double>& expected) const {
    double worst = 0;
    for (std::size_t i = 0; i < expected.size(); ++i)
      worst = std::max(worst, std::abs(N_VGetArrayPointer(x)[i] - expected[i]));
    return worst;
  }
};

/// Values for a pattern: 4 on the diagonal, −1 elsewhere (diagonally dominant up to 4 neighbours).
std::vector<double> laplacianValues(const Pattern& p) {
  std::vector<double> v(p.rows.size());
  for (std::size_t c = 0; c + 1 < p.starts.size(); ++c)
    for (int64_t k = p.starts[c]; k < p.starts[c + 1]; ++k) v[k] = p.rows[k] == static_cast<int64_t>(c) ? 4.0 : -1.0;
  return v;
}

std::vector<double> ramp(int64_t n) {
  std::vector<double> x(n);
  for (int64_t i = 0; i < n; ++i) x[i] = 1.0 + 0.01 * static_cast<double>(i);
  return x;
}

TEST(KluBandOrdering, KluFactorsTheWholeMatrixInTheGivenOrder) {
  const int64_t n = 400;
  Pattern a(n, banded(n, 1, scramble(n, 5)));
  std::vector<double> values = laplacianValues(a);
  std::optional<BandOrdering> band = chooseBandOrdering(a.csc());
  ASSERT_TRUE(band);
  KluSystem klu(a, values);
  useBandOrdering(klu.common(), *band);
  ASSERT_TRUE(klu.solve(a, values, ramp(n)));
  EXPECT_LT(klu.error(ramp(n)), 1e-12);
  klu_l_symbolic* symbolic = SUNLinSol_KLUGetSymbolic(klu.solver);
  EXPECT_EQ(symbolic->ordering, 3);
  EXPECT_EQ(symbolic->nblocks, 1);
  EXPECT_TRUE(std::equal(band->order.begin(), band->order.end(), symbolic->Q));  // the column order given
  klu_l_numeric* numeric = SUNLinSol_KLUGetNumeric(klu.solver);
  EXPECT_LE(numeric->lnz + numeric->unz, 4 * n);  // no fill beyond the band
}

// With BTF the callback meets each diagonal block (in BTF's numbering) and orders it by RCM itself:
// two scrambled tridiagonal blocks, the second coupled to the first in one direction only.
TEST(KluBandOrdering, OrdersEachBlockOfTheBlockTriangularForm) {
  const int64_t half = 200, n = 2 * half;
  std::vector<int64_t> at = scramble(n, 9);
  std::vector<std::pair<int64_t, int64_t>> e;
  for (int64_t block : {0, 1})
    for (int64_t i = 0; i < half; ++i)
      for (int64_t j = std::max<int64_t>(0, i - 1); j <= std::min(half - 1, i + 1); ++j)
        e.emplace_back(at[block * half + i], at[block * half + j]);
  for (int64_t i = 0; i < half; i += 7) e.emplace_back(at[half + i], at[i]);  // block 1 reads block 0
  Pattern a(n, e);
  std::vector<double> values = laplacianValues(a);
  std::optional<BandOrdering> band = chooseBandOrdering(a.csc());
  ASSERT_TRUE(band);
  KluSystem klu(a, values);
  useBandOrdering(klu.common(), *band);
  klu.common().btf = 1;
  ASSERT_TRUE(klu.solve(a, values, ramp(n)));
  EXPECT_LT(klu.error(ramp(n)), 1e-12);
  klu_l_symbolic* symbolic = SUNLinSol_KLUGetSymbolic(klu.solver);
  EXPECT_EQ(symbolic->ordering, 3);
  EXPECT_EQ(symbolic->nblocks, 2);
  // In RCM order each tridiagonal block factors with 2 entries per column of L and 2 of
  // U (diagonals included); in the scrambled order it was given, the fill was 50 % more.
  klu_l_numeric* numeric = SUNLinSol_KLUGetNumeric(klu.solver);
  EXPECT_LE(numeric->lnz + numeric->unz, 4 * n);
}

// --- a session -------------------------------------------------------------------------------

/// heatChain(n) with cell i stored as unknown at[i]: the same tridiagonal system, scrambled.
HandModel scrambledHeatChain(int n, std::vector<int64_t> at) {
  HandModel m;
  m.name = "scrambled chain";
  double h = 1.0 / (n + 1), k = 1.0 / (h * h);
  m.variables.resize(n), m.start.resize(n), m.differential.assign(n, 1);
  for (int i = 0; i < n; ++i) {
    m.variables[at[i]] = "T[" + std::to_string(i + 1) + "]";
    m.start[at[i]] = std::sin(std::numbers::pi * (i + 1) * h);
    for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j) m.entries.emplace_back(at[i], at[j]);
  }
  m.residual = [n, k, at](double, const double* y, const double* yp, const double*, double* F) {
    for (int i = 0; i < n; ++i) {
      double left = i > 0 ? y[at[i - 1]] : 0, right = i + 1 < n ? y[at[i + 1]] : 0;
      F[at[i]] = yp[at[i]] - k * (left - 2 * y[at[i]] + right);
    }
    return 0;
  };
  m.jacobian = [n, k, at](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    for (int i = 0; i < n; ++i) {
      J(at[i], at[i]) = cj + 2 * k;
      if (i > 0) J(at[i], at[i - 1]) = -k;
      if (i + 1 < n) J(at[i], at[i + 1]) = -k;
    }
    return 0;
  };
  return m;
}

// A heat model from t = 0 to `stop`, rows every `interval`, at `rtol`; large enough for KLU. Returns
// the largest |value − exact(t, unknown)| over the rows written (and the session's result in `r`).
double worstErrorOnKlu(HandModel& model, int unknowns, double stop, double interval, double rtol,
                       const std::function<double(double, int)>& exact, SimulationResult& r) {
  MemorySink sink;
  SimulationSettings s;
  s.stop = stop, s.interval = interval, s.rtol = rtol;
  r = simulate(model.abi(), s, sink);
  EXPECT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.linearSolver, LinearSolverKind::Klu);
  double worst = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k)
    for (int v = 0; v < unknowns; ++v) worst = std::max(worst, std::abs(sink.rows[k][v] - exact(sink.times[k], v)));
  EXPECT_EQ(sink.rows.size(), static_cast<std::size_t>(std::lround(stop / interval)) + 1);
  return worst;
}

// Reference: cell i at exp(−λt) sin(πih), as in PhysicsTest's HeatChain; the scrambling hides
// the tridiagonal band, which RCM finds again (half bandwidth 1).
void expectScrambledChainSolvedInItsBand(int n, unsigned seed, double stop, double interval) {
  const double rtol = 1e-7, h = 1.0 / (n + 1);
  const double lambda = 4.0 / (h * h) * std::pow(std::sin(std::numbers::pi * h / 2), 2);
  std::vector<int64_t> at = scramble(n, seed);
  std::vector<int> cellOf(n);  // unknown at[i] is cell i
  for (int i = 0; i < n; ++i) cellOf[at[i]] = i;
  HandModel model = scrambledHeatChain(n, at);
  SimulationResult r;
  double worst = worstErrorOnKlu(model, n, stop, interval, rtol, [&](double t, int v) {
    return std::exp(-lambda * t) * std::sin(std::numbers::pi * (cellOf[v] + 1) * h);
  }, r);
  ASSERT_TRUE(r.bandwidth);
  EXPECT_EQ(*r.bandwidth, 1);
  EXPECT_FALSE(r.blockTriangular);
  EXPECT_LT(worst, 100 * rtol);
}

TEST(KluBandOrdering, ASessionSolvesAScrambledChainInItsBand) { expectScrambledChainSolvedInItsBand(3000, 13, 0.2, 0.05); }

// The same above 20 000 unknowns, where the session orders the pattern on another thread while it
// computes the start values (IdaSession's orderAhead): the same band, the same accuracy.
TEST(KluBandOrdering, ALargeSessionOrdersItsChainAhead) { expectScrambledChainSolvedInItsBand(25000, 5, 0.02, 0.01); }

/// Heat conduction on an m × m grid of cells (5-point Laplacian, zero at the border), started in
/// its lowest eigenmode sin(πih) sin(πjh): it decays as exp(−2λt), λ = 4/h² sin²(πh/2).
HandModel heatGrid(int m) {
  HandModel g;
  g.name = "grid";
  double h = 1.0 / (m + 1), k = 1.0 / (h * h);
  auto id = [m](int i, int j) { return i * m + j; };
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      g.variables.push_back("T[" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "]");
      g.differential.push_back(1);
      g.start.push_back(std::sin(std::numbers::pi * (i + 1) * h) * std::sin(std::numbers::pi * (j + 1) * h));
      g.entries.emplace_back(id(i, j), id(i, j));
      if (i > 0) g.entries.emplace_back(id(i, j), id(i - 1, j)), g.entries.emplace_back(id(i - 1, j), id(i, j));
      if (j > 0) g.entries.emplace_back(id(i, j), id(i, j - 1)), g.entries.emplace_back(id(i, j - 1), id(i, j));
    }
  auto at = [m](const double* y, int i, int j) { return i < 0 || j < 0 || i >= m || j >= m ? 0.0 : y[i * m + j]; };
  g.residual = [m, k, at](double, const double* y, const double* yp, const double*, double* F) {
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        F[i * m + j] = yp[i * m + j] - k * (at(y, i - 1, j) + at(y, i + 1, j) + at(y, i, j - 1) + at(y, i, j + 1) -
                                            4 * y[i * m + j]);
    return 0;
  };
  g.jacobian = [m, k](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        int v = i * m + j;
        J(v, v) = cj + 4 * k;
        if (i > 0) J(v, v - m) = J(v - m, v) = -k;
        if (j > 0) J(v, v - 1) = J(v - 1, v) = -k;
      }
    return 0;
  };
  return g;
}

// A 2-D grid is no narrow band: KLU keeps COLAMD (and BTF), and the session says so.
TEST(KluBandOrdering, ASessionOnAGridKeepsColamd) {
  const int m = 40;
  const double rtol = 1e-7, h = 1.0 / (m + 1);
  const double lambda = 4.0 / (h * h) * std::pow(std::sin(std::numbers::pi * h / 2), 2);
  HandModel model = heatGrid(m);
  SimulationResult r;
  double worst = worstErrorOnKlu(model, m * m, 0.01, 0.005, rtol, [&](double t, int v) {
    return std::exp(-2 * lambda * t) * model.start[v];
  }, r);
  EXPECT_FALSE(r.bandwidth);
  EXPECT_TRUE(r.blockTriangular);
  EXPECT_LT(worst, 100 * rtol);
}

}  // namespace
}  // namespace qdot::rt::test
