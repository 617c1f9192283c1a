// LLJIT session: native target initialisation (once), the optimisation pipeline (new pass
// manager, per-module default pipeline at the requested level) run on the module before it is
// handed to ORC, code generation at the matching CodeGenOpt level, and symbol lookup. libm
// functions the code calls (tan, atan2, ...) resolve against the running process.
#include "llvm/Jit.h"

#include <chrono>
#include <mutex>

#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Target/TargetMachine.h>

#include "llvm/Codegen.h"

namespace qdot::llvmbackend {

struct JitSession::Impl {
  std::unique_ptr<llvm::orc::LLJIT> jit;
};

JitSession::JitSession() : impl_(std::make_unique<Impl>()) {}
JitSession::~JitSession() = default;

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void initialiseNativeTarget() {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
  });
}

llvm::CodeGenOpt::Level codegenLevel(int optLevel) {
  switch (optLevel) {
    case 0: return llvm::CodeGenOpt::None;
    case 1: return llvm::CodeGenOpt::Less;
    case 2: return llvm::CodeGenOpt::Default;
    default: return llvm::CodeGenOpt::Aggressive;
  }
}

llvm::OptimizationLevel passLevel(int optLevel) {
  switch (optLevel) {
    case 1: return llvm::OptimizationLevel::O1;
    case 2: return llvm::OptimizationLevel::O2;
    default: return llvm::OptimizationLevel::O3;
  }
}

// The per-module default pipeline (nothing at O0: the code is already minimal SSA).
void optimise(llvm::Module& m, llvm::TargetMachine* tm, int optLevel) {
  if (optLevel <= 0) return;
  llvm::LoopAnalysisManager lam;
  llvm::FunctionAnalysisManager fam;
  llvm::CGSCCAnalysisManager cgam;
  llvm::ModuleAnalysisManager mam;
  llvm::PassBuilder pb(tm);
  pb.registerModuleAnalyses(mam);
  pb.registerCGSCCAnalyses(cgam);
  pb.registerFunctionAnalyses(fam);
  pb.registerLoopAnalyses(lam);
  pb.crossRegisterProxies(lam, fam, cgam, mam);
  pb.buildPerModuleDefaultPipeline(passLevel(optLevel)).run(m, mam);
}

template <typename T>
bool take(llvm::Expected<T>& value, std::string& error, const char* what) {
  if (value) return true;
  error = std::string(what) + ": " + llvm::toString(value.takeError());
  return false;
}

}  // namespace

std::unique_ptr<JitSession> JitSession::compile(const kernel::KernelModule& k, const JitOptions& options,
                                                std::string& error, JitStats* stats) {
  initialiseNativeTarget();
  JitStats local;
  JitStats& st = stats ? *stats : local;
  auto jtmb = llvm::orc::JITTargetMachineBuilder::detectHost();
  if (!take(jtmb, error, "LLVM cannot target this host")) return nullptr;
  size_t instructions = 0;
  for (const kernel::Program& p : k.programs) instructions += p.code.size();
  int codegen = instructions > options.largeModelInstructions ? 0 : options.optLevel;
  jtmb->setCodeGenOptLevel(codegenLevel(codegen));
  auto tm = jtmb->createTargetMachine();
  if (!take(tm, error, "LLVM target machine")) return nullptr;

  auto start = Clock::now();
  auto ctx = std::make_unique<llvm::LLVMContext>();
  LoweredModule lowered = lowerKernels(k, *ctx, options.maxInstructionsPerFunction);
  lowered.module->setDataLayout((*tm)->createDataLayout());
  lowered.module->setTargetTriple((*tm)->getTargetTriple().str());
  std::string verifyErrors;
  llvm::raw_string_ostream os(verifyErrors);
  if (llvm::verifyModule(*lowered.module, &os)) {
    error = "internal error: invalid LLVM IR: " + os.str();
    return nullptr;
  }
  st.lowerSeconds = secondsSince(start);
  st.functions = lowered.functions;
  st.spillSlots = lowered.spillSlots;

  start = Clock::now();
  optimise(*lowered.module, tm->get(), options.pipelineLevel >= 0 ? options.pipelineLevel : options.optLevel);
  st.optimiseSeconds = secondsSince(start);

  start = Clock::now();
  auto jit = llvm::orc::LLJITBuilder().setJITTargetMachineBuilder(std::move(*jtmb)).create();
  if (!take(jit, error, "cannot create the LLVM JIT")) return nullptr;
  auto& dylib = (*jit)->getMainJITDylib();
  auto process = llvm::orc::DynamicLibrarySearchGenerator::GetForCurrentProcess((*jit)->getDataLayout().getGlobalPrefix());
  if (!take(process, error, "cannot resolve libm symbols")) return nullptr;
  dylib.addGenerator(std::move(*process));
  if (auto err = (*jit)->addIRModule(llvm::orc::ThreadSafeModule(std::move(lowered.module), std::move(ctx)))) {
    error = "LLVM JIT: " + llvm::toString(std::move(err));
    return nullptr;
  }
  std::unique_ptr<JitSession> session(new JitSession());
  for (size_t i = 0; i < kernel::kProgramCount; ++i) {
    auto address = (*jit)->lookup(lowered.entryNames[i]);
    if (!take(address, error, "LLVM JIT lookup")) return nullptr;
    session->entries_[i] = address->toPtr<ProgramFn>();
    session->spill_[i] = lowered.spillSlots[i];
  }
  st.codegenSeconds = secondsSince(start);
  session->impl_->jit = std::move(*jit);
  return session;
}

}  // namespace qdot::llvmbackend
