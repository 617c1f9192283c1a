// printIR: lowerKernels into a fresh context, then LLVM's own textual IR printer.
#include "llvm/PrintIR.h"

#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>
#include <llvm/Support/raw_os_ostream.h>

#include "llvm/Codegen.h"

namespace qdot::llvmbackend {

void printIR(std::ostream& os, const kernel::KernelModule& k, uint32_t maxInstructionsPerFunction) {
  llvm::LLVMContext ctx;
  LoweredModule lowered = lowerKernels(k, ctx, maxInstructionsPerFunction);
  llvm::raw_os_ostream out(os);
  lowered.module->print(out, nullptr);
}

}  // namespace qdot::llvmbackend
