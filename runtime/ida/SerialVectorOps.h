// The serial N_Vector's operations compiled with this project's optimization (issue 15).
//
// Debian bookworm's SUNDIALS 6.4.1 is built without optimization: its shared libraries are -O0 code
// (every local kept on the stack; `objdump -d libsundials_nvecserial.so.6` shows it), and
// N_VWrmsNorm_Serial evaluates its sum twice (SUNRsqrt is a macro). IDA and ARKODE spend most of a
// large model's step in these loops: at 10⁶ masses the WRMS norm of two 2·10⁶ vectors took 17.5 ms
// where the same loop compiled with -O2 takes 3.6 ms, and the vector operations were 60 % of the
// first step. useOptimizedSerialOps(v) replaces the operations in v's table (N_VClone copies it, so
// every vector IDA or ARKODE makes from v has them too) with the same arithmetic compiled here:
// every special case SUNDIALS distinguishes (z = x + y, z = c(x + y), y += a x, …) is kept, and
// every element sees the same operations in the same order, so every result is the same to the bit
// (tests/unit/runtime/SerialVectorOpsTest.cpp compares each operation with SUNDIALS' own). The
// fused operations go through memory once where SUNDIALS' go once per vector (z = Σ c_i X_i sums
// each element in the same order either way). Operations SUNDIALS leaves unset stay unset.
#pragma once

#include <sundials/sundials_nvector.h>

namespace qdot::rt {

/// Puts the optimized implementations (above) into a serial vector's operations table. Not a serial
/// vector: no effect. QDOT_SUNDIALS_VECTOR_OPS=1 in the environment leaves SUNDIALS' own, for
/// measuring the difference (bench/README.md).
void useOptimizedSerialOps(N_Vector v);

}  // namespace qdot::rt
