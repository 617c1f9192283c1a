// libFuzzer entry point for the whole front end: parse, check, flatten, derive the equations of
// motion, assemble the DAE, build the kernels (residual, symbolic Jacobian, CSE) and the bytecode,
// and validate the bytecode. No input may crash, hang or violate these invariants:
// every diagnostic is located inside the file with a stable code; a model that compiles without
// errors yields a DAE whose equations and unknowns balance and bytecode that validates.
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "bytecode/Emitter.h"
#include "driver/Pipeline.h"
#include "kernel/Kernel.h"
#include "qdot/bytecode.h"

namespace {

using namespace qdot;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void checkDiagnostics(const driver::Compilation& c, size_t size) {
  for (const auto& d : c.diags.diagnostics()) {
    check(!d.message.empty() && d.code.size() == 5 && d.code[0] != ' ');
    if (d.range.valid()) check(d.range.begin <= d.range.end && d.range.end <= size);
  }
  std::ostream null(nullptr);
  c.diags.render(null, c.sources);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  driver::Compilation c;
  c.limits.maxScalars = 20'000;  // keep each input fast; the limit itself is E0310
  bool ok = driver::compileSource(c, "fuzz.qd", std::string(reinterpret_cast<const char*>(data), size), "",
                                  driver::Stage::Dae);
  checkDiagnostics(c, size);
  if (!ok) return 0;
  check(c.dae->equations.size() == c.dae->variables.size() || !c.eom->multipliers.empty());
  // The symbolic Jacobian of a dense model costs O(n^3) (an 83-link pendulum takes 2 s in a release
  // build, 14 s under ASan: the fuzzer's first timeout). That is a known cost, not a hang; bound
  // the size here so the fuzzer keeps exploring robustness.
  std::vector<sym::Expr> residuals;
  for (const auto& e : c.dae->equations) residuals.push_back(e.residual);
  if (c.ctx.dagSize(residuals) > 5'000) return 0;
  kernel::KernelModule k = kernel::buildKernels(*c.dae, c.ctx, c.diags);
  bc::Module m = bytecode::emitBytecode(k, c.sources);
  std::string error;
  check(bc::validate(m, error));
  return 0;
}
