/* The qdot model ABI: the one narrow interface between compiled model code (bytecode VM, LLVM JIT,
 * or a standalone executable's object file) and the runtime (IDA session, simulation loop, result
 * writers). Plain C so that generated object files and the runtime agree without C++ name mangling.
 *
 * The system is F(t, y, y', p) = 0 with n = nVariables unknowns y (differential and algebraic, in
 * result order) and n residuals. The Jacobian J = dF/dy + cj * dF/dy' is sparse, in compressed
 * sparse column form (CSC, the layout SUNDIALS' SUNSparseMatrix uses) with a fixed pattern.
 * Every function returns 0 on success; a nonzero return is a recoverable failure (e.g. a NaN or a
 * domain error) whose description the runtime can read with lastError. Versioned: a runtime refuses
 * a model whose abiVersion differs from QDOT_MODEL_ABI_VERSION. */
#ifndef QDOT_MODEL_ABI_H
#define QDOT_MODEL_ABI_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define QDOT_MODEL_ABI_VERSION 3

typedef struct QdotModel QdotModel;

/* Everything the runtime calls. `self` is the model itself (so backends can keep private data
 * after the table: the VM its program, the JIT its function pointers). */
struct QdotModel {
  uint32_t abiVersion; /* QDOT_MODEL_ABI_VERSION */
  const char* name;    /* model name */

  /* --- sizes and names ------------------------------------------------------------------- */
  uint32_t nVariables;  /* y and y' have this size; so does F unless index reduction made it longer */
  uint32_t nParameters; /* run-time parameters p */
  uint32_t nOutputs;    /* extra result columns (output definitions) */
  uint32_t nInvariants; /* first integrals (energy/Jacobi, conserved momenta) */
  const char* const* variableNames;  /* [nVariables], e.g. "x", "der(x)", "E" */
  const int32_t* isDifferential;     /* [nVariables]: 1 if y' of that variable appears (IDASetId) */
  const char* const* parameterNames; /* [nParameters] */
  const char* const* parameterDescriptions; /* [nParameters], "" if none */
  const char* const* outputNames;    /* [nOutputs] */
  const char* const* invariantNames; /* [nInvariants] */

  /* --- Jacobian pattern (CSC) ----------------------------------------------------------------- */
  uint32_t jacobianNonzeros;
  const int32_t* jacobianColumnStarts; /* [nVariables + 1] */
  const int32_t* jacobianRowIndices;   /* [jacobianNonzeros], ascending within a column, < nResiduals */

  /* --- index reduction (dummy derivatives) -------------------------------------------------- */
  /* F has nResiduals >= nVariables rows. Beyond nVariables they come from differentiated
   * equations (constraints): the runtime keeps all rows but one link per derivative of an
   * equation, chosen from the values (the dummy derivative method), and gives IDA that square
   * system. Without index reduction nResiduals == nVariables (0 means the same) and the tables
   * are empty. */
  uint32_t nResiduals;
  uint32_t nDerivativeLinks;
  const int32_t* derivativeLinks;          /* [3*nDerivativeLinks]: row, variable, derivative */
  uint32_t nDifferentiatedEquations;
  const int32_t* differentiatedRowStarts;  /* [nDifferentiatedEquations + 1] into differentiatedRows */
  const int32_t* differentiatedRows;       /* rows of e, e', e'', … per differentiated equation */
  /* The last nInitialRows rows of F hold only at t0: initial equations that are not start values.
   * The runtime solves them with the other rows at the start and leaves them out afterwards. */
  uint32_t nInitialRows;
  const char* const* initialRowLabels;     /* [nInitialRows], e.g. "initial equation x + der(x) = 3" */
  /* How the runtime makes outputs continuous from one result row to the next: 0 as computed,
   * 1 an angle (plus the multiple of 2 pi nearest the previous row's), 2 the first of a z-x-z
   * Euler-angle triple psi, theta, phi in consecutive outputs (see runtime/output/AngleUnwrap.h). */
  const int32_t* outputKinds;              /* [nOutputs] */

  /* --- functions ---------------------------------------------------------------------------- */
  /* Parameter values: p[i] = overridden[i] ? given[i] : default binding of parameter i, evaluated
   * in dependency order (a default may depend on other parameters, e.g. k = 2*m). */
  int (*parameters)(const QdotModel* self, const double* given, const uint8_t* overridden, double* p);
  /* Start values of y (from `start` attributes, over p; 0 where none) and of y' (0), and the
   * per-variable nominal magnitudes (from `nominal`, else 0 meaning "choose automatically"). */
  int (*initialValues)(const QdotModel* self, const double* p, double t0, double* y0, double* yp0, double* nominal);
  /* Which variables have fixed start values (1) and which may be changed by consistent
   * initialisation (0); written into fixed[nVariables]. */
  int (*fixedStarts)(const QdotModel* self, int32_t* fixed);
  int (*residual)(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double* F);
  /* Values of J = dF/dy + cj*dF/dy' in the CSC pattern above: every one of the jacobianNonzeros
   * values on every call (the runtime does not clear them in between; a value never written keeps
   * the 0 it starts with). */
  int (*jacobian)(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double cj,
                  double* values);
  int (*outputs)(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double* out);
  int (*invariants)(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double* out);
  /* Text of the last failure (e.g. "sqrt of a negative number in equation 3 (model.qd:12)"), or "". */
  const char* (*lastError)(const QdotModel* self);
  /* Releases the model (and its private data). */
  void (*destroy)(QdotModel* self);
};

#ifdef __cplusplus
}
#endif

#endif /* QDOT_MODEL_ABI_H */
