// IDA's Newton matrix with its two-entry rows eliminated, the rest factored by KLU (ReducedKlu.h).
#include "ida/ReducedKlu.h"

#include <klu.h>
#include <sundials/sundials_math.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <new>

namespace qdot::rt {

namespace {

struct Content {
  ReducedKluPlan plan;
  klu_l_common common{};
  klu_l_symbolic* symbolic = nullptr;
  klu_l_numeric* numeric = nullptr;
  std::vector<double> values;        // S's values
  PairPivots pivots;
  std::vector<double> rhs, pairRhs;  // S's right-hand side (then its solution), the pair rows' b
  int64_t singularColumn = -1;
  sunindextype lastFlag = SUNLS_SUCCESS;

  explicit Content(ReducedKluPlan p) : plan(std::move(p)) {
    klu_l_defaults(&common);
    if (plan.band) useBandOrdering(common, *plan.band);  // the plan lives here: it outlives the analysis
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

  // The first factorization pivots; later ones reuse its pivot order (refactor) unless KLU's
  // condition estimates say that order has gone bad, as SUNDIALS' KLU solver does.
  int factor() {
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
  c.lastFlag = SUNLS_SUCCESS;
  return SUNLS_SUCCESS;
}

int setup(SUNLinearSolver s, SUNMatrix A) {
  Content& c = content(s);
  c.singularColumn = -1;
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
  if (!c.numeric) return static_cast<int>(c.lastFlag = SUNLS_PACKAGE_FAIL_UNREC);
  size_t n = static_cast<size_t>(rows.n);
  reduceRightHandSide(rows, c.pivots, {N_VGetArrayPointer(b), n}, c.rhs, c.pairRhs);
  if (!klu_l_solve(c.symbolic, c.numeric, rows.size(), 1, c.rhs.data(), &c.common))
    return static_cast<int>(c.lastFlag = SUNLS_PACKAGE_FAIL_REC);
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

}  // namespace qdot::rt
