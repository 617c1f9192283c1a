// The VM behind the model ABI on hand-written modules: the function table, sizes and names,
// serialisation round trips and rejection of malformed bytes, validation of everything the
// interpreter trusts, and domain errors traced to the instruction and location that caused them.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "Assembler.h"
#include "vm/Vm.h"

namespace qdot::test {
namespace {

using bc::Opcode;

// A VM model of `module`; the test fails if it does not validate.
struct VmModel {
  ModelPtr owned;
  QdotModel* m = nullptr;
  explicit VmModel(const bc::Module& module) {
    Result<ModelPtr> created = vm::createModel(module);
    EXPECT_TRUE(created.ok()) << created.error();
    if (created) owned = std::move(created).value(), m = owned.get();
  }
};

TEST(ModelAbi, TableDescribesTheModule) {
  VmModel p(tinyModule());
  QdotModel* m = p.m;
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->abiVersion, QDOT_MODEL_ABI_VERSION);
  EXPECT_STREQ(m->name, "Tiny");
  EXPECT_EQ(m->nVariables, 1u);
  EXPECT_EQ(m->nParameters, 1u);
  EXPECT_STREQ(m->variableNames[0], "x");
  EXPECT_STREQ(m->parameterDescriptions[0], "a parameter");
  EXPECT_EQ(m->jacobianNonzeros, 1u);
  EXPECT_EQ(m->jacobianColumnStarts[1], 1);
  EXPECT_STREQ(m->lastError(m), "");
  double given = 0.5, a = 0, y0, yp0, nominal, x = 2, xp = 3, F, J;
  uint8_t overridden = 1;
  int32_t fixed = 0;
  EXPECT_EQ(m->parameters(m, &given, &overridden, &a), 0);
  EXPECT_EQ(a, 0.5);
  EXPECT_EQ(m->initialValues(m, &a, 0, &y0, &yp0, &nominal), 0);
  EXPECT_EQ(y0, 1.0);
  EXPECT_EQ(m->fixedStarts(m, &fixed), 0);
  EXPECT_EQ(fixed, 1);
  EXPECT_EQ(m->residual(m, 0, &x, &xp, &a, &F), 0);
  EXPECT_EQ(F, 3 - 0.5 * 2);
  EXPECT_EQ(m->jacobian(m, 0, &x, &xp, &a, 10, &J), 0);
  EXPECT_EQ(J, 10 - 0.5);
  EXPECT_EQ(m->outputs(m, 0, &x, &xp, &a, nullptr), 0);
}

TEST(ModelAbi, NaNInputIsNamed) {
  VmModel p(tinyModule());
  double a = 0.5, x = std::nan(""), xp = 1, F;
  EXPECT_EQ(p.m->residual(p.m, 0, &x, &xp, &a, &F), 1);
  EXPECT_STREQ(p.m->lastError(p.m), "the value of x is nan in equation 1 at tiny.qd:3");
}

// F = sqrt(x) + (x > 0 ? sqrt(x) ... ) built by hand: the culprit is the sqrt, even though the NaN
// passes through registers that are reused and a select whose other branch is fine.
TEST(ModelAbi, DomainErrorIsTracedToItsInstruction) {
  bc::Module module = tinyModule();
  module.locations.push_back({"equation 2", "tiny.qd:7", "y = sqrt(x)"});
  Assembler f(module.function(ModelProgram::Residual), {0.0}, 3);
  f.op(Opcode::LoadY, {f.r(0), 0}, 0).op(Opcode::Lt, {f.r(1), 0, f.r(0)}, 0);  // 0 < x
  f.op(Opcode::Sqrt, {f.r(2), f.r(0)}, 1).op(Opcode::Select, {f.r(1), f.r(1), f.r(2), 0}, 0);  // untaken if x < 0
  f.op(Opcode::Store, {0, f.r(1)}, 0).ret(1);
  VmModel p(module);
  double a = 1, x = -4, xp = 0, F;
  EXPECT_EQ(p.m->residual(p.m, 0, &x, &xp, &a, &F), 0) << p.m->lastError(p.m);
  EXPECT_EQ(F, 0.0);
  Assembler g(module.function(ModelProgram::Residual), {0.0}, 2);
  g.op(Opcode::LoadY, {g.r(0), 0}, 0).op(Opcode::Sqrt, {g.r(0), g.r(0)}, 1);
  g.op(Opcode::Exp, {g.r(1), g.r(0)}, 0).op(Opcode::Add, {g.r(0), g.r(1), 0}, 0).op(Opcode::Store, {0, g.r(0)}, 0);
  g.ret(1);
  VmModel q(module);
  EXPECT_EQ(q.m->residual(q.m, 0, &x, &xp, &a, &F), 1);
  EXPECT_STREQ(q.m->lastError(q.m),
               "sqrt of a negative number (-4) in equation 2 at tiny.qd:7, which makes equation 1 at tiny.qd:3 non-finite");
}

TEST(ModelAbi, UndefinedConstantAndOverflow) {
  bc::Module module = tinyModule();
  Assembler f(module.function(ModelProgram::Parameters), {std::nan("")}, 1);
  f.op(Opcode::LoadOverridden, {f.r(0), 0}, 0).op(Opcode::Select, {f.r(0), f.r(0), 0, 0}, 0);
  f.op(Opcode::Store, {0, f.r(0)}, 0).ret(1);
  VmModel p(module);
  double a;
  EXPECT_EQ(p.m->parameters(p.m, nullptr, nullptr, &a), 1);
  EXPECT_STREQ(p.m->lastError(p.m), "undefined value (nan) in equation 1 at tiny.qd:3 (computing parameters)");
  Assembler g(module.function(ModelProgram::Residual), {800.0}, 1);
  g.op(Opcode::Exp, {g.r(0), 0}, 0).op(Opcode::Store, {0, g.r(0)}, 0).ret(1);
  VmModel q(module);
  double x = 0, xp = 0, F;
  EXPECT_EQ(q.m->residual(q.m, 0, &x, &xp, &a, &F), 1);
  EXPECT_STREQ(q.m->lastError(q.m), "overflow in exp (inf) in equation 1 at tiny.qd:3");
}

TEST(Serialization, RoundTrip) {
  bc::Module m = tinyModule();
  std::vector<uint8_t> bytes = bc::serialize(m);
  Result<bc::Module> read = bc::deserialize(bytes);
  ASSERT_TRUE(read.ok()) << read.error();
  const bc::Module& back = read.value();
  EXPECT_EQ(bc::serialize(back), bytes);
  EXPECT_EQ(back.locations[0].text, "der(x) = a*x");
  EXPECT_EQ(back.function(ModelProgram::Residual).code, m.function(ModelProgram::Residual).code);
  Result<ModelPtr> q = vm::createModelFromBytes(bytes);
  EXPECT_TRUE(q.ok()) << q.error();
}

TEST(Serialization, MalformedBytesAreRejected) {
  std::vector<uint8_t> bytes = bc::serialize(tinyModule());
  for (size_t cut : {size_t(0), size_t(3), size_t(8), bytes.size() / 2, bytes.size() - 1}) {
    Result<bc::Module> m = bc::deserialize(std::span(bytes.data(), cut));
    EXPECT_FALSE(m.ok()) << cut;
    EXPECT_FALSE(m.error().empty());
  }
  auto bad = bytes;
  bad[4] = 99;  // version
  Result<bc::Module> m = bc::deserialize(bad);
  EXPECT_FALSE(m.ok());
  EXPECT_NE(m.error().find("version 99"), std::string::npos) << m.error();
  bad = bytes;
  bad.push_back(0);
  m = bc::deserialize(bad);
  EXPECT_FALSE(m.ok());
  EXPECT_EQ(m.error(), "trailing bytes after the bytecode module");
  bad = bytes;
  bad[8] = 0xff, bad[9] = 0xff, bad[10] = 0xff, bad[11] = 0x7f;  // absurd name length
  EXPECT_FALSE(bc::deserialize(bad).ok());
}

std::string invalid(const std::function<void(bc::Module&)>& spoil) {
  bc::Module m = tinyModule();
  spoil(m);
  Status valid = bc::validate(m);
  EXPECT_FALSE(valid.ok());
  return valid.error();
}

TEST(Validation, RejectsWhatTheInterpreterTrusts) {
  Status ok = bc::validate(tinyModule());
  EXPECT_TRUE(ok.ok()) << ok.error();
  auto R = [](bc::Module& m) -> bc::Function& { return m.function(ModelProgram::Residual); };
  EXPECT_NE(invalid([&](bc::Module& m) { R(m).code[0] = 200; }).find("bad opcode 200"), std::string::npos);
  EXPECT_NE(invalid([&](bc::Module& m) { R(m).code.pop_back(); }).find("ret"), std::string::npos);
  EXPECT_NE(invalid([&](bc::Module& m) { R(m).code[1] = 99; }).find("operand out of range"), std::string::npos);
  EXPECT_NE(invalid([&](bc::Module& m) { R(m).outputCount = 2; }).find("output count"), std::string::npos);
  EXPECT_NE(invalid([&](bc::Module& m) { R(m).sources.pop_back(); }).find("source table"), std::string::npos);
  EXPECT_NE(invalid([](bc::Module& m) {
              Assembler a(m.function(ModelProgram::Parameters), {1.0}, 1);
              a.op(Opcode::LoadY, {a.r(0), 0}).op(Opcode::Store, {0, a.r(0)}).ret(1);
            }).find("ldy is not available"),
            std::string::npos);
  EXPECT_NE(invalid([](bc::Module& m) {
              Assembler a(m.function(ModelProgram::Residual), {1.0}, 1);
              a.op(Opcode::LoadY, {0, 0}).op(Opcode::Store, {0, 0}).ret(1);  // writes the constant register
            }).find("operand out of range in ldy"),
            std::string::npos);
  EXPECT_NE(invalid([](bc::Module& m) { m.description.edit().jacobianRowIndices = {3}; }).find("Jacobian"), std::string::npos);
  EXPECT_NE(invalid([](bc::Module& m) { m.description.edit().fixed.clear(); }).find("per-variable"), std::string::npos);
  bc::Module broken = tinyModule();
  broken.function(ModelProgram::Jacobian).code.clear();
  Result<ModelPtr> model = vm::createModel(broken);
  EXPECT_FALSE(model.ok());
  EXPECT_NE(model.error().find("function jacobian"), std::string::npos) << model.error();
}

}  // namespace
}  // namespace qdot::test
