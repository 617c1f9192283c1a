// The bytecode backend: kernel programs -> qdot bytecode (runtime/include/qdot/bytecode.h) for the
// VM in runtime/vm. Kernel opcodes map one to one; this stage assigns registers (constants pinned
// to the low registers, scratch registers reused after their last use) and encodes the words.
#pragma once

#include <iosfwd>

#include "kernel/Kernel.h"
#include "qdot/bytecode.h"

namespace qdot::bytecode {

/// Every program of the kernel module, its description (copied) and the source table (labels and "file.qd:line" resolved with `sm`). The result passes bc::validate.
bc::Module emitBytecode(const kernel::KernelModule& k, const SourceManager& sm);

/// One program. Instruction sources are the kernel's source indices (= Module::locations indices).
bc::Function emitFunction(const kernel::Program& p);

/// `--emit=bytecode`: the disassembly of m (runtime/vm's disassembler).
void printBytecode(std::ostream& os, const bc::Module& m);

}  // namespace qdot::bytecode
