// execute (the fast loops of DispatchLoop.h) and traceOf, the decoded form of a function that the
// non-finite diagnosis (qdot/non_finite.hpp) re-runs.
#include "vm/Interpreter.h"

#include <algorithm>

#include "vm/DispatchLoop.h"

namespace qdot::vm {

void execute(const bc::Function& f, double* registers, const ModelCall& in, double* out) {
#if (defined(__GNUC__) || defined(__clang__)) && !defined(QDOT_VM_NO_COMPUTED_GOTO)
  detail::loopComputedGoto(f.code.data(), registers, in, f.constants.data(), out, f.loops.data(), f.indexTable.data());
#else
  detail::loopSwitch(f.code.data(), registers, in, f.constants.data(), out, f.loops.data(), f.indexTable.data());
#endif
}

void executeWithSwitch(const bc::Function& f, double* registers, const ModelCall& in, double* out) {
  detail::loopSwitch(f.code.data(), registers, in, f.constants.data(), out, f.loops.data(), f.indexTable.data());
}

std::vector<double> makeRegisters(const bc::Function& f) {
  std::vector<double> r(f.registerCount, 0.0);
  std::copy(f.constants.begin(), f.constants.end(), r.begin());
  return r;
}

ProgramTrace traceOf(const bc::Function& f) {
  ProgramTrace trace;
  for (const uint32_t* ip = f.code.data(); ip < f.code.data() + f.code.size();
       ip += 1 + bc::operandCount(bc::info(static_cast<bc::Opcode>(*ip)).format))
    trace.code.push_back(bc::decode(ip));
  trace.sources = f.sources;
  trace.constants = f.constants;
  trace.preloaded = static_cast<uint32_t>(f.constants.size());
  trace.registerCount = f.registerCount;
  trace.loops = f.loops;
  trace.indexTable = f.indexTable;
  return trace;
}

}  // namespace qdot::vm
