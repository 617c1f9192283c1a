// Kernel IR -> LLVM IR. Straight-line code is one basic block; a loop (qdot/loop.hpp) becomes a
// body block branching back to itself, with a phi for the iteration c (i64) and the offset L
// computed from first/stride or loaded from the index table, a private constant global of the
// module; the body's registers are SSA values of the body block. The inputs' addresses and the
// values an earlier part computed are loaded in the entry block, so they dominate every loop.
// Semantics follow kernel::interpret (qdot/opcodes.def) bit for bit where LLVM allows it:
//  - sqrt, fabs, sin, cos, exp, log, pow are LLVM intrinsics (lowered to the same libm calls or
//    to correctly rounded instructions); tan, asin, acos, atan, sinh, cosh, tanh, atan2 are libm calls;
//  - powi is expanded into the multiplications of qdot::bc::powi (same association, so exact);
//  - min/max call libm's fmin/fmax (marked nobuiltin), not llvm.minnum/maxnum: both leave the
//    choice between +0 and -0 open, and the interpreter's libm and LLVM's x86 lowering (minsd)
//    choose differently, so only the same function gives the same bits (the test checks ±0, NaN);
//  - sign is an explicit fcmp/select sequence (as qdot::bc::sign);
//  - comparisons and logic produce 1.0/0.0 with ordered compares (and 'une' for "!= 0", which is
//    true for NaN, as in C).
// No fast-math flags are set anywhere, so LLVM may not reassociate or contract.
#include "llvm/Codegen.h"

#include <array>
#include <cstddef>
#include <unordered_map>

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

namespace qdot::llvmbackend {
namespace {

using kernel::Instr;
using kernel::Loop;
using kernel::Op;

/// The arguments of every generated function, in ProgramFn order.
enum Arg : unsigned { kCall, kOut, kSpill, kArgCount };

/// The fields of qdot::ModelCall, in declaration order (the LLVM struct below mirrors its layout).
enum CallField : unsigned { kTime, kCj, kY, kYp, kP, kGiven, kOverridden, kIndexTable };
static_assert(offsetof(ModelCall, t) == 0 && offsetof(ModelCall, cj) == 8 && offsetof(ModelCall, y) == 16 &&
                  offsetof(ModelCall, overridden) == 48 && offsetof(ModelCall, indexTable) == 56 && sizeof(ModelCall) == 64,
              "the generated code reads qdot::ModelCall as {double, double, ptr x 6}");

llvm::StructType* callType(llvm::LLVMContext& c) {
  auto* ptr = llvm::PointerType::getUnqual(c);
  auto* dbl = llvm::Type::getDoubleTy(c);
  return llvm::StructType::get(c, {dbl, dbl, ptr, ptr, ptr, ptr, ptr, ptr});
}

llvm::Function* declareProgramFunction(llvm::Module& m, const std::string& name, bool internal) {
  llvm::LLVMContext& c = m.getContext();
  auto* ptr = llvm::PointerType::getUnqual(c);
  std::vector<llvm::Type*> params(kArgCount, ptr);
  auto* type = llvm::FunctionType::get(llvm::Type::getVoidTy(c), params, false);
  auto linkage = internal ? llvm::GlobalValue::InternalLinkage : llvm::GlobalValue::ExternalLinkage;
  auto* f = llvm::Function::Create(type, linkage, name, m);
  f->addFnAttr(llvm::Attribute::NoUnwind);
  for (unsigned a = 0; a < kArgCount; ++a) {
    f->addParamAttr(a, llvm::Attribute::NoCapture);
    if (a == kOut || a == kSpill) f->addParamAttr(a, llvm::Attribute::NoAlias);
    else f->addParamAttr(a, llvm::Attribute::ReadOnly);
  }
  return f;
}

/// Lowers one part of a program (instructions [begin, end)) into one function: one basic block,
/// plus a body and an after block per loop.
/// Registers defined in the part are SSA values; an earlier part's register is either redone (a
/// load or constant) or reloaded from its spill slot, once per part.
class PartLowering {
 public:
  PartLowering(const kernel::Program& p, const ProgramSplit& split, llvm::Function* f, size_t begin, size_t end,
               IndexTables tables = IndexTables::FromCall)
      : prog_(p), split_(split), mod_(*f->getParent()), b_(f->getContext()), dbl_(b_.getDoubleTy()), fn_(f),
        begin_(begin), end_(end), local_(end - begin, nullptr), tables_(tables) {}

  void emit() {
    entry_ = llvm::BasicBlock::Create(mod_.getContext(), "entry", fn_);
    b_.SetInsertPoint(entry_);
    for (size_t i = begin_; i < end_; ++i) {
      if (prog_.code[i].op == Op::LoopBegin && prog_.loops[prog_.code[i].imm].count == 0) {
        while (prog_.code[i].op != Op::LoopEnd) ++i;  // no iteration: nothing to emit
        continue;
      }
      llvm::Value* v = emit(prog_.code[i]);
      local_[i - begin_] = v;
      if (split_.spillSlot[i] != ProgramSplit::kNoSlot) b_.CreateStore(v, elementPtr(kSpill, split_.spillSlot[i], dbl_));
    }
    b_.CreateRetVoid();
  }

 private:
  llvm::Value* elementPtr(Arg a, uint32_t index, llvm::Type* type) {
    return b_.CreateConstInBoundsGEP1_64(type, fn_->getArg(a), index);
  }
  // Runs `make` with the builder at the end of the entry block (before its branch into a loop):
  // what it emits dominates the whole function and runs once, not once per iteration.
  template <class Make>
  llvm::Value* atEntry(Make make) {
    llvm::IRBuilderBase::InsertPointGuard guard(b_);
    if (llvm::Instruction* branch = entry_->getTerminator()) b_.SetInsertPoint(branch);
    else b_.SetInsertPoint(entry_);
    return make();
  }
  // Field `f` of the ModelCall: t and cj are values, the others the arrays' addresses (loaded once
  // per part, in the entry block).
  llvm::Value* callField(CallField f) {
    llvm::Value*& v = fields_[f];
    if (!v) {
      llvm::Type* type = f <= kCj ? dbl_ : static_cast<llvm::Type*>(llvm::PointerType::getUnqual(mod_.getContext()));
      v = atEntry([&] { return b_.CreateLoad(type, b_.CreateStructGEP(callType(mod_.getContext()), fn_->getArg(kCall), f)); });
    }
    return v;
  }
  llvm::Value* inputPtr(CallField f, uint32_t index, llvm::Type* type) {
    return b_.CreateConstInBoundsGEP1_64(type, callField(f), index);
  }
  llvm::Value* loadInput(CallField f, uint32_t index) { return b_.CreateLoad(dbl_, inputPtr(f, index, dbl_)); }

  // Register %v in this part: its value, a redone load, or a reload from the spill array.
  llvm::Value* value(uint32_t v) {
    if (v >= begin_) return local_[v - begin_];
    auto [it, fresh] = imported_.try_emplace(v, nullptr);
    if (fresh) {
      const Instr& def = prog_.code[v];
      it->second = atEntry([&] {
        return rematerialisable(def.op) ? emit(def) : b_.CreateLoad(dbl_, elementPtr(kSpill, split_.spillSlot[v], dbl_));
      });
    }
    return it->second;
  }

  // `loop`: the body block, entered with c = 0; L for this iteration.
  void beginLoop(const Instr& ins) {
    const Loop& loop = prog_.loops[ins.imm];
    llvm::BasicBlock* before = b_.GetInsertBlock();
    body_ = llvm::BasicBlock::Create(mod_.getContext(), "loop" + std::to_string(ins.imm), fn_);
    b_.CreateBr(body_);
    b_.SetInsertPoint(body_);
    c_ = b_.CreatePHI(b_.getInt64Ty(), 2, "c");
    c_->addIncoming(b_.getInt64(0), before);
    count_ = loop.count;
    if (loop.offsetTable == Loop::kNoTable) L_ = b_.CreateAdd(b_.getInt64(loop.first), b_.CreateMul(c_, b_.getInt64(loop.stride)));
    else L_ = tableEntry(loop.offsetTable);
  }
  // `endloop`: back to the body while c + 1 < count, else on in a new block.
  void endLoop(const Instr& ins) {
    llvm::Value* next = b_.CreateAdd(c_, b_.getInt64(1));
    c_->addIncoming(next, b_.GetInsertBlock());
    auto* after = llvm::BasicBlock::Create(mod_.getContext(), "after" + std::to_string(ins.imm), fn_);
    b_.CreateCondBr(b_.CreateICmpULT(next, b_.getInt64(count_)), body_, after);
    b_.SetInsertPoint(after);
  }
  // X[base + c] as an i64: from the index table the call points to, or the program's own table at
  // its address (IndexTables::InPlace).
  llvm::Value* tableEntry(uint32_t base) {
    llvm::Type* i32 = b_.getInt32Ty();
    llvm::Value* at = b_.CreateInBoundsGEP(i32, indexTable(), b_.CreateAdd(b_.getInt64(base), c_));
    return b_.CreateZExt(b_.CreateLoad(i32, at), b_.getInt64Ty());
  }
  llvm::Value* indexTable() {
    if (tables_ == IndexTables::InPlace) {
      auto address = reinterpret_cast<uint64_t>(prog_.indexTable.data());
      return llvm::ConstantExpr::getIntToPtr(b_.getInt64(address), b_.getPtrTy());
    }
    return callField(kIndexTable);
  }
  // &array[imm + L] of a looped load or store.
  llvm::Value* loopedPtr(llvm::Value* array, uint32_t imm) {
    return b_.CreateInBoundsGEP(dbl_, array, b_.CreateAdd(b_.getInt64(imm), L_));
  }

  llvm::Value* boolean(llvm::Value* cond) {
    return b_.CreateSelect(cond, llvm::ConstantFP::get(dbl_, 1.0), llvm::ConstantFP::get(dbl_, 0.0));
  }
  llvm::Value* constant(double x) { return llvm::ConstantFP::get(dbl_, x); }
  llvm::Value* isTrue(llvm::Value* x) { return b_.CreateFCmpUNE(x, constant(0.0)); }  // NaN counts as true

  llvm::Value* libm(const char* name, std::initializer_list<llvm::Value*> args) {
    std::vector<llvm::Type*> params(args.size(), dbl_);
    llvm::FunctionCallee callee = mod_.getOrInsertFunction(name, llvm::FunctionType::get(dbl_, params, false));
    if (auto* f = llvm::dyn_cast<llvm::Function>(callee.getCallee())) f->addFnAttr(llvm::Attribute::NoUnwind);
    return b_.CreateCall(callee, std::vector<llvm::Value*>(args));
  }

  // x^n by repeated squaring, the exact multiplication sequence of qdot::bc::powi.
  llvm::Value* powi(llvm::Value* x, int32_t n) {
    uint32_t m = n < 0 ? 0u - static_cast<uint32_t>(n) : static_cast<uint32_t>(n);
    llvm::Value *r = nullptr, *base = x;
    while (m) {
      if (m & 1u) r = r ? b_.CreateFMul(r, base) : base;  // 1.0 * base == base
      m >>= 1;
      if (m) base = b_.CreateFMul(base, base);
    }
    if (!r) r = constant(1.0);
    return n < 0 ? b_.CreateFDiv(constant(1.0), r) : r;
  }

  // fmin/fmax: the very libm functions kernel::interpret calls, as calls LLVM may not turn into
  // llvm.minnum/maxnum (nobuiltin), because the choice between +0 and -0 is left open by those
  // and by C (see the file comment).
  llvm::Value* minMax(llvm::Value* x, llvm::Value* y, bool isMin) {
    auto* call = llvm::cast<llvm::CallInst>(libm(isMin ? "fmin" : "fmax", {x, y}));
    call->addFnAttr(llvm::Attribute::NoBuiltin);
    return call;
  }

  // sign: 1, -1, 0 for ±0, the NaN itself for NaN.
  llvm::Value* sign(llvm::Value* x) {
    llvm::Value* zeroOrNaN = b_.CreateSelect(b_.CreateFCmpOEQ(x, constant(0.0)), constant(0.0), x);
    llvm::Value* negative = b_.CreateSelect(b_.CreateFCmpOLT(x, constant(0.0)), constant(-1.0), zeroOrNaN);
    return b_.CreateSelect(b_.CreateFCmpOGT(x, constant(0.0)), constant(1.0), negative);
  }

  llvm::Value* unary(llvm::Intrinsic::ID id, llvm::Value* x) { return b_.CreateUnaryIntrinsic(id, x); }

  llvm::Value* emit(const Instr& ins) {
    auto A = [&] { return value(ins.a); };
    auto B = [&] { return value(ins.b); };
    switch (ins.op) {
      case Op::Ret: return nullptr;
      case Op::LoadTime: return callField(kTime);
      case Op::LoadCj: return callField(kCj);
      case Op::LoadY: return loadInput(kY, ins.imm);
      case Op::LoadYp: return loadInput(kYp, ins.imm);
      case Op::LoadP: return loadInput(kP, ins.imm);
      case Op::LoadGiven: return loadInput(kGiven, ins.imm);
      case Op::LoadOverridden: {
        llvm::Value* flag = b_.CreateLoad(b_.getInt8Ty(), inputPtr(kOverridden, ins.imm, b_.getInt8Ty()));
        return boolean(b_.CreateICmpNE(flag, b_.getInt8(0)));
      }
      case Op::LoadConst: return constant(prog_.constants[ins.imm]);
      case Op::Add: return b_.CreateFAdd(A(), B());
      case Op::Sub: return b_.CreateFSub(A(), B());
      case Op::Mul: return b_.CreateFMul(A(), B());
      case Op::Div: return b_.CreateFDiv(A(), B());
      case Op::Neg: return b_.CreateFNeg(A());
      case Op::Pow: return b_.CreateBinaryIntrinsic(llvm::Intrinsic::pow, A(), B());
      case Op::Powi: return powi(A(), static_cast<int32_t>(ins.imm));
      case Op::Sqrt: return unary(llvm::Intrinsic::sqrt, A());
      case Op::Sin: return unary(llvm::Intrinsic::sin, A());
      case Op::Cos: return unary(llvm::Intrinsic::cos, A());
      case Op::Tan: return libm("tan", {A()});
      case Op::Asin: return libm("asin", {A()});
      case Op::Acos: return libm("acos", {A()});
      case Op::Atan: return libm("atan", {A()});
      case Op::Sinh: return libm("sinh", {A()});
      case Op::Cosh: return libm("cosh", {A()});
      case Op::Tanh: return libm("tanh", {A()});
      case Op::Exp: return unary(llvm::Intrinsic::exp, A());
      case Op::Log: return unary(llvm::Intrinsic::log, A());
      case Op::Abs: return unary(llvm::Intrinsic::fabs, A());
      case Op::Sign: return sign(A());
      case Op::Atan2: return libm("atan2", {A(), B()});
      case Op::Min: return minMax(A(), B(), true);
      case Op::Max: return minMax(A(), B(), false);
      case Op::Lt: return boolean(b_.CreateFCmpOLT(A(), B()));
      case Op::Le: return boolean(b_.CreateFCmpOLE(A(), B()));
      case Op::Eq: return boolean(b_.CreateFCmpOEQ(A(), B()));
      case Op::Ne: return boolean(b_.CreateFCmpUNE(A(), B()));
      case Op::And: return boolean(b_.CreateAnd(isTrue(A()), isTrue(B())));
      case Op::Or: return boolean(b_.CreateOr(isTrue(A()), isTrue(B())));
      case Op::Not: return boolean(b_.CreateFCmpOEQ(A(), constant(0.0)));
      case Op::Select: return b_.CreateSelect(isTrue(A()), B(), value(ins.c));
      case Op::Store: b_.CreateStore(A(), elementPtr(kOut, ins.imm, dbl_)); return nullptr;
      case Op::StoreAdd: {
        llvm::Value* slot = elementPtr(kOut, ins.imm, dbl_);
        b_.CreateStore(b_.CreateFAdd(b_.CreateLoad(dbl_, slot), A()), slot);
        return nullptr;
      }
      case Op::LoopBegin: beginLoop(ins); return nullptr;
      case Op::LoopEnd: endLoop(ins); return nullptr;
      case Op::LoadYLooped: return b_.CreateLoad(dbl_, loopedPtr(callField(kY), ins.imm));
      case Op::LoadYpLooped: return b_.CreateLoad(dbl_, loopedPtr(callField(kYp), ins.imm));
      case Op::LoadPLooped: return b_.CreateLoad(dbl_, loopedPtr(callField(kP), ins.imm));
      case Op::LoadLoopOffset: return b_.CreateSIToFP(L_, dbl_);
      case Op::LoadTable: return b_.CreateUIToFP(tableEntry(ins.imm), dbl_);
      case Op::StoreLooped: b_.CreateStore(A(), loopedPtr(fn_->getArg(kOut), ins.imm)); return nullptr;
      case Op::StoreIndexed: {
        llvm::Value* slot = tableEntry(ins.imm);
        b_.CreateStore(A(), b_.CreateInBoundsGEP(dbl_, fn_->getArg(kOut), slot));
        return nullptr;
      }
    }
    return nullptr;
  }

  const kernel::Program& prog_;
  const ProgramSplit& split_;
  llvm::Module& mod_;
  llvm::IRBuilder<> b_;
  llvm::Type* dbl_;
  llvm::Function* fn_;
  size_t begin_, end_;
  std::vector<llvm::Value*> local_;                       // values of [begin_, end_)
  IndexTables tables_;
  std::unordered_map<uint32_t, llvm::Value*> imported_;  // earlier parts' values used here
  std::array<llvm::Value*, kIndexTable + 1> fields_{};    // ModelCall fields loaded in this part
  llvm::BasicBlock* entry_ = nullptr;
  // The open loop: its body block, the iteration phi, its offset in this iteration, its count.
  llvm::BasicBlock* body_ = nullptr;
  llvm::PHINode* c_ = nullptr;
  llvm::Value* L_ = nullptr;
  uint32_t count_ = 0;
};

void emitCaller(llvm::Function* entry, const std::vector<llvm::Function*>& parts) {
  llvm::IRBuilder<> b(llvm::BasicBlock::Create(entry->getContext(), "entry", entry));
  std::vector<llvm::Value*> args;
  for (auto& a : entry->args()) args.push_back(&a);
  for (llvm::Function* f : parts) b.CreateCall(f, args);
  b.CreateRetVoid();
}

}  // namespace

void lowerParts(const kernel::Program& p, const ProgramSplit& split, uint32_t first, uint32_t last,
                const std::string& name, llvm::Module& m, bool internal, IndexTables tables) {
  for (uint32_t k = first; k < last; ++k) {
    llvm::Function* f = declareProgramFunction(m, partName(name, k), internal);
    if (internal) f->addFnAttr(llvm::Attribute::NoInline);
    PartLowering(p, split, f, split.begin(k), split.end(k, p.code.size()), tables).emit();
  }
}

LoweredModule lowerKernels(const kernel::KernelModule& k, llvm::LLVMContext& ctx, uint32_t maxInstructions,
                           uint32_t programs) {
  LoweredModule out;
  out.module = std::make_unique<llvm::Module>("qdot." + k.description->name, ctx);
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    if (!(programs & (1u << i))) continue;
    ModelProgram id = programAt(i);
    const kernel::Program& prog = k.program(id);
    const std::string name = entryName(prog, id);
    ProgramSplit split = splitProgram(prog, maxInstructions);
    llvm::Function* entry = declareProgramFunction(*out.module, name, false);
    if (split.parts == 1) {
      PartLowering(prog, split, entry, 0, prog.code.size()).emit();
    } else {
      lowerParts(prog, split, 0, split.parts, name, *out.module, true);
      std::vector<llvm::Function*> parts;
      for (uint32_t p = 0; p < split.parts; ++p) parts.push_back(out.module->getFunction(partName(name, p)));
      emitCaller(entry, parts);
    }
    out.entryNames[i] = name;
    out.functions[i] = split.parts;
    out.spillSlots[i] = split.spillSlots;
  }
  return out;
}

}  // namespace qdot::llvmbackend
