// Kernel IR -> LLVM IR. One basic block of straight-line code per function. Semantics follow
// kernel::interpret (qdot/opcodes.def) bit for bit where LLVM allows it:
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

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

namespace qdot::llvmbackend {
namespace {

using kernel::Instr;
using kernel::Op;

/// Number of register operands (a, b, c) an opcode reads.
unsigned operandCount(Op op) {
  switch (op) {
#define QDOT_ARITY_End 0
#define QDOT_ARITY_None 0
#define QDOT_ARITY_Index 0
#define QDOT_ARITY_Unary 1
#define QDOT_ARITY_Binary 2
#define QDOT_ARITY_Ternary 3
#define QDOT_ARITY_UnaryIndex 1
#define QDOT_ARITY_Store 1
#define QDOT_OPCODE(Name, Mnemonic, Format, Value) \
  case Op::Name: return QDOT_ARITY_##Format;
#include "qdot/opcodes.def"
  }
  return 0;
}

/// Loads and constants: cheaper to redo in a later function than to pass through the spill array.
bool rematerialisable(Op op) {
  switch (op) {
    case Op::LoadTime: case Op::LoadCj: case Op::LoadY: case Op::LoadYp: case Op::LoadP:
    case Op::LoadGiven: case Op::LoadOverridden: case Op::LoadConst: return true;
    default: return false;
  }
}

uint32_t operand(const Instr& ins, unsigned i) { return i == 0 ? ins.a : i == 1 ? ins.b : ins.c; }

/// The arguments of every generated function, in ProgramFn order.
enum Arg : unsigned { kTimeCj, kY, kYp, kP, kGiven, kOverridden, kOut, kSpill, kArgCount };

/// Lowers one program, possibly into several functions.
class ProgramLowering {
 public:
  ProgramLowering(const kernel::Program& p, llvm::Module& m, uint32_t maxInstructions)
      : prog_(p), mod_(m), b_(m.getContext()), dbl_(b_.getDoubleTy()), chunk_(std::max<uint32_t>(1, maxInstructions)) {}

  /// Emits the entry function `name`; returns {functions, spill slots}.
  std::pair<uint32_t, uint32_t> lower(const std::string& name) {
    size_t n = prog_.code.size();
    uint32_t parts = n <= chunk_ ? 1 : static_cast<uint32_t>((n + chunk_ - 1) / chunk_);
    assignSpillSlots();
    if (parts == 1) {
      emitPart(declare(name, llvm::GlobalValue::ExternalLinkage), 0, n);
      return {1, spillCount_};
    }
    std::vector<llvm::Function*> fns;
    for (uint32_t k = 0; k < parts; ++k) {
      llvm::Function* f = declare(name + "." + std::to_string(k), llvm::GlobalValue::InternalLinkage);
      f->addFnAttr(llvm::Attribute::NoInline);
      emitPart(f, size_t(k) * chunk_, std::min(n, size_t(k + 1) * chunk_));
      fns.push_back(f);
    }
    emitCaller(declare(name, llvm::GlobalValue::ExternalLinkage), fns);
    return {parts, spillCount_};
  }

 private:
  uint32_t partOf(size_t i) const { return static_cast<uint32_t>(i / chunk_); }

  // A value used in a later part than the one defining it gets a slot (unless it is a load).
  void assignSpillSlots() {
    spillSlot_.assign(prog_.code.size(), UINT32_MAX);
    for (size_t i = 0; i < prog_.code.size(); ++i) {
      const Instr& ins = prog_.code[i];
      for (unsigned j = 0, e = operandCount(ins.op); j < e; ++j) {
        uint32_t v = operand(ins, j);
        if (partOf(v) != partOf(i) && !rematerialisable(prog_.code[v].op) && spillSlot_[v] == UINT32_MAX)
          spillSlot_[v] = spillCount_++;
      }
    }
  }

  llvm::Function* declare(const std::string& name, llvm::GlobalValue::LinkageTypes linkage) {
    auto* ptr = llvm::PointerType::getUnqual(mod_.getContext());
    std::vector<llvm::Type*> params(kArgCount, ptr);
    auto* type = llvm::FunctionType::get(b_.getVoidTy(), params, false);
    auto* f = llvm::Function::Create(type, linkage, name, mod_);
    f->addFnAttr(llvm::Attribute::NoUnwind);
    for (unsigned a = 0; a < kArgCount; ++a) {
      f->addParamAttr(a, llvm::Attribute::NoCapture);
      if (a == kOut || a == kSpill) f->addParamAttr(a, llvm::Attribute::NoAlias);
      else f->addParamAttr(a, llvm::Attribute::ReadOnly);
    }
    return f;
  }

  void emitCaller(llvm::Function* entry, const std::vector<llvm::Function*>& parts) {
    b_.SetInsertPoint(llvm::BasicBlock::Create(mod_.getContext(), "entry", entry));
    std::vector<llvm::Value*> args;
    for (auto& a : entry->args()) args.push_back(&a);
    for (llvm::Function* f : parts) b_.CreateCall(f, args);
    b_.CreateRetVoid();
  }

  // Instructions [begin, end) into f: one basic block.
  void emitPart(llvm::Function* f, size_t begin, size_t end) {
    fn_ = f;
    b_.SetInsertPoint(llvm::BasicBlock::Create(mod_.getContext(), "entry", f));
    ++part_;  // invalidates the values of the previous part
    if (values_.empty()) values_.assign(prog_.code.size(), {nullptr, 0});
    for (size_t i = begin; i < end; ++i) {
      llvm::Value* v = emit(prog_.code[i]);
      values_[i] = {v, part_};
      if (spillSlot_[i] != UINT32_MAX) b_.CreateStore(v, elementPtr(kSpill, spillSlot_[i], dbl_));
    }
    b_.CreateRetVoid();
  }

  llvm::Value* elementPtr(Arg a, uint32_t index, llvm::Type* type) {
    return b_.CreateConstInBoundsGEP1_64(type, fn_->getArg(a), index);
  }
  llvm::Value* loadInput(Arg a, uint32_t index) { return b_.CreateLoad(dbl_, elementPtr(a, index, dbl_)); }

  // Register %v in the current part: its value, a redone load, or a reload from the spill array.
  llvm::Value* value(uint32_t v) {
    if (values_[v].second == part_) return values_[v].first;
    const Instr& def = prog_.code[v];
    llvm::Value* x = rematerialisable(def.op) ? emit(def) : b_.CreateLoad(dbl_, elementPtr(kSpill, spillSlot_[v], dbl_));
    values_[v] = {x, part_};
    return x;
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
      case Op::LoadTime: return loadInput(kTimeCj, 0);
      case Op::LoadCj: return loadInput(kTimeCj, 1);
      case Op::LoadY: return loadInput(kY, ins.imm);
      case Op::LoadYp: return loadInput(kYp, ins.imm);
      case Op::LoadP: return loadInput(kP, ins.imm);
      case Op::LoadGiven: return loadInput(kGiven, ins.imm);
      case Op::LoadOverridden: {
        llvm::Value* flag = b_.CreateLoad(b_.getInt8Ty(), elementPtr(kOverridden, ins.imm, b_.getInt8Ty()));
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
    }
    return nullptr;
  }

  const kernel::Program& prog_;
  llvm::Module& mod_;
  llvm::IRBuilder<> b_;
  llvm::Type* dbl_;
  uint32_t chunk_;
  llvm::Function* fn_ = nullptr;
  std::vector<std::pair<llvm::Value*, uint32_t>> values_;  // value and the part it belongs to
  uint32_t part_ = 0;                                       // 1 + index of the part being emitted
  std::vector<uint32_t> spillSlot_;
  uint32_t spillCount_ = 0;
};

}  // namespace

std::string entryName(const kernel::Program& p, kernel::ProgramId id) {
  return "qdot_" + (p.name.empty() ? std::to_string(static_cast<int>(id)) : p.name);
}

LoweredModule lowerKernels(const kernel::KernelModule& k, llvm::LLVMContext& ctx, uint32_t maxInstructions) {
  LoweredModule out;
  out.module = std::make_unique<llvm::Module>("qdot." + k.name, ctx);
  for (size_t i = 0; i < kernel::kProgramCount; ++i) {
    auto id = static_cast<kernel::ProgramId>(i);
    out.entryNames[i] = entryName(k.program(id), id);
    auto [functions, slots] = ProgramLowering(k.program(id), *out.module, maxInstructions).lower(out.entryNames[i]);
    out.functions[i] = functions;
    out.spillSlots[i] = slots;
  }
  return out;
}

}  // namespace qdot::llvmbackend
