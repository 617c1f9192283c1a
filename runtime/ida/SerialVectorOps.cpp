// The serial N_Vector's operations, compiled here (SerialVectorOps.h says why). Each one computes
// what SUNDIALS 6.4's nvector_serial.c computes, case for case and element for element: reductions
// run over the elements in order with one accumulator (no reassociation, so no vectorized sums),
// and the fused operations that read several vectors work through them a block of elements at a
// time — for one element the same operations in the same order as SUNDIALS' vector-by-vector loops
// (every operation here reads and writes element j only at element j), with the block's elements
// still in cache for the next vector.
#include "ida/SerialVectorOps.h"

#include <nvector/nvector_serial.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <string_view>

namespace qdot::rt {
namespace {

using Real = realtype;
using Index = sunindextype;

Real* data(N_Vector v) { return NV_DATA_S(v); }
Index length(N_Vector v) { return NV_LENGTH_S(v); }

// SUNDIALS' SUNRsqrt: 0 for a sum that is not positive.
Real rootOrZero(Real x) { return x <= 0 ? Real(0) : std::sqrt(x); }

/// Runs body(begin, end) over [0, n) in blocks small enough that a block of a few vectors stays in
/// the first-level cache while an operation goes from one vector to the next.
template <class Body>
void inBlocks(Index n, Body body) {
  constexpr Index kBlock = 512;
  for (Index begin = 0; begin < n; begin += kBlock) body(begin, std::min(n, begin + kBlock));
}

// --- z = a x + b y, with SUNDIALS' special cases -------------------------------------------------

/// Which loop N_VLinearSum_Serial runs for (a, b) and which vector is written in place; the
/// vector-array operation decides the same way on its arrays.
enum class SumLoop { AxpyIntoY, AxpyIntoX, Sum, XMinusY, YMinusX, BYPlusX, AXPlusY, BYMinusX, AXMinusY, ScaledSum, ScaledDiff, General };

SumLoop sumLoop(Real a, Real b, bool zIsY, bool zIsX) {
  if (b == 1 && zIsY) return SumLoop::AxpyIntoY;
  if (a == 1 && zIsX) return SumLoop::AxpyIntoX;
  if (a == 1 && b == 1) return SumLoop::Sum;
  if (a == 1 && b == -1) return SumLoop::XMinusY;
  if (a == -1 && b == 1) return SumLoop::YMinusX;
  if (a == 1) return SumLoop::BYPlusX;
  if (b == 1) return SumLoop::AXPlusY;
  if (a == -1) return SumLoop::BYMinusX;
  if (b == -1) return SumLoop::AXMinusY;
  if (a == b) return SumLoop::ScaledSum;
  if (a == -b) return SumLoop::ScaledDiff;
  return SumLoop::General;
}

// y += a x (SUNDIALS' Vaxpy: a = ±1 without the multiplication).
void axpy(Real a, const Real* x, Real* y, Index n) {
  if (a == 1)
    for (Index i = 0; i < n; ++i) y[i] += x[i];
  else if (a == -1)
    for (Index i = 0; i < n; ++i) y[i] -= x[i];
  else
    for (Index i = 0; i < n; ++i) y[i] += a * x[i];
}

void runSum(SumLoop loop, Real a, const Real* x, Real b, const Real* y, Real* z, Index n) {
  switch (loop) {
    case SumLoop::AxpyIntoY: return axpy(a, x, z, n);
    case SumLoop::AxpyIntoX: return axpy(b, y, z, n);
    case SumLoop::Sum: for (Index i = 0; i < n; ++i) z[i] = x[i] + y[i]; return;
    case SumLoop::XMinusY: for (Index i = 0; i < n; ++i) z[i] = x[i] - y[i]; return;
    case SumLoop::YMinusX: for (Index i = 0; i < n; ++i) z[i] = y[i] - x[i]; return;
    case SumLoop::BYPlusX: for (Index i = 0; i < n; ++i) z[i] = (b * y[i]) + x[i]; return;
    case SumLoop::AXPlusY: for (Index i = 0; i < n; ++i) z[i] = (a * x[i]) + y[i]; return;
    case SumLoop::BYMinusX: for (Index i = 0; i < n; ++i) z[i] = (b * y[i]) - x[i]; return;
    case SumLoop::AXMinusY: for (Index i = 0; i < n; ++i) z[i] = (a * x[i]) - y[i]; return;
    case SumLoop::ScaledSum: for (Index i = 0; i < n; ++i) z[i] = a * (x[i] + y[i]); return;
    case SumLoop::ScaledDiff: for (Index i = 0; i < n; ++i) z[i] = a * (x[i] - y[i]); return;
    case SumLoop::General: for (Index i = 0; i < n; ++i) z[i] = (a * x[i]) + (b * y[i]); return;
  }
}

void linearSum(Real a, N_Vector x, Real b, N_Vector y, N_Vector z) {
  runSum(sumLoop(a, b, z == y, z == x), a, data(x), b, data(y), data(z), length(x));
}

// z = c x (SUNDIALS' N_VScale: in place, a copy, a negation, or the product).
void scaleInto(Real c, const Real* x, Real* z, Index n, bool inPlace) {
  if (inPlace)
    for (Index i = 0; i < n; ++i) z[i] *= c;
  else if (c == 1)
    std::copy_n(x, n, z);
  else if (c == -1)
    for (Index i = 0; i < n; ++i) z[i] = -x[i];
  else
    for (Index i = 0; i < n; ++i) z[i] = c * x[i];
}

void scale(Real c, N_Vector x, N_Vector z) { scaleInto(c, data(x), data(z), length(x), z == x); }

// --- element-wise operations ---------------------------------------------------------------------

void constant(Real c, N_Vector z) { std::fill_n(data(z), length(z), c); }

void product(N_Vector x, N_Vector y, N_Vector z) {
  const Real *xd = data(x), *yd = data(y);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = xd[i] * yd[i];
}

void quotient(N_Vector x, N_Vector y, N_Vector z) {
  const Real *xd = data(x), *yd = data(y);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = xd[i] / yd[i];
}

void absolute(N_Vector x, N_Vector z) {
  const Real* xd = data(x);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = std::fabs(xd[i]);
}

void inverse(N_Vector x, N_Vector z) {
  const Real* xd = data(x);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = Real(1) / xd[i];
}

void addConstant(N_Vector x, Real b, N_Vector z) {
  const Real* xd = data(x);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = xd[i] + b;
}

void compare(Real c, N_Vector x, N_Vector z) {
  const Real* xd = data(x);
  Real* zd = data(z);
  for (Index i = 0, n = length(x); i < n; ++i) zd[i] = std::fabs(xd[i]) >= c ? Real(1) : Real(0);
}

// z = 1/x where x is not zero (elsewhere z keeps its value); whether no x was zero.
booleantype inverseTest(N_Vector x, N_Vector z) {
  const Real* xd = data(x);
  Real* zd = data(z);
  booleantype noZero = SUNTRUE;
  for (Index i = 0, n = length(x); i < n; ++i) {
    if (xd[i] == 0)
      noZero = SUNFALSE;
    else
      zd[i] = Real(1) / xd[i];
  }
  return noZero;
}

// m = 1 where x violates the constraint c (±1: ≥ 0 / ≤ 0, ±2: > 0 / < 0), else 0; whether none did.
booleantype constraintMask(N_Vector c, N_Vector x, N_Vector m) {
  const Real *cd = data(c), *xd = data(x);
  Real* md = data(m);
  bool violated = false;
  for (Index i = 0, n = length(x); i < n; ++i) {
    md[i] = 0;
    if (cd[i] == 0) continue;
    if ((std::fabs(cd[i]) > 1.5 && xd[i] * cd[i] <= 0) || (std::fabs(cd[i]) > 0.5 && xd[i] * cd[i] < 0)) md[i] = 1, violated = true;
  }
  return violated ? SUNFALSE : SUNTRUE;
}

// --- reductions, in element order ----------------------------------------------------------------

Real dotProduct(N_Vector x, N_Vector y) {
  const Real *xd = data(x), *yd = data(y);
  Real sum = 0;
  for (Index i = 0, n = length(x); i < n; ++i) sum += xd[i] * yd[i];
  return sum;
}

Real maxNorm(N_Vector x) {
  const Real* xd = data(x);
  Real max = 0;
  for (Index i = 0, n = length(x); i < n; ++i)
    if (std::fabs(xd[i]) > max) max = std::fabs(xd[i]);
  return max;
}

Real minimum(N_Vector x) {
  const Real* xd = data(x);
  Real min = xd[0];
  for (Index i = 1, n = length(x); i < n; ++i)
    if (xd[i] < min) min = xd[i];
  return min;
}

Real l1Norm(N_Vector x) {
  const Real* xd = data(x);
  Real sum = 0;
  for (Index i = 0, n = length(x); i < n; ++i) sum += std::fabs(xd[i]);
  return sum;
}

Real weightedSquareSum(const Real* x, const Real* w, Index n) {
  Real sum = 0;
  for (Index i = 0; i < n; ++i) {
    Real p = x[i] * w[i];
    sum += p * p;
  }
  return sum;
}

Real weightedSquareSumMasked(const Real* x, const Real* w, const Real* id, Index n) {
  Real sum = 0;
  for (Index i = 0; i < n; ++i)
    if (id[i] > 0) {
      Real p = x[i] * w[i];
      sum += p * p;
    }
  return sum;
}

Real wSqrSum(N_Vector x, N_Vector w) { return weightedSquareSum(data(x), data(w), length(x)); }
Real wSqrSumMask(N_Vector x, N_Vector w, N_Vector id) { return weightedSquareSumMasked(data(x), data(w), data(id), length(x)); }
Real wrmsNorm(N_Vector x, N_Vector w) { return rootOrZero(wSqrSum(x, w) / static_cast<Real>(length(x))); }
Real wrmsNormMask(N_Vector x, N_Vector w, N_Vector id) { return rootOrZero(wSqrSumMask(x, w, id) / static_cast<Real>(length(x))); }
Real wl2Norm(N_Vector x, N_Vector w) { return rootOrZero(wSqrSum(x, w)); }

// min over the elements with a nonzero denominator of num/denom; DBL_MAX where there is none.
Real minQuotient(N_Vector num, N_Vector denom) {
  const Real *nd = data(num), *dd = data(denom);
  bool none = true;
  Real min = DBL_MAX;
  for (Index i = 0, n = length(num); i < n; ++i) {
    if (dd[i] == 0) continue;
    Real q = nd[i] / dd[i];
    if (none)
      min = q, none = false;
    else
      min = min < q ? min : q;  // SUNMIN's order: a NaN quotient is taken
  }
  return min;
}

// --- fused operations ----------------------------------------------------------------------------

// z = Σ c_i X_i: z = c_0 X_0 (or X_0 scaled in place, or left as it is for c_0 = 1), then + c_i X_i.
int linearCombination(int count, Real* c, N_Vector* X, N_Vector z) {
  if (count == 1) return scale(c[0], X[0], z), 0;
  if (count == 2) return linearSum(c[0], X[0], c[1], X[1], z), 0;
  Real* zd = data(z);
  const Real* x0 = data(X[0]);
  bool inPlace = X[0] == z;
  inBlocks(length(z), [&](Index begin, Index end) {
    if (!inPlace)
      for (Index j = begin; j < end; ++j) zd[j] = c[0] * x0[j];
    else if (c[0] != 1)
      for (Index j = begin; j < end; ++j) zd[j] *= c[0];
    for (int i = 1; i < count; ++i) {
      const Real* xd = data(X[i]);
      for (Index j = begin; j < end; ++j) zd[j] += c[i] * xd[j];
    }
  });
  return 0;
}

// Z_i = a_i x + Y_i (in place when the arrays are one: Y_i += a_i x).
int scaleAddMulti(int count, Real* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  if (count == 1) return linearSum(a[0], x, 1, Y[0], Z[0]), 0;
  const Real* xd = data(x);
  bool inPlace = Y == Z;
  inBlocks(length(x), [&](Index begin, Index end) {
    for (int i = 0; i < count; ++i) {
      Real* yd = data(Y[i]);
      if (inPlace) {
        for (Index j = begin; j < end; ++j) yd[j] += a[i] * xd[j];
      } else {
        Real* zd = data(Z[i]);
        for (Index j = begin; j < end; ++j) zd[j] = a[i] * xd[j] + yd[j];
      }
    }
  });
  return 0;
}

int dotProductMulti(int count, N_Vector x, N_Vector* Y, Real* dots) {
  if (count == 1) return dots[0] = dotProduct(x, Y[0]), 0;
  const Real* xd = data(x);
  std::fill_n(dots, count, Real(0));
  inBlocks(length(x), [&](Index begin, Index end) {
    for (int i = 0; i < count; ++i) {
      const Real* yd = data(Y[i]);
      Real sum = dots[i];
      for (Index j = begin; j < end; ++j) sum += xd[j] * yd[j];
      dots[i] = sum;
    }
  });
  return 0;
}

// --- vector-array operations ---------------------------------------------------------------------

int linearSumArray(int count, Real a, N_Vector* X, Real b, N_Vector* Y, N_Vector* Z) {
  if (count == 1) return linearSum(a, X[0], b, Y[0], Z[0]), 0;
  SumLoop loop = sumLoop(a, b, Z == Y, Z == X);
  for (int i = 0; i < count; ++i) runSum(loop, a, data(X[i]), b, data(Y[i]), data(Z[i]), length(Z[0]));
  return 0;
}

int scaleArray(int count, Real* c, N_Vector* X, N_Vector* Z) {
  if (count == 1) return scale(c[0], X[0], Z[0]), 0;
  Index n = length(Z[0]);
  for (int i = 0; i < count; ++i) {
    const Real* xd = data(X[i]);
    Real* zd = data(Z[i]);
    if (X == Z)
      for (Index j = 0; j < n; ++j) zd[j] *= c[i];
    else
      for (Index j = 0; j < n; ++j) zd[j] = c[i] * xd[j];
  }
  return 0;
}

int constantArray(int count, Real c, N_Vector* Z) {
  for (int i = 0; i < count; ++i) constant(c, Z[i]);
  return 0;
}

int wrmsNormArray(int count, N_Vector* X, N_Vector* W, Real* norms) {
  for (int i = 0; i < count; ++i) norms[i] = wrmsNorm(X[i], W[i]);
  return 0;
}

int wrmsNormMaskArray(int count, N_Vector* X, N_Vector* W, N_Vector id, Real* norms) {
  for (int i = 0; i < count; ++i) norms[i] = wrmsNormMask(X[i], W[i], id);
  return 0;
}

bool keepSundials() {
  const char* v = std::getenv("QDOT_SUNDIALS_VECTOR_OPS");
  return v && std::string_view(v) == "1";
}

// Replaces an operation SUNDIALS has set (an unset one stays unset: enabling is the caller's choice).
template <class F>
void replace(F& slot, F ours) {
  if (slot) slot = ours;
}

}  // namespace

void useOptimizedSerialOps(N_Vector v) {
  if (!v || !v->ops || N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL || keepSundials()) return;
  N_Vector_Ops ops = v->ops;
  replace(ops->nvlinearsum, &linearSum);
  replace(ops->nvconst, &constant);
  replace(ops->nvprod, &product);
  replace(ops->nvdiv, &quotient);
  replace(ops->nvscale, &scale);
  replace(ops->nvabs, &absolute);
  replace(ops->nvinv, &inverse);
  replace(ops->nvaddconst, &addConstant);
  replace(ops->nvdotprod, &dotProduct);
  replace(ops->nvmaxnorm, &maxNorm);
  replace(ops->nvwrmsnorm, &wrmsNorm);
  replace(ops->nvwrmsnormmask, &wrmsNormMask);
  replace(ops->nvmin, &minimum);
  replace(ops->nvwl2norm, &wl2Norm);
  replace(ops->nvl1norm, &l1Norm);
  replace(ops->nvcompare, &compare);
  replace(ops->nvinvtest, &inverseTest);
  replace(ops->nvconstrmask, &constraintMask);
  replace(ops->nvminquotient, &minQuotient);
  replace(ops->nvlinearcombination, &linearCombination);
  replace(ops->nvscaleaddmulti, &scaleAddMulti);
  replace(ops->nvdotprodmulti, &dotProductMulti);
  replace(ops->nvlinearsumvectorarray, &linearSumArray);
  replace(ops->nvscalevectorarray, &scaleArray);
  replace(ops->nvconstvectorarray, &constantArray);
  replace(ops->nvwrmsnormvectorarray, &wrmsNormArray);
  replace(ops->nvwrmsnormmaskvectorarray, &wrmsNormMaskArray);
  replace(ops->nvdotprodlocal, &dotProduct);
  replace(ops->nvmaxnormlocal, &maxNorm);
  replace(ops->nvminlocal, &minimum);
  replace(ops->nvl1normlocal, &l1Norm);
  replace(ops->nvinvtestlocal, &inverseTest);
  replace(ops->nvconstrmasklocal, &constraintMask);
  replace(ops->nvminquotientlocal, &minQuotient);
  replace(ops->nvwsqrsumlocal, &wSqrSum);
  replace(ops->nvwsqrsummasklocal, &wSqrSumMask);
  replace(ops->nvdotprodmultilocal, &dotProductMulti);
}

}  // namespace qdot::rt
