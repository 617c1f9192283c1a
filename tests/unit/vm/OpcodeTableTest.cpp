// The opcode table (qdot/opcodes.def) round trip: every opcode has a unique mnemonic that maps
// back to it, the disassembler prints every opcode, the computed-goto and switch loops agree bit
// for bit on every opcode, and the semantics of the opcodes with edge cases are pinned down.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <set>
#include <sstream>

#include "Assembler.h"
#include "vm/Interpreter.h"
#include "vm/Vm.h"

namespace qdot::test {
namespace {

using bc::Opcode;

TEST(OpcodeTable, MnemonicsAreUniqueAndMapBack) {
  std::set<std::string> seen;
  for (uint32_t i = 0; i < bc::kOpcodeCount; ++i) {
    auto op = static_cast<Opcode>(i);
    EXPECT_TRUE(seen.insert(bc::info(op).mnemonic).second) << bc::info(op).mnemonic;
    Opcode back = Opcode::Ret;
    ASSERT_TRUE(bc::opcodeFromMnemonic(bc::info(op).mnemonic, back));
    EXPECT_EQ(back, op);
  }
  Opcode unused;
  EXPECT_FALSE(bc::opcodeFromMnemonic("frobnicate", unused));
}

// A residual-like function using every opcode once, inside a loop of one iteration (offset 0) so
// that the looped opcodes are allowed: registers 0..2 are constants, the loads fill the next ones,
// and every computing opcode stores its result in out[k]; stl and stx store the last one again, and
// stadd adds it to out[0].
struct EveryOpcode {
  bc::Module module = tinyModule();
  uint32_t outputs = 0;

  EveryOpcode() {
    bc::Function& f = module.function(ModelProgram::Jacobian);
    Assembler a(f, {0.75, -1.5, 2.0}, bc::kOpcodeCount);
    f.loops = {Loop{.count = 1, .first = 0, .stride = 1}};
    a.op(Opcode::LoopBegin, {0, 0});
    uint32_t next = a.r(0);
    for (uint32_t i = 0; i < bc::kOpcodeCount; ++i) {
      auto op = static_cast<Opcode>(i);
      uint32_t d = next++;
      switch (bc::info(op).format) {
        case bc::Format::End:
        case bc::Format::Store:
        case bc::Format::StoreAdd:
        case bc::Format::StoreLooped:
        case bc::Format::StoreIndexed:
        case bc::Format::LoopBegin:
        case bc::Format::LoopEnd: continue;
        case bc::Format::None: a.op(op, {d}); break;
        case bc::Format::Index: a.op(op, {d, 0}); break;
        case bc::Format::Unary: a.op(op, {d, 0}); break;
        case bc::Format::Binary: a.op(op, {d, 0, 1}); break;
        case bc::Format::Ternary: a.op(op, {d, 1, 0, 2}); break;
        case bc::Format::UnaryIndex: a.op(op, {d, 1, static_cast<uint32_t>(-3)}); break;
      }
      a.op(Opcode::Store, {outputs++, d});
    }
    f.indexTable = {outputs + 1};
    a.op(Opcode::StoreLooped, {outputs, next - 1}).op(Opcode::StoreIndexed, {0, next - 1}).op(Opcode::StoreAdd, {0, next - 1});
    a.op(Opcode::LoopEnd, {0});
    f.code[2] = static_cast<uint32_t>(f.code.size());  // the loop's exit: after its endloop
    outputs += 2;
    a.ret(outputs);
  }
};

TEST(OpcodeTable, DisassemblerPrintsEveryOpcode) {
  EveryOpcode m;
  std::ostringstream os;
  vm::disassembleFunction(os, m.module, ModelProgram::Jacobian);
  std::string text = os.str();
  for (uint32_t i = 0; i < bc::kOpcodeCount; ++i) {
    std::string name = std::string("  ") + bc::kOpcodes[i].mnemonic;
    bool found = text.find(name + " ") != std::string::npos || text.find(name + "\n") != std::string::npos;
    EXPECT_TRUE(found) << bc::kOpcodes[i].mnemonic << " missing";
  }
  EXPECT_EQ(text.rfind("  ret\n"), text.size() - 6);  // ret comes last
  EXPECT_NE(text.find("powi    r"), std::string::npos);
  EXPECT_NE(text.find(", -3"), std::string::npos);
}

TEST(Dispatch, ComputedGotoAndSwitchAgreeOnEveryOpcode) {
  EveryOpcode m;
  const bc::Function& f = m.module.function(ModelProgram::Jacobian);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 200; ++trial) {
    double y[] = {u(rng)}, yp[] = {u(rng)}, p[] = {u(rng)}, given[] = {u(rng)};
    uint8_t overridden[] = {static_cast<uint8_t>(trial % 2)};
    ModelCall in{.t = u(rng), .cj = u(rng), .y = y, .yp = yp, .p = p, .given = given, .overridden = overridden};
    std::vector<double> r1 = vm::makeRegisters(f), r2 = r1, o1(m.outputs), o2(m.outputs);
    r1[0] = r2[0] = u(rng), r1[1] = r2[1] = u(rng);  // vary the operands of the computing opcodes
    vm::execute(f, r1.data(), in, o1.data());
    vm::executeWithSwitch(f, r2.data(), in, o2.data());
    for (uint32_t k = 0; k < m.outputs; ++k) EXPECT_EQ(std::bit_cast<uint64_t>(o1[k]), std::bit_cast<uint64_t>(o2[k]));
  }
}

// out[0] = op(a, b) computed by the VM.
double apply(Opcode op, double a, double b = 0, uint32_t imm = 0) {
  bc::Module m = tinyModule();
  bc::Function& f = m.function(ModelProgram::Jacobian);
  Assembler as(f, {a, b}, 1);
  bc::Format fmt = bc::info(op).format;
  if (fmt == bc::Format::Unary) as.op(op, {as.r(0), 0});
  if (fmt == bc::Format::Binary) as.op(op, {as.r(0), 0, 1});
  if (fmt == bc::Format::UnaryIndex) as.op(op, {as.r(0), 0, imm});
  as.op(Opcode::Store, {0, as.r(0)}).ret(1);
  std::vector<double> r = vm::makeRegisters(f), out(1);
  vm::execute(f, r.data(), {}, out.data());
  return out[0];
}

TEST(Semantics, EdgeCases) {
  EXPECT_EQ(apply(Opcode::Powi, -2, 0, 3), -8);
  EXPECT_EQ(apply(Opcode::Powi, 2, 0, static_cast<uint32_t>(-2)), 0.25);
  EXPECT_EQ(apply(Opcode::Powi, 0, 0, 0), 1);
  EXPECT_NEAR(apply(Opcode::Powi, 1.1, 0, 16), std::pow(1.1, 16), 16 * 2.3e-16 * std::pow(1.1, 16));
  EXPECT_EQ(apply(Opcode::Sign, -0.0), 0.0);
  EXPECT_EQ(apply(Opcode::Sign, -3), -1.0);
  EXPECT_TRUE(std::isnan(apply(Opcode::Sign, std::nan(""))));
  EXPECT_EQ(apply(Opcode::Min, std::nan(""), 1), 1);  // fmin, as sym::evaluate
  EXPECT_EQ(apply(Opcode::Max, 2, std::nan("")), 2);
  EXPECT_EQ(apply(Opcode::And, 2, -1), 1);
  EXPECT_EQ(apply(Opcode::Or, 0, 0), 0);
  EXPECT_EQ(apply(Opcode::Not, 0.5), 0);
  EXPECT_EQ(apply(Opcode::Le, 1, 1), 1);
  EXPECT_EQ(apply(Opcode::Ne, 1, 1), 0);
  EXPECT_EQ(apply(Opcode::Atan2, 1, -1), std::atan2(1.0, -1.0));
  EXPECT_TRUE(std::isnan(apply(Opcode::Sqrt, -1)));
}

// stadd adds to what the slot holds: a sum over a loop's iterations, started by a `st`.
TEST(Semantics, StoreAddSumsOverALoop) {
  bc::Module m = tinyModule();
  bc::Function& f = m.function(ModelProgram::Jacobian);
  Assembler a(f, {0.5}, 2);
  f.loops = {Loop{.count = 4, .first = 0, .stride = 1}};
  a.op(Opcode::Store, {0, 0}).op(Opcode::LoopBegin, {0, 0});
  size_t loopWord = f.code.size() - 3;
  a.op(Opcode::LoadLoopOffset, {a.r(0)}).op(Opcode::StoreAdd, {0, a.r(0)}).op(Opcode::LoopEnd, {0});
  f.code[loopWord + 2] = static_cast<uint32_t>(f.code.size() - loopWord);
  a.ret(1);
  std::vector<double> r = vm::makeRegisters(f), out(1, -7.0);
  vm::execute(f, r.data(), {}, out.data());
  EXPECT_EQ(out[0], 0.5 + 0 + 1 + 2 + 3);
}

}  // namespace
}  // namespace qdot::test
