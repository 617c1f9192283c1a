// Loops in bytecode written by hand: the VM runs affine and table loops (peeled stencil ends,
// count 0 and 1, invariant registers, stx through a permutation, ldidx, negative offsets, a
// parameter array read with ldpl) exactly as the direct C++ computation; modules with loops
// survive serialisation; the validator rejects every broken loop rule (an ldpl outside the
// parameters too); a non-finite value inside a loop is named with its iteration and offset.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <functional>
#include <random>

#include "Assembler.h"
#include "vm/Interpreter.h"
#include "vm/Vm.h"

namespace qdot::test {
namespace {

using bc::Opcode;

// A model of n variables x0..x{n-1} and one parameter k whose residual the test writes.
bc::Module loopModule(uint32_t n) {
  bc::Module m = tinyModule();
  ModelDescription& d = m.description.edit();
  d.variableNames.clear();
  for (uint32_t i = 0; i < n; ++i) d.variableNames.push_back("x" + std::to_string(i));
  d.isDifferential.assign(n, 1), d.fixed.assign(n, 0);
  d.jacobianColumnStarts.assign(n + 1, 0), d.jacobianRowIndices.clear();
  Assembler(m.function(ModelProgram::InitialValues), {}, 0).ret(3 * n);
  Assembler(m.function(ModelProgram::Jacobian), {}, 0).ret(0);
  return m;
}

// Appends `loop id, exit` and patches the exit at `endloop`.
struct LoopWriter {
  bc::Function& f;
  Assembler& a;
  size_t at = 0;
  void begin(uint32_t id) {
    at = f.code.size();
    a.op(Opcode::LoopBegin, {id, 0});
  }
  void end(uint32_t id) {
    a.op(Opcode::LoopEnd, {id});
    f.code[at + 2] = static_cast<uint32_t>(f.code.size() - at);
  }
};

std::vector<double> residualOf(const bc::Module& m, const std::vector<double>& y, double k = 1.5) {
  Result<ModelPtr> model = vm::createModel(m);
  EXPECT_TRUE(model.ok()) << model.error();
  std::vector<double> F(y.size(), -99.0), yp(y.size(), 0.25);
  if (!model) return F;
  QdotModel* q = model.value().get();
  EXPECT_EQ(q->residual(q, 0, y.data(), yp.data(), &k, F.data()), 0);
  return F;
}

std::vector<double> randomY(uint32_t n) {
  std::mt19937_64 rng(n);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> y(n);
  for (double& v : y) v = u(rng);
  return y;
}

// F[i] = k*(y[i+1] - 2y[i] + y[i-1]) + yp[i] with y[-1] = y[n] = 0: the ends straight-line, the
// interior one loop (L = i - 1) reading k and -2 from registers set before it.
bc::Module stencil(uint32_t n) {
  bc::Module m = loopModule(n);
  bc::Function& f = m.function(ModelProgram::Residual);
  Assembler a(f, {-2.0}, 8);
  LoopWriter w{f, a};
  f.loops = {Loop{.count = n - 2, .first = 0, .stride = 1}};
  auto [k, y0, y1, t, u, v, yp, s] = std::array{a.r(0), a.r(1), a.r(2), a.r(3), a.r(4), a.r(5), a.r(6), a.r(7)};
  a.op(Opcode::LoadP, {k, 0});
  for (uint32_t end : {0u, n - 1}) {  // peeled: k*(-2 y[end] + y[neighbour]) + yp[end]
    a.op(Opcode::LoadY, {y0, end}).op(Opcode::LoadY, {y1, end == 0 ? 1 : n - 2});
    a.op(Opcode::Mul, {t, 0, y0}).op(Opcode::Add, {t, t, y1}).op(Opcode::Mul, {t, k, t});
    a.op(Opcode::LoadYp, {yp, end}).op(Opcode::Add, {t, t, yp}).op(Opcode::Store, {end, t});
  }
  w.begin(0);
  a.op(Opcode::LoadYLooped, {y0, 2}).op(Opcode::LoadYLooped, {y1, 1}).op(Opcode::Mul, {u, 0, y1});
  a.op(Opcode::Add, {u, y0, u}).op(Opcode::LoadYLooped, {v, 0}).op(Opcode::Add, {u, u, v});
  a.op(Opcode::Mul, {u, k, u}).op(Opcode::LoadYpLooped, {s, 1}).op(Opcode::Add, {u, u, s});
  a.op(Opcode::StoreLooped, {1, u});
  w.end(0);
  a.ret(n);
  return m;
}

std::vector<double> stencilDirect(const std::vector<double>& y, double k = 1.5, double yp = 0.25) {
  size_t n = y.size();
  std::vector<double> F(n);
  F[0] = k * (-2.0 * y[0] + y[1]) + yp;
  F[n - 1] = k * (-2.0 * y[n - 1] + y[n - 2]) + yp;
  for (size_t i = 1; i + 1 < n; ++i) F[i] = k * (y[i + 1] + -2.0 * y[i] + y[i - 1]) + yp;
  return F;
}

void expectSameBits(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(std::bit_cast<uint64_t>(a[i]), std::bit_cast<uint64_t>(b[i])) << i;
}

TEST(VmLoops, StencilOverTheInteriorWithPeeledEnds) {
  for (uint32_t n : {2u, 3u, 7u, 100u}) {  // count 0, 1, 5, 98
    std::vector<double> y = randomY(n);
    expectSameBits(residualOf(stencil(n), y), stencilDirect(y));
  }
}

TEST(VmLoops, BothDispatchLoopsAgree) {
  bc::Module m = stencil(9);
  const bc::Function& f = m.function(ModelProgram::Residual);
  std::vector<double> y = randomY(9), yp(9, 0.5), r1 = vm::makeRegisters(f), r2 = r1, o1(9), o2(9);
  double k = 0.75;
  ModelCall in{.y = y.data(), .yp = yp.data(), .p = &k};
  vm::execute(f, r1.data(), in, o1.data());
  vm::executeWithSwitch(f, r2.data(), in, o2.data());
  expectSameBits(o1, o2);
  expectSameBits(o1, stencilDirect(y, 0.75, 0.5));
}

// out[X[c]] = 2*y[L] + L for the table loop L = X[n + c] (X: the permutation `perm`, then the
// offsets n-1 .. 0).
bc::Module permuted(uint32_t n, const std::vector<uint32_t>& perm) {
  bc::Module m = loopModule(n);
  bc::Function& f = m.function(ModelProgram::Residual);
  Assembler a(f, {2.0}, 3);
  LoopWriter w{f, a};
  f.indexTable = perm;
  for (uint32_t c = 0; c < n; ++c) f.indexTable.push_back(n - 1 - c);
  f.loops = {Loop{.count = n, .offsetTable = n}};
  w.begin(0);  // L = n-1-c: y[L], stored at out[X[c]]
  a.op(Opcode::LoadYLooped, {a.r(0), 0}).op(Opcode::Mul, {a.r(0), 0, a.r(0)});
  a.op(Opcode::LoadLoopOffset, {a.r(1)}).op(Opcode::Add, {a.r(2), a.r(0), a.r(1)});
  a.op(Opcode::StoreIndexed, {0, a.r(2)});
  w.end(0);
  a.ret(n);
  return m;
}

TEST(VmLoops, TableLoopStoresThroughAPermutation) {
  std::vector<uint32_t> perm = {3, 0, 4, 1, 2};
  std::vector<double> y = randomY(5), expected(5);
  for (uint32_t c = 0; c < 5; ++c) {
    uint32_t L = 4 - c;
    expected[perm[c]] = 2.0 * y[L] + double(L);
  }
  expectSameBits(residualOf(permuted(5, perm), y), expected);
}

// out[3 + L] = 0.01*L + y[3 + L] for L = -3 .. n-4: negative offsets.
TEST(VmLoops, NegativeOffsetsAndLdidx) {
  uint32_t n = 6;
  bc::Module m = loopModule(n);
  bc::Function& f = m.function(ModelProgram::Residual);
  Assembler a(f, {0.01}, 3);
  LoopWriter w{f, a};
  f.loops = {Loop{.count = n, .first = -3, .stride = 1}};
  w.begin(0);
  a.op(Opcode::LoadLoopOffset, {a.r(0)}).op(Opcode::Mul, {a.r(0), 0, a.r(0)});
  a.op(Opcode::LoadYLooped, {a.r(1), 3}).op(Opcode::Add, {a.r(2), a.r(0), a.r(1)});
  a.op(Opcode::StoreLooped, {3, a.r(2)});
  w.end(0);
  a.ret(n);
  std::vector<double> y = randomY(n), expected(n);
  for (int L = -3; L < int(n) - 3; ++L) expected[3 + L] = 0.01 * double(L) + y[3 + L];
  expectSameBits(residualOf(m, y), expected);
}

TEST(VmLoops, SerialisationKeepsLoopsAndTable) {
  bc::Module m = permuted(5, {3, 0, 4, 1, 2});
  Result<bc::Module> back = bc::deserialize(bc::serialize(m));
  ASSERT_TRUE(back.ok()) << back.error();
  const bc::Function &f = m.function(ModelProgram::Residual), &g = back->function(ModelProgram::Residual);
  EXPECT_EQ(g.code, f.code);
  EXPECT_EQ(g.indexTable, f.indexTable);
  ASSERT_EQ(g.loops.size(), 1u);
  EXPECT_EQ(g.loops[0].count, 5u);
  EXPECT_EQ(g.loops[0].offsetTable, 5u);
  bc::Module stencilModule = stencil(6);
  Result<bc::Module> again = bc::deserialize(bc::serialize(stencilModule));
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again->function(ModelProgram::Residual).loops[0].first, 0);
  std::vector<double> y = randomY(6);
  expectSameBits(residualOf(again.value(), y), stencilDirect(y));
}

// The error validate gives for the stencil after `edit`.
std::string invalidBecause(std::function<void(bc::Function&)> edit, uint32_t n = 6) {
  bc::Module m = stencil(n);
  edit(m.function(ModelProgram::Residual));
  Status s = bc::validate(m);
  return s ? "valid" : s.error();
}

// Word offset of the k-th instruction with opcode op in f.
size_t wordOf(const bc::Function& f, Opcode op, int k = 0) {
  for (size_t pc = 0; pc < f.code.size(); pc += 1 + bc::operandCount(bc::info(Opcode(f.code[pc])).format))
    if (Opcode(f.code[pc]) == op && k-- == 0) return pc;
  return SIZE_MAX;
}

TEST(VmLoopValidation, TheStencilIsValid) { EXPECT_EQ(invalidBecause([](bc::Function&) {}), "valid"); }

TEST(VmLoopValidation, RejectsALoopedLoadOutsideTheInput) {
  // y[3 + L] for L up to n-3 reaches y[n].
  std::string e = invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::LoadYLooped) + 2] = 3; });
  EXPECT_NE(e.find("ldyl index out of range"), std::string::npos) << e;
  e = invalidBecause([](bc::Function& f) { f.loops[0].first = -1; });  // y[0 + L] at L = -1
  EXPECT_NE(e.find("index out of range"), std::string::npos) << e;
  e = invalidBecause([](bc::Function& f) { f.loops[0].count = 5; });  // stl out[1 + 4] of 6 is fine, ldyl y[6] is not
  EXPECT_NE(e.find("out of range"), std::string::npos) << e;
}

TEST(VmLoopValidation, RejectsABodyRegisterReadAfterTheLoop) {
  bc::Module m = stencil(6);
  bc::Function& f = m.function(ModelProgram::Residual);
  f.code.pop_back(), f.sources.pop_back();  // ret
  uint32_t bodyValue = f.code[wordOf(f, Opcode::StoreLooped) + 2];
  Assembler::append(f, Opcode::Store, {0, bodyValue});
  Assembler::append(f, Opcode::Ret, {});
  Status s = bc::validate(m);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("is read after its endloop"), std::string::npos) << s.error();
}

TEST(VmLoopValidation, RejectsARegisterReadInTheBodyBeforeTheBodyWritesIt) {
  // The body's last add writes k's register, which the body reads earlier (k*...): the next
  // iteration would read the add's value instead of k.
  std::string e = invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::Add, 6) + 1] = f.code[wordOf(f, Opcode::LoadP) + 1]; });
  EXPECT_NE(e.find("before the body writes it"), std::string::npos) << e;
}

TEST(VmLoopValidation, RejectsANestedLoop) {
  bc::Module m = loopModule(4);
  bc::Function& f = m.function(ModelProgram::Residual);
  Assembler a(f, {}, 1);
  LoopWriter outer{f, a}, inner{f, a};
  f.loops = {Loop{.count = 2}, Loop{.count = 2}};
  outer.begin(0);
  inner.begin(1);
  inner.end(1);
  outer.end(0);
  a.ret(4);
  Status s = bc::validate(m);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("nested loop"), std::string::npos) << s.error();
}

TEST(VmLoopValidation, RejectsALoopedOpcodeOutsideALoop) {
  std::string e = invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::LoadY)] = uint32_t(Opcode::LoadYLooped); });
  EXPECT_NE(e.find("ldyl outside a loop"), std::string::npos) << e;
  e = invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::Store)] = uint32_t(Opcode::StoreLooped); });
  EXPECT_NE(e.find("stl outside a loop"), std::string::npos) << e;
}

TEST(VmLoopValidation, RejectsBrokenLoopControl) {
  EXPECT_NE(invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::LoopBegin) + 2] += 1; }).find("loop exit"),
            std::string::npos);
  EXPECT_NE(invalidBecause([](bc::Function& f) { f.code[wordOf(f, Opcode::LoopEnd) + 1] = 1; }).find("does not close"),
            std::string::npos);
  EXPECT_NE(invalidBecause([](bc::Function& f) { f.loops.clear(); }).find("loop id out of range"), std::string::npos);
  EXPECT_NE(invalidBecause([](bc::Function& f) { f.loops[0] = Loop{.count = 4, .offsetTable = 0}; }).find("table"),
            std::string::npos);
}

TEST(VmLoopValidation, RejectsAnStxSlotOutsideTheOutputs) {
  bc::Module m = permuted(5, {3, 0, 5, 1, 2});
  Status s = bc::validate(m);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("stx"), std::string::npos) << s.error();
}

// F[i] = a[i + 1]*y[i] for i = 0 .. n-2: a parameter array read in a loop (ldpl p[1 + L]), n
// parameters a0 .. a{n-1} (each its given value).
bc::Module parameterLoop(uint32_t n) {
  bc::Module m = loopModule(n);
  ModelDescription& d = m.description.edit();
  d.parameterNames.clear(), d.parameterDescriptions.clear();
  for (uint32_t i = 0; i < n; ++i) d.parameterNames.push_back("a" + std::to_string(i));
  d.parameterDescriptions.assign(n, "");
  Assembler pa(m.function(ModelProgram::Parameters), {}, 1);
  for (uint32_t i = 0; i < n; ++i) pa.op(Opcode::LoadGiven, {pa.r(0), i}).op(Opcode::Store, {i, pa.r(0)});
  pa.ret(n);
  bc::Function& f = m.function(ModelProgram::Residual);
  Assembler a(f, {0.0}, 2);
  LoopWriter w{f, a};
  f.loops = {Loop{.count = n - 1, .first = 0, .stride = 1}};
  a.op(Opcode::Store, {n - 1, 0});
  w.begin(0);
  a.op(Opcode::LoadPLooped, {a.r(0), 1}).op(Opcode::LoadYLooped, {a.r(1), 0});
  a.op(Opcode::Mul, {a.r(0), a.r(0), a.r(1)}).op(Opcode::StoreLooped, {0, a.r(0)});
  w.end(0);
  a.ret(n);
  return m;
}

TEST(VmLoops, ALoopedParameterLoadReadsItsArrayElement) {
  const uint32_t n = 7;
  bc::Module m = parameterLoop(n);
  ASSERT_TRUE(bc::validate(m)) << bc::validate(m).error();
  Result<ModelPtr> model = vm::createModel(m);
  ASSERT_TRUE(model.ok()) << model.error();
  QdotModel* q = model.value().get();
  std::vector<double> y = randomY(n), yp(n, 0.0), p(n), F(n, -99.0);
  for (uint32_t i = 0; i < n; ++i) p[i] = 0.5 + i * i;
  EXPECT_EQ(q->residual(q, 0, y.data(), yp.data(), p.data(), F.data()), 0);
  for (uint32_t i = 0; i + 1 < n; ++i)
    EXPECT_EQ(std::bit_cast<uint64_t>(F[i]), std::bit_cast<uint64_t>(p[i + 1] * y[i])) << i;
  EXPECT_EQ(F[n - 1], 0.0);
}

TEST(VmLoops, ANonFiniteParameterReadInALoopIsNamed) {
  const uint32_t n = 6;
  Result<ModelPtr> model = vm::createModel(parameterLoop(n));
  ASSERT_TRUE(model.ok()) << model.error();
  QdotModel* q = model.value().get();
  std::vector<double> y = randomY(n), yp(n, 0.0), p(n, 1.0), F(n);
  p[3] = std::nan("");  // read by iteration c = 2 (a[1 + L], L = 2)
  EXPECT_EQ(q->residual(q, 0, y.data(), yp.data(), p.data(), F.data()), 1);
  std::string e = q->lastError(q);
  EXPECT_NE(e.find("parameter a3 is nan"), std::string::npos) << e;
  EXPECT_NE(e.find("loop iteration 2, offset 2"), std::string::npos) << e;
}

TEST(VmLoopValidation, RejectsALoopedParameterLoadOutsideTheParameters) {
  bc::Module m = parameterLoop(5);
  bc::Function& residual = m.function(ModelProgram::Residual);
  residual.code[wordOf(residual, Opcode::LoadPLooped) + 2] = 2;  // a[2 + L] reaches a[5] at L = 3
  Status s = bc::validate(m);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("ldpl index out of range"), std::string::npos) << s.error();
  bc::Module outside = parameterLoop(5);
  bc::Function& f = outside.function(ModelProgram::Parameters);
  f.code[wordOf(f, Opcode::LoadGiven)] = uint32_t(Opcode::LoadPLooped);  // the parameters function has no p
  s = bc::validate(outside);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("ldpl"), std::string::npos) << s.error();
}

// ldx reads X[imm + c] as a number; the validator wants that entry in the table at every iteration.
TEST(VmLoopValidation, ATableEntryReadAsANumberStaysInTheTable) {
  const uint32_t n = 5;
  bc::Module m = parameterLoop(n);
  bc::Function& f = m.function(ModelProgram::Residual);
  f.code[wordOf(f, Opcode::LoadPLooped)] = uint32_t(Opcode::LoadTable);  // X[1 + c] instead of a[1 + L]
  f.indexTable = {0, 10, 20, 30, 40};
  ASSERT_TRUE(bc::validate(m)) << bc::validate(m).error();
  Result<ModelPtr> model = vm::createModel(m);
  ASSERT_TRUE(model.ok()) << model.error();
  QdotModel* q = model.value().get();
  std::vector<double> y = randomY(n), yp(n, 0.0), p(n, 1.0), F(n, -99.0);
  EXPECT_EQ(q->residual(q, 0, y.data(), yp.data(), p.data(), F.data()), 0);
  for (uint32_t c = 0; c + 1 < n; ++c) EXPECT_EQ(F[c], 10.0 * (c + 1) * y[c]) << c;
  f.indexTable.pop_back();  // X[4] missing at c = 3
  Status s = bc::validate(m);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find("ldx index table position out of range"), std::string::npos) << s.error();
}

TEST(VmLoops, ANonFiniteValueInsideALoopNamesItsIterationAndOffset) {
  bc::Module m = stencil(8);
  Result<ModelPtr> model = vm::createModel(m);
  ASSERT_TRUE(model.ok()) << model.error();
  std::vector<double> y = randomY(8), yp(8, 0.0), F(8);
  y[2] = std::nan("");  // the peeled ends read y0, y1, y6, y7; iteration c = 0 reads y[2]
  double k = 1.0;
  QdotModel* q = model.value().get();
  EXPECT_EQ(q->residual(q, 0, y.data(), yp.data(), &k, F.data()), 1);
  std::string e = q->lastError(q);
  EXPECT_NE(e.find("the value of x2 is nan"), std::string::npos) << e;
  EXPECT_NE(e.find("loop iteration 0, offset 0"), std::string::npos) << e;
}

}  // namespace
}  // namespace qdot::test
