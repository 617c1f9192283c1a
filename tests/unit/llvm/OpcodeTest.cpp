// Every opcode of qdot/opcodes.def, compiled by the JIT, against kernel::interpret bit for bit on
// special values (signed zeros, infinities, NaN, subnormals, huge and ordinary numbers) — in
// particular min/max/sign/logic on NaN and ±0, and powi's exact multiplication sequence.
#include <limits>

#include "KernelSource.h"

namespace qdot::test {
namespace {

using kernel::Instr;
using kernel::Op;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const std::vector<double> kValues = {0.0, -0.0, 1.0, -1.0, 2.5, -3.75, 0.3, 1e308, -1e-310, kInf, -kInf, kNaN};

// A module whose residual program applies every opcode to y0, y1, y2 (one output each).
kernel::KernelModule opcodeModule() {
  kernel::Program res;
  res.name = "residual";
  auto add = [&](Op op, uint32_t a = 0, uint32_t b = 0, uint32_t c = 0, uint32_t imm = 0) {
    res.code.push_back(Instr{op, a, b, c, imm, UINT32_MAX});
    return static_cast<uint32_t>(res.code.size() - 1);
  };
  uint32_t x = add(Op::LoadY, 0, 0, 0, 0), y = add(Op::LoadY, 0, 0, 0, 1), z = add(Op::LoadY, 0, 0, 0, 2);
  res.constants = {0.5, -2.0};
  std::vector<uint32_t> results = {add(Op::LoadTime), add(Op::LoadCj), add(Op::LoadYp, 0, 0, 0, 1),
                                   add(Op::LoadP, 0, 0, 0, 0), add(Op::LoadConst, 0, 0, 0, 1)};
  for (Op op : {Op::Add, Op::Sub, Op::Mul, Op::Div, Op::Pow, Op::Atan2, Op::Min, Op::Max, Op::Lt, Op::Le, Op::Eq,
                Op::Ne, Op::And, Op::Or})
    results.push_back(add(op, x, y)), results.push_back(add(op, y, x));
  for (Op op : {Op::Neg, Op::Sqrt, Op::Sin, Op::Cos, Op::Tan, Op::Asin, Op::Acos, Op::Atan, Op::Sinh, Op::Cosh,
                Op::Tanh, Op::Exp, Op::Log, Op::Abs, Op::Sign, Op::Not})
    results.push_back(add(op, x));
  for (int32_t e : {3, -3, 4, 5, -7, 11, 16, -16}) results.push_back(add(Op::Powi, x, 0, 0, static_cast<uint32_t>(e)));
  results.push_back(add(Op::Select, x, y, z));
  results.push_back(add(Op::Select, z, x, y));
  for (uint32_t i = 0; i < results.size(); ++i) add(Op::Store, results[i], 0, 0, i);
  add(Op::StoreAdd, results[6], 0, 0, 0);  // out[0] = t + (x + y)
  res.outputCount = static_cast<uint32_t>(results.size());

  kernel::KernelModule m;
  ModelDescription& d = m.description.edit();
  d.name = "Opcodes";
  size_t n = results.size();
  for (size_t i = 0; i < n; ++i) d.variableNames.push_back("v" + std::to_string(i));
  d.isDifferential.assign(n, 0);
  d.fixed.assign(n, 0);
  d.jacobianColumnStarts.assign(n + 1, 0);
  d.parameterNames = {"a", "b"};
  d.parameterDescriptions = {"", ""};
  kernel::Program& params = m.program(ModelProgram::Parameters);
  params.name = "parameters";
  params.code = {Instr{Op::LoadOverridden, 0, 0, 0, 0}, Instr{Op::LoadGiven, 0, 0, 0, 0},
                 Instr{Op::LoadConst, 0, 0, 0, 0},      Instr{Op::Select, 0, 1, 2, 0},
                 Instr{Op::Store, 3, 0, 0, 0},          Instr{Op::LoadOverridden, 0, 0, 0, 1},
                 Instr{Op::Store, 5, 0, 0, 1}};
  params.constants = {7.0};
  params.outputCount = 2;
  m.program(ModelProgram::InitialValues).outputCount = static_cast<uint32_t>(3 * n);
  m.program(ModelProgram::Residual) = res;
  return m;
}

void checkEveryOpcode(int optLevel, uint32_t split) {
  kernel::KernelModule k = opcodeModule();
  SourceManager sm;
  llvmbackend::JitOptions options;
  options.optLevel = options.jacobianOptLevel = options.coldOptLevel = optLevel;
  options.compiledPrograms = llvmbackend::kAllPrograms;  // the parameters program has ldgiven/ldover
  options.maxInstructionsPerFunction = split;
  Result<ModelPtr> model = llvmbackend::createJitModel(k, sm, options);
  ASSERT_TRUE(model.ok()) << model.error();
  QdotModel* q = model->get();
  size_t n = q->nVariables;
  const kernel::Program& res = k.program(ModelProgram::Residual);
  std::vector<double> p = {1.25, -4.0}, yp(n, 0.0), F(n), ref(n), y(n, 0.0);
  yp[1] = -0.0;
  size_t mismatches = 0;
  for (double a : kValues)
    for (double b : kValues) {
      y[0] = a, y[1] = b, y[2] = a == b ? 0.0 : 1.0;
      q->residual(q, 3.5, y.data(), yp.data(), p.data(), F.data());
      ModelCall in;
      in.t = 3.5, in.y = y.data(), in.yp = yp.data(), in.p = p.data();
      kernel::interpret(res, in, ref);
      for (size_t i = 0; i < n; ++i)
        if (!sameBits(F[i], ref[i]) && ++mismatches < 20)
          ADD_FAILURE() << "O" << optLevel << " output " << i << " (opcode "
                        << kernel::mnemonic(res.code[res.code.size() - n + i].op) << " chain) at (" << a << ", " << b
                        << "): jit " << F[i] << " vs " << ref[i];
    }
  EXPECT_EQ(mismatches, 0u);
  // Parameters: ldover / ldgiven / sel.
  std::vector<double> given = {3.0, 0.0}, out(2);
  std::vector<uint8_t> flags = {1, 0};
  q->parameters(q, given.data(), flags.data(), out.data());
  EXPECT_EQ(out[0], 3.0);
  EXPECT_EQ(out[1], 0.0);
  flags = {0, 2};
  q->parameters(q, given.data(), flags.data(), out.data());
  EXPECT_EQ(out[0], 7.0);
  EXPECT_EQ(out[1], 1.0);
}

TEST(JitOpcodes, EveryOpcodeMatchesTheInterpreterBitForBitAtO2) { checkEveryOpcode(2, 5000); }
TEST(JitOpcodes, EveryOpcodeMatchesTheInterpreterBitForBitAtO0) { checkEveryOpcode(0, 5000); }
TEST(JitOpcodes, EveryOpcodeMatchesTheInterpreterWhenSplit) { checkEveryOpcode(2, 4); }

}  // namespace
}  // namespace qdot::test
