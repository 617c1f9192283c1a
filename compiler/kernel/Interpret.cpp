// Reference interpreter of the kernel IR: one plain switch generated from qdot/opcodes.def, so
// it computes exactly what the VM's handlers compute. Used by tests and for debugging.
#include <cmath>

#include "kernel/Kernel.h"
#include "qdot/bytecode.h"

namespace qdot::kernel {
namespace {

// The open loop of a run (nullptr outside loops), its iteration c and offset L, and the index of
// its body's first instruction.
struct LoopState {
  const Loop* loop = nullptr;
  uint32_t c = 0;
  int64_t L = 0;
  size_t body = 0;
};

// The index of the instruction to run after the `loop` or `endloop` at i.
size_t stepLoop(const Program& prog, size_t i, LoopState& s) {
  if (prog.code[i].op == Op::LoopBegin) {
    s = {&prog.loops[prog.code[i].imm], 0, 0, i + 1};
  } else if (++s.c == s.loop->count) {
    s.loop = nullptr;
    return i + 1;
  }
  if (s.loop->count == 0) {  // no iteration: past its endloop
    while (prog.code[i].op != Op::LoopEnd) ++i;
    s.loop = nullptr;
    return i + 1;
  }
  s.L = s.loop->offset(s.c, prog.indexTable.data());
  return s.body;
}

}  // namespace

#define QDOT_KERNEL_End(E) return;
#define QDOT_KERNEL_None(E) r[i] = (E);
#define QDOT_KERNEL_Index(E) r[i] = (E);
#define QDOT_KERNEL_Unary(E) r[i] = (E);
#define QDOT_KERNEL_Binary(E) r[i] = (E);
#define QDOT_KERNEL_Ternary(E) r[i] = (E);
#define QDOT_KERNEL_UnaryIndex(E) r[i] = (E);
#define QDOT_KERNEL_Store(E) out[I] = (E);
#define QDOT_KERNEL_StoreLooped(E) out[I + L] = (E);
#define QDOT_KERNEL_StoreIndexed(E) out[X[I + c]] = (E);
#define QDOT_KERNEL_StoreAdd(E) out[I] += (E);
#define QDOT_KERNEL_LoopBegin(E) next = stepLoop(prog, i, loop);
#define QDOT_KERNEL_LoopEnd(E) next = stepLoop(prog, i, loop);

void interpret(const Program& prog, const ModelCall& in, std::span<double> out) {
  std::vector<double> r(prog.code.size(), 0.0);
  const double t = in.t, cj = in.cj;
  const double *y = in.y, *yp = in.yp, *p = in.p, *given = in.given;
  const double* k = prog.constants.data();
  const uint32_t* X = prog.indexTable.data();
  const uint8_t* overridden = in.overridden;
  LoopState loop;
  for (size_t i = 0, next = 0; i < prog.code.size(); i = next) {
    const Instr& ins = prog.code[i];
    const double A = r[ins.a], B = r[ins.b], C = r[ins.c];
    const uint32_t I = ins.imm, c = loop.c;
    const int64_t L = loop.L;
    next = i + 1;
    switch (ins.op) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case Op::Name:                                   \
    QDOT_KERNEL_##Format(Value) break;
#include "qdot/opcodes.def"
    }
  }
}

}  // namespace qdot::kernel
