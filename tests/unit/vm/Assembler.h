// Test helper: bytecode modules written by hand (no compiler), so the VM is tested alone.
// tinyModule() is a valid model with one variable x, one parameter a and one location.
#pragma once

#include <initializer_list>

#include "qdot/bytecode.h"

namespace qdot::test {

/// Appends instructions to a function; constants take the low registers as the VM expects.
class Assembler {
 public:
  Assembler(bc::Function& f, std::initializer_list<double> constants, uint32_t scratch) : f_(f) {
    f_ = bc::Function();
    f_.constants.assign(constants);
    f_.registerCount = static_cast<uint32_t>(constants.size()) + scratch;
  }
  /// Register of scratch value i.
  uint32_t r(uint32_t i) const { return static_cast<uint32_t>(f_.constants.size()) + i; }
  Assembler& op(bc::Opcode op, std::initializer_list<uint32_t> operands, uint32_t source = bc::kNoSource) {
    f_.code.push_back(static_cast<uint32_t>(op));
    f_.code.insert(f_.code.end(), operands);
    f_.sources.push_back(source);
    return *this;
  }
  /// Appends one instruction to f (for edits of a finished function).
  static void append(bc::Function& f, bc::Opcode op, std::initializer_list<uint32_t> operands) {
    f.code.push_back(static_cast<uint32_t>(op));
    f.code.insert(f.code.end(), operands);
    f.sources.push_back(bc::kNoSource);
  }
  void ret(uint32_t outputs) {
    op(bc::Opcode::Ret, {});
    f_.outputCount = outputs;
  }

 private:
  bc::Function& f_;
};

inline bc::Module tinyModule() {
  using bc::Opcode;
  bc::Module m;
  ModelDescription& d = m.description.edit();
  d.name = "Tiny";
  d.variableNames = {"x"}, d.parameterNames = {"a"}, d.parameterDescriptions = {"a parameter"};
  d.isDifferential = {1}, d.fixed = {1};
  d.jacobianColumnStarts = {0, 1}, d.jacobianRowIndices = {0};
  m.locations = {{"equation 1", "tiny.qd:3", "der(x) = a*x"}};
  Assembler p(m.function(ModelProgram::Parameters), {}, 1);
  p.op(Opcode::LoadGiven, {p.r(0), 0}).op(Opcode::Store, {0, p.r(0)}).ret(1);
  Assembler s(m.function(ModelProgram::InitialValues), {1.0, 0.0}, 0);
  s.op(Opcode::Store, {0, 0}).op(Opcode::Store, {1, 1}).op(Opcode::Store, {2, 1}).ret(3);
  Assembler f(m.function(ModelProgram::Residual), {}, 2);  // F = x' - a*x
  f.op(Opcode::LoadP, {f.r(1), 0}, 0).op(Opcode::LoadY, {f.r(0), 0}, 0).op(Opcode::Mul, {f.r(1), f.r(1), f.r(0)}, 0);
  f.op(Opcode::LoadYp, {f.r(0), 0}, 0).op(Opcode::Sub, {f.r(0), f.r(0), f.r(1)}, 0).op(Opcode::Store, {0, f.r(0)}, 0);
  f.ret(1);
  Assembler j(m.function(ModelProgram::Jacobian), {}, 2);  // J = cj - a
  j.op(Opcode::LoadCj, {j.r(0)}).op(Opcode::LoadP, {j.r(1), 0}).op(Opcode::Sub, {j.r(0), j.r(0), j.r(1)});
  j.op(Opcode::Store, {0, j.r(0)}).ret(1);
  Assembler(m.function(ModelProgram::Outputs), {}, 0).ret(0);
  Assembler(m.function(ModelProgram::Invariants), {}, 0).ret(0);
  return m;
}

}  // namespace qdot::test
