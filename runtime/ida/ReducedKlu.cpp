// IDA's Newton matrix with its two-entry rows eliminated, the rest factored by KLU or, in a
// narrow band, by a band LU (ReducedKlu.h).
#include "ida/ReducedKlu.h"

#include <klu.h>
#include <sundials/sundials_math.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <new>

#include "ida/BandLu.h"

namespace qdot::rt {

namespace {

// S in the plan's band ordering, factored by BandLu: its positions in the band storage, made once.
struct BandedS {
  BandLu lu;
  std::vector<int64_t> order;        ///< position k holds S's index order[k]; empty: S's own order
  std::vector<int64_t> entryOffset;  ///< per entry of S: its place in lu.storage()
  std::vector<double> permuted;      ///< a right-hand side in band order (when `order` is not empty)
};

// A band LU computes every entry inside its band, KLU only the nonzeros and their fill: the band
// is used when at least a third of it is S's entries (a chain's tridiagonal S: all of it). A whole
// chain matrix (half bandwidth 3: 4 entries per column in a band of 7, 10 rows with U's fill)
// measured slower with SUNDIALS' band LU than with KLU (bench/README.md, session 20).
constexpr int64_t kBandFullness = 3;

// S in the band ordering, for BandLu: the band's lower and upper widths in that ordering (RCM's
// band is symmetric, a matrix's need not be) and where each entry of S goes; nullopt when the
// band is mostly zeros (above).
std::optional<BandedS> bandedS(const TwoEntryRows& rows, const BandOrdering& band) {
  int64_t n = rows.size();
  bool own = true;
  for (int64_t k = 0; k < n && own; ++k) own = band.order[static_cast<size_t>(k)] == k;
  std::vector<int64_t> position(own ? 0 : static_cast<size_t>(n));
  for (int64_t k = 0; k < n && !own; ++k) position[static_cast<size_t>(band.order[static_cast<size_t>(k)])] = k;
  auto at = [&](int64_t i) { return own ? i : position[static_cast<size_t>(i)]; };
  int64_t lower = 0, upper = 0;
  for (int64_t j = 0; j < n; ++j)
    for (int64_t e = rows.columnStarts[j]; e < rows.columnStarts[j + 1]; ++e) {
      int64_t d = at(rows.rowIndices[e]) - at(j);
      lower = std::max(lower, d), upper = std::max(upper, -d);
    }
  if (n * (lower + upper + 1) > kBandFullness * static_cast<int64_t>(rows.rowIndices.size())) return std::nullopt;
  BandedS s{BandLu(n, lower, upper), own ? std::vector<int64_t>{} : band.order, {}, {}};
  s.entryOffset.resize(rows.rowIndices.size());
  for (int64_t j = 0; j < n; ++j)
    for (int64_t e = rows.columnStarts[j]; e < rows.columnStarts[j + 1]; ++e)
      s.entryOffset[static_cast<size_t>(e)] = s.lu.offset(at(rows.rowIndices[e]), at(j));
  if (!own) s.permuted.assign(static_cast<size_t>(n), 0.0);
  return s;
}

struct Content {
  ReducedKluPlan plan;
  klu_l_common common{};
  klu_l_symbolic* symbolic = nullptr;
  klu_l_numeric* numeric = nullptr;
  std::vector<double> values;        // S's values
  PairPivots pivots;
  std::vector<double> rhs, pairRhs;  // S's right-hand side (then its solution), the pair rows' b
  std::optional<BandedS> banded;     // a band ordering: S factored as a band, not by KLU
  bool factored = false;             // banded: the last factorization succeeded
  int64_t singularColumn = -1;
  sunindextype lastFlag = SUNLS_SUCCESS;

  explicit Content(ReducedKluPlan p) : plan(std::move(p)) {
    klu_l_defaults(&common);
    if (plan.band) banded = bandedS(plan.rows, *plan.band);
    if (plan.band && !banded) useBandOrdering(common, *plan.band);  // the plan lives here: it outlives the analysis
    if (!plan.blockTriangular) common.btf = 0;
    values.assign(std::max<size_t>(plan.rows.rowIndices.size(), 1), 0.0);
    rhs.assign(plan.rows.size(), 0.0);
    pairRhs.assign(plan.rows.pairs(), 0.0);
  }
  ~Content() {
    if (numeric) klu_l_free_numeric(&numeric, &common);
    if (symbolic) klu_l_free_symbolic(&symbolic, &common);
  }

  SuiteSparse_long* Sp() { return const_cast<SuiteSparse_long*>(plan.rows.columnStarts.data()); }
  // KLU refuses a null array even where it reads nothing (an S without entries: the rows left empty)
  SuiteSparse_long* Si() {
    static SuiteSparse_long none = 0;
    return plan.rows.rowIndices.empty() ? &none : const_cast<SuiteSparse_long*>(plan.rows.rowIndices.data());
  }

  int fail(sunindextype flag) {
    if (common.status == KLU_SINGULAR && common.singular_col >= 0 && common.singular_col < plan.rows.size())
      singularColumn = unknownOf(common.singular_col);
    return static_cast<int>(lastFlag = flag);
  }

  // The unknown a column of S stands for: a pair's column stands for the unknown its row was not
  // solved for in this factorization.
  int64_t unknownOf(int64_t reducedColumn) const {
    const TwoEntryRows& rows = plan.rows;
    int32_t index = rows.originalIndex[reducedColumn], q = rows.pairOf[index];
    if (q < 0 || static_cast<size_t>(q) >= pivots.solvesRow.size()) return index;
    return pivots.kept(rows, q);
  }

  // A band is factored with partial pivoting every time: a pass over its storage, cheaper than
  // KLU's refactorization without pivoting. A zero pivot names its column's unknown.
  int factorBand() {
    BandedS& b = *banded;
    b.lu.clear();
    std::span<double> band = b.lu.storage();
    for (size_t e = 0; e < b.entryOffset.size(); ++e) band[static_cast<size_t>(b.entryOffset[e])] = values[e];
    int64_t zero = b.lu.factor();
    factored = zero < 0;
    if (factored) return static_cast<int>(lastFlag = SUNLS_SUCCESS);
    singularColumn = unknownOf(b.order.empty() ? zero : b.order[static_cast<size_t>(zero)]);
    return static_cast<int>(lastFlag = SUNLS_PACKAGE_FAIL_REC);
  }

  // S's solution in place of its right-hand side `rhs`.
  bool solveReduced() {
    if (!banded) return klu_l_solve(symbolic, numeric, plan.rows.size(), 1, rhs.data(), &common) != 0;
    BandedS& b = *banded;
    if (b.order.empty()) {
      b.lu.solve(rhs);
      return true;
    }
    for (size_t k = 0; k < b.order.size(); ++k) b.permuted[k] = rhs[static_cast<size_t>(b.order[k])];
    b.lu.solve(b.permuted);
    for (size_t k = 0; k < b.order.size(); ++k) rhs[static_cast<size_t>(b.order[k])] = b.permuted[k];
    return true;
  }

  bool ready() const { return banded ? factored : numeric != nullptr; }

  // KLU: the first factorization pivots; later ones reuse its pivot order (refactor) unless KLU's
  // condition estimates say that order has gone bad, as SUNDIALS' KLU solver does.
  int factor() {
    if (banded) return factorBand();
    if (!symbolic && !(symbolic = klu_l_analyze(plan.rows.size(), Sp(), Si(), &common)))
      return fail(SUNLS_PACKAGE_FAIL_UNREC);
    if (!numeric) {
      numeric = klu_l_factor(Sp(), Si(), values.data(), symbolic, &common);
      return numeric ? static_cast<int>(lastFlag = SUNLS_SUCCESS) : fail(SUNLS_PACKAGE_FAIL_REC);
    }
    if (!klu_l_refactor(Sp(), Si(), values.data(), symbolic, numeric, &common)) return fail(SUNLS_PACKAGE_FAIL_REC);
    if (!klu_l_rcond(symbolic, numeric, &common)) return fail(SUNLS_PACKAGE_FAIL_REC);
    double threshold = std::pow(SUN_UNIT_ROUNDOFF, 2.0 / 3.0);
    if (common.rcond < threshold) {
      if (!klu_l_condest(Sp(), values.data(), symbolic, numeric, &common)) return fail(SUNLS_PACKAGE_FAIL_REC);
      if (common.condest > 1.0 / threshold) {
        klu_l_free_numeric(&numeric, &common);
        numeric = klu_l_factor(Sp(), Si(), values.data(), symbolic, &common);
        if (!numeric) return fail(SUNLS_PACKAGE_FAIL_REC);
      }
    }
    return static_cast<int>(lastFlag = SUNLS_SUCCESS);
  }
};

Content& content(SUNLinearSolver s) { return *static_cast<Content*>(s->content); }

int64_t size(SUNMatrix A) { return SUNSparseMatrix_Columns(A); }

int initialize(SUNLinearSolver s) {
  Content& c = content(s);
  if (c.numeric) klu_l_free_numeric(&c.numeric, &c.common);  // the next setup factors with pivoting
  c.factored = false;
  c.lastFlag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

int setup(SUNLinearSolver s, SUNMatrix A) {
  Content& c = content(s);
  c.singularColumn = -1;
  c.factored = false;
  const TwoEntryRows& rows = c.plan.rows;
  if (SUNSparseMatrix_SparseType(A) != CSC_MAT || size(A) != rows.n) return static_cast<int>(c.lastFlag = SUNLS_ILL_INPUT);
  std::span<const int64_t> starts(SUNSparseMatrix_IndexPointers(A), rows.n + 1);
  size_t nnz = static_cast<size_t>(starts.back());
  int64_t zeroRow = reduceMatrix(rows, starts, {SUNSparseMatrix_IndexValues(A), nnz}, {SUNSparseMatrix_Data(A), nnz},
                                 c.values, c.pivots);
  if (zeroRow >= 0) {  // a pair row that is zero: J is singular at that row's columns
    c.singularColumn = rows.row[zeroRow];
    return static_cast<int>(c.lastFlag = SUNLS_PACKAGE_FAIL_REC);
  }
  return c.factor();
}

int solve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
  Content& c = content(s);
  const TwoEntryRows& rows = c.plan.rows;
  if (!c.ready()) return static_cast<int>(c.lastFlag = SUNLS_PACKAGE_FAIL_UNREC);
  size_t n = static_cast<size_t>(rows.n);
  reduceRightHandSide(rows, c.pivots, {N_VGetArrayPointer(b), n}, c.rhs, c.pairRhs);
  if (!c.solveReduced()) return static_cast<int>(c.lastFlag = SUNLS_PACKAGE_FAIL_REC);
  completeSolution(rows, c.pivots, c.rhs, c.pairRhs, {N_VGetArrayPointer(x), n});
  return static_cast<int>(c.lastFlag = SUNLS_SUCCESS);
}

int release(SUNLinearSolver s) {
  if (!s) return SUNLS_SUCCESS;
  delete static_cast<Content*>(s->content);
  s->content = nullptr;
  SUNLinSolFreeEmpty(s);
  return SUNLS_SUCCESS;
}

}  // namespace

std::optional<ReducedKluPlan> planReducedKlu(CscPattern pattern) {
  std::optional<TwoEntryRows> rows = findTwoEntryRows(pattern);
  if (!rows) return std::nullopt;
  ReducedKluPlan plan{std::move(*rows), std::nullopt, true};
  plan.band = chooseBandOrdering(plan.rows.reducedPattern());
  plan.blockTriangular = !plan.band && zeroFreeDiagonal(plan.rows.reducedPattern());
  return plan;
}

SUNLinearSolver reducedKluSolver(ReducedKluPlan plan, SUNContext context) {
  SUNLinearSolver s = SUNLinSolNewEmpty(context);
  if (!s) return nullptr;
  s->content = new (std::nothrow) Content(std::move(plan));
  if (!s->content) {
    SUNLinSolFreeEmpty(s);
    return nullptr;
  }
  s->ops->gettype = [](SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; };
  s->ops->getid = [](SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; };
  s->ops->initialize = initialize;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->lastflag = [](SUNLinearSolver ls) { return content(ls).lastFlag; };
  s->ops->free = release;
  return s;
}

const ReducedKluPlan& reducedKluPlan(SUNLinearSolver solver) { return content(solver).plan; }

int64_t reducedKluSingularColumn(SUNLinearSolver solver) { return content(solver).singularColumn; }

bool reducedKluBanded(SUNLinearSolver solver) { return content(solver).banded.has_value(); }

}  // namespace qdot::rt
