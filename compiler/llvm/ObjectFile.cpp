// emitObjectFile: lowerKernels as for the JIT, the host target machine (as JitSession::compile:
// detectHost, the code generator level of optLevel, level 0 for very large models) with a PIC
// relocation model, then the legacy code generation pipeline writing an object file.
#include "llvm/ObjectFile.h"

#include <mutex>

#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>

#include "llvm/Codegen.h"
#include "llvm/JitModel.h"

namespace qdot::llvmbackend {

Result<ObjectFileInfo> emitObjectFile(const kernel::KernelModule& k, int optLevel, const std::string& path) {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
  });
  JitOptions defaults;
  auto jtmb = llvm::orc::JITTargetMachineBuilder::detectHost();
  if (!jtmb) return Error{"LLVM cannot target this host: " + llvm::toString(jtmb.takeError())};
  size_t instructions = 0;
  for (const kernel::Program& p : k.programs) instructions += p.code.size();
  int level = instructions > defaults.largeModelInstructions ? 0 : optLevel;
  jtmb->setCodeGenOptLevel(level <= 0   ? llvm::CodeGenOpt::None
                           : level == 1 ? llvm::CodeGenOpt::Less
                           : level == 2 ? llvm::CodeGenOpt::Default
                                        : llvm::CodeGenOpt::Aggressive);
  jtmb->setRelocationModel(llvm::Reloc::PIC_);
  auto tm = jtmb->createTargetMachine();
  if (!tm) return Error{"LLVM target machine: " + llvm::toString(tm.takeError())};
  llvm::LLVMContext ctx;
  LoweredModule lowered = lowerKernels(k, ctx, defaults.maxInstructionsPerFunction, defaults.compiledPrograms);
  lowered.module->setDataLayout((*tm)->createDataLayout());
  lowered.module->setTargetTriple((*tm)->getTargetTriple().str());
  std::string verifyErrors;
  llvm::raw_string_ostream vos(verifyErrors);
  if (llvm::verifyModule(*lowered.module, &vos)) return Error{"internal error: invalid LLVM IR: " + vos.str()};
  std::error_code ec;
  llvm::raw_fd_ostream out(path, ec, llvm::sys::fs::OF_None);
  if (ec) return Error{"cannot write " + path + ": " + ec.message()};
  llvm::legacy::PassManager pm;
  if ((*tm)->addPassesToEmitFile(pm, out, nullptr, llvm::CGFT_ObjectFile))
    return Error{"LLVM cannot emit an object file for this target"};
  pm.run(*lowered.module);
  out.flush();
  if (out.has_error()) {
    out.clear_error();
    return Error{"cannot write " + path};
  }
  ObjectFileInfo info;
  info.entryNames = lowered.entryNames;
  info.spillSlots = lowered.spillSlots;
  return info;
}

}  // namespace qdot::llvmbackend
