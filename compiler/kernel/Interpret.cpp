// Reference interpreter of the kernel IR: one plain switch generated from qdot/opcodes.def, so
// it computes exactly what the VM's handlers compute. Used by tests and for debugging.
#include <cmath>

#include "kernel/Kernel.h"
#include "qdot/bytecode.h"

namespace qdot::kernel {

#define QDOT_KERNEL_End(E) return;
#define QDOT_KERNEL_None(E) r[i] = (E);
#define QDOT_KERNEL_Index(E) r[i] = (E);
#define QDOT_KERNEL_Unary(E) r[i] = (E);
#define QDOT_KERNEL_Binary(E) r[i] = (E);
#define QDOT_KERNEL_Ternary(E) r[i] = (E);
#define QDOT_KERNEL_UnaryIndex(E) r[i] = (E);
#define QDOT_KERNEL_Store(E) out[I] = (E);

void interpret(const Program& prog, const ModelCall& in, std::span<double> out) {
  std::vector<double> r(prog.code.size(), 0.0);
  const double t = in.t, cj = in.cj;
  const double *y = in.y, *yp = in.yp, *p = in.p, *given = in.given;
  const double* k = prog.constants.data();
  const uint8_t* overridden = in.overridden;
  for (size_t i = 0; i < prog.code.size(); ++i) {
    const Instr& ins = prog.code[i];
    const double A = r[ins.a], B = r[ins.b], C = r[ins.c];
    const uint32_t I = ins.imm;
    switch (ins.op) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case Op::Name:                                   \
    QDOT_KERNEL_##Format(Value) break;
#include "qdot/opcodes.def"
    }
  }
}

}  // namespace qdot::kernel
