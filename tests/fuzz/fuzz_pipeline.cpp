// libFuzzer entry point for the whole front end: parse, check, flatten, derive the equations of
// motion and assemble the DAE (Stage::Dae), build the kernels (Stage::Kernel: residual, symbolic
// Jacobian, CSE), then continue to the bytecode (Stage::Bytecode), validate it and round-trip it
// through its serialised form. No input may crash, hang or violate these invariants:
// - every diagnostic has a registered code and a message and is located inside the file;
// - a model that compiles without errors yields a DAE whose equations and unknowns balance, kernel
//   programs in SSA form writing as many values as the description says, and bytecode that
//   validates and reads back unchanged in size.
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "qdot/bytecode.h"
#include "support/DiagnosticCodes.h"

namespace {

using namespace qdot;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// Every diagnostic has a message, a known code and, if located, a range inside its own file (the
// input, or a library the input imports).
void checkDiagnostics(const driver::Compilation& c) {
  for (const auto& d : c.diags.diagnostics()) {
    check(!d.message.empty() && static_cast<size_t>(d.code) < allDiagCodes().size());
    if (d.range.valid()) check(d.range.begin <= d.range.end && d.range.end <= c.sources.text(d.range.file).size());
  }
  std::ostream null(nullptr);
  c.diags.render(null, c.sources);
}

// Instruction i defines register %i and reads only earlier registers; each program writes what the
// description says it writes and keeps the loop rules.
void checkKernels(const kernel::KernelModule& m, size_t unknowns) {
  check(m.variableCount() == unknowns && m.description->inconsistency().empty());
  for (size_t p = 0; p < kModelProgramCount; ++p) {
    const kernel::Program& program = m.programs[p];
    check(program.outputCount == m.description->outputCount(programAt(p)));
    check(kernel::checkLoops(program, m.variableCount(), m.description->parameterCount()).empty());
    for (uint32_t i = 0; i < program.code.size(); ++i) {
      const kernel::Instr& ins = program.code[i];
      uint32_t reads = kernel::readCount(ins.op);
      check((reads < 1 || ins.a < i) && (reads < 2 || ins.b < i) && (reads < 3 || ins.c < i));
      check(ins.source == UINT32_MAX || ins.source < m.sources.size());
    }
  }
}

void checkBytecode(const bc::Module& m) {
  check(bc::validate(m).ok());
  std::vector<uint8_t> bytes = bc::serialize(m);
  Result<bc::Module> back = bc::deserialize(bytes);
  check(back.ok() && bc::serialize(back.value()) == bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  driver::Compilation c;
  c.options.limits.maxScalars = 20'000;  // keep each input fast; the limit itself is E0310
  c.options.keepLoops = size % 2 == 0;    // half the inputs the way `qdot run` compiles: templates and loops,
  c.options.eliminateAlgebraics = c.options.keepLoops;  // explicit algebraic unknowns solved out
  c.options.rerollRows = c.options.keepLoops;           // and runs of repeating rows rerolled,
  c.options.rerollMinimumRun = 2;                        // however short (small inputs have short runs)
  // and a quarter with a result asked for (`--outputs x`: arrays of components' energies summed,
  // their terms rerolled; a name the model lacks only keeps everything).
  if (size % 4 == 0) c.options.results = {"x"};
  bool ok = driver::compileSource(c, "fuzz.qd", std::string(reinterpret_cast<const char*>(data), size), "",
                                  driver::Stage::Dae);
  checkDiagnostics(c);
  if (!ok) return 0;
  // Square, except for one row per dummy derivative after index reduction.
  check(c.dae->equations.size() == c.dae->variables.size() + c.dae->dummyDerivativeCount());
  // The symbolic Jacobian of a dense model costs O(n^3) (an 83-link pendulum takes 2 s in a release
  // build, 14 s under ASan: the fuzzer's first timeout). That is a known cost, not a hang; bound
  // the size here so the fuzzer keeps exploring robustness.
  std::vector<sym::Expr> residuals;
  for (const auto& e : c.dae->equations)
    if (e.residual) residuals.push_back(e.residual);  // null: a row of a template block
  for (const auto& b : c.dae->templateBlocks) residuals.push_back(b.residual);
  if (c.ctx.dagSize(residuals) > 5'000) return 0;
  ok = driver::continueTo(c, driver::Stage::Kernel);
  checkDiagnostics(c);
  if (!ok) return 0;  // E06xx: what the kernels cannot compute, reported and located
  checkKernels(*c.kernels, c.dae->variables.size());
  check(driver::continueTo(c, driver::Stage::Bytecode) && c.internalError.empty());
  checkBytecode(*c.bytecode);
  return 0;
}
