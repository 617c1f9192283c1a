// Executable: `qdot build` — a standalone executable of a model, taking the run options of
// `qdot run`. The model's bytecode (always; the VM runs it, or re-runs a failing call to name the
// equation) and, with the LLVM backend, an object file of its programs are linked with the
// prebuilt runtime main (runtime/exe) by the system C++ compiler. The runtime libraries are found
// next to qdot: in an installed tree (<prefix>/bin/qdot, <prefix>/lib/qdot/) or in the build tree
// qdot was built in.
#pragma once

#include <ostream>
#include <string>

#include "driver/Pipeline.h"
#include "qdot/exit_code.hpp"

namespace qdot::driver {

struct ExecutableOptions {
  std::string outputPath;       ///< the executable to write
  bool native = true;           ///< LLVM object code (else the VM, linked in)
};

/// Checks that `path` can be written as a file: not a directory, its folder exists and is
/// writable. Returns the reason it cannot ("" if it can).
std::string checkOutputPath(const std::string& path);

/// Builds the executable of a compilation that reached Stage::Kernel. Errors go to `log` as
/// sentences; returns ExitCode::Success, Usage (a bad output path) or Internal.
ExitCode buildExecutable(Compilation& c, const ExecutableOptions& options, std::ostream& log);

/// Where the runtime libraries for executables are ("" if neither layout is found), for messages.
std::string runtimeLibraryDirectory();

}  // namespace qdot::driver
