// The VM's inner loop, generated from qdot/opcodes.def: each handler decodes its operands by
// format, computes the opcode's value expression and jumps to the next handler (computed goto),
// or, with QDOT_VM_NO_COMPUTED_GOTO or a compiler without labels-as-values, loops over a switch.
// Included by Interpreter.cpp (both variants) — every handler reads its operands before writing.
// Loop state lives in locals: the open loop, its iteration c, its offset L and the body's first
// word (loops do not nest, so one of each).
#pragma once

#include <cmath>

#include "qdot/bytecode.h"
#include "vm/Interpreter.h"

// Operand decoding per format; ip[0] is the opcode word.
#define QDOT_VM_End(E) return;
#define QDOT_VM_None(E) r[ip[1]] = (E), ip += 2;
#define QDOT_VM_Index(E) { const uint32_t I = ip[2]; r[ip[1]] = (E); ip += 3; }
#define QDOT_VM_Unary(E) { const double A = r[ip[2]]; r[ip[1]] = (E); ip += 3; }
#define QDOT_VM_Binary(E) { const double A = r[ip[2]], B = r[ip[3]]; r[ip[1]] = (E); ip += 4; }
#define QDOT_VM_Ternary(E) { const double A = r[ip[2]], B = r[ip[3]], C = r[ip[4]]; r[ip[1]] = (E); ip += 5; }
#define QDOT_VM_UnaryIndex(E) { const double A = r[ip[2]]; const uint32_t I = ip[3]; r[ip[1]] = (E); ip += 4; }
#define QDOT_VM_Store(E) { const double A = r[ip[2]]; out[ip[1]] = (E); ip += 3; }
#define QDOT_VM_StoreLooped(E) { const double A = r[ip[2]]; out[ip[1] + L] = (E); ip += 3; }
#define QDOT_VM_StoreIndexed(E) { const double A = r[ip[2]]; out[X[ip[1] + c]] = (E); ip += 3; }
#define QDOT_VM_StoreAdd(E) { const double A = r[ip[2]]; out[ip[1]] += (E); ip += 3; }
#define QDOT_VM_LoopBegin(E) \
  { loop = &loops[ip[1]], c = 0; if (loop->count == 0) ip += ip[2]; else L = loop->offset(0, X), ip += 3, body = ip; }
#define QDOT_VM_LoopEnd(E) { if (++c < loop->count) L = loop->offset(c, X), ip = body; else ip += 2; }

// The inputs and the loop state as the names the value expressions of opcodes.def use.
#define QDOT_VM_INPUTS                                                         \
  [[maybe_unused]] const double t = in.t, cj = in.cj;                          \
  [[maybe_unused]] const double *y = in.y, *yp = in.yp, *p = in.p, *given = in.given; \
  [[maybe_unused]] const uint8_t* overridden = in.overridden;                \
  [[maybe_unused]] const Loop* loop = nullptr;                                 \
  [[maybe_unused]] const uint32_t* body = nullptr;                             \
  [[maybe_unused]] uint32_t c = 0;                                             \
  [[maybe_unused]] int64_t L = 0;

namespace qdot::vm::detail {

#if defined(__GNUC__) || defined(__clang__)
inline void loopComputedGoto(const uint32_t* ip, double* __restrict r, const ModelCall& in, const double* k,
                             double* __restrict out, const Loop* loops, const uint32_t* X) {
  QDOT_VM_INPUTS
  static const void* const handlers[] = {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) &&op_##Name,
#include "qdot/opcodes.def"
  };
  goto* handlers[*ip];
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  op_##Name : QDOT_VM_##Format(Value) goto* handlers[*ip];
#include "qdot/opcodes.def"
}
#endif

inline void loopSwitch(const uint32_t* ip, double* r, const ModelCall& in, const double* k, double* out,
                       const Loop* loops, const uint32_t* X) {
  QDOT_VM_INPUTS
  for (;;) {
    switch (static_cast<bc::Opcode>(*ip)) {
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case bc::Opcode::Name:                           \
    QDOT_VM_##Format(Value) break;
#include "qdot/opcodes.def"
    }
  }
}

}  // namespace qdot::vm::detail
