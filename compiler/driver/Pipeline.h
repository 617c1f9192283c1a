// Pipeline: runs the compiler stages in order on one model, from source text to a runnable model,
// and keeps every stage's result, so the command line, the tests and the benchmarks all drive the
// compiler the same way:
//
//   text ─ Parse ─ Check ─ Flatten ─ Derive ─ Dae ─ Kernel ─┬─ Bytecode   (the VM's module)
//                                                           └─ Native     (the LLVM JIT's model)
//
// A later call may continue a compilation to a later stage (continueTo); each stage runs once.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "ast/AST.h"
#include "dae/Dae.h"
#include "dae/ExplicitAlgebraics.h"
#include "dae/Prune.h"
#include "dae/Reroll.h"
#include "flatten/Flatten.h"
#include "kernel/Kernel.h"
#include "llvm/JitModel.h"
#include "mechanics/EulerLagrange.h"
#include "qdot/bytecode.h"
#include "qdot/result.hpp"
#include "driver/LibraryPath.h"
#include "sema/Sema.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"
#include "symbolic/Simplify.h"

namespace qdot::driver {

/// The stages, in order. Bytecode and Native are alternative backends of the kernels: asking for
/// Native does not build the bytecode.
enum class Stage { Parse, Check, Flatten, Derive, Dae, Kernel, Bytecode, Native };

/// Wall time of each stage in seconds (0 for a stage that did not run).
struct StageTimes {
  double parse = 0, check = 0, flatten = 0, derive = 0, dae = 0, kernel = 0, bytecode = 0, native = 0;
  /// Everything from the text to the kernels (what both backends share).
  double frontEnd() const { return parse + check + flatten + derive + dae + kernel; }
};

/// How to compile; set before the first compile call.
struct CompileOptions {
  std::string model;            ///< the model to compile; empty: the file's last model
  flat::FlattenLimits limits;   ///< size limits of flattening (tests and fuzzing lower them)
  flat::StructuralValues structural;  ///< values of Integer parameters (see takeStructuralParameters)
  llvmbackend::JitOptions jit;  ///< what Stage::Native compiles, and how
  sym::SimplifyLevel simplify = sym::SimplifyLevel::Fast;  ///< `--simplify`: of the derived equations
  /// Results asked for (`--outputs`): the DAE stage keeps only what they need (dae/Prune.h); empty:
  /// everything. keepInvariants keeps every invariant (and what it needs) as well (`--invariants`).
  std::vector<std::string> results;
  bool keepInvariants = false;
  /// Keep repeated structure as templates and loops where the model allows it (docs/loops.md):
  /// `qdot run`. Elsewhere (equations, modes, …) every sum is expanded.
  bool keepLoops = false;
  /// Make runs of rows that repeat along arrays loops again when the model was expanded to scalars
  /// (dae::rerollRows, with keepLoops): `qdot run` and `build`.
  bool rerollRows = false;
  size_t rerollMinimumRun = 16;  ///< the shortest run of rows made a loop (tests and fuzzing lower it)
  /// Solve the algebraic unknowns some row defines explicitly out of the DAE (they become outputs,
  /// still result columns: dae/ExplicitAlgebraics.h): what `qdot run`, `build` and `wp` integrate.
  /// `qdot equations`, modes and linearize show and use the system as derived.
  bool eliminateAlgebraics = false;
  /// Free each stage's input once the next stage has what it needs (`qdot run`: after the kernels
  /// only the kernels, the bytecode and the experiment are used): the flat model and the
  /// equations of motion once the DAE is built, the DAE and every symbolic node once the kernels
  /// are. The compiler's peak memory is then that of one stage and its output, not of all stages.
  bool releaseStages = false;
};

/// Everything one compilation creates; later stages point into earlier ones, so it is not
/// copyable. The kernels are shared: a background JIT (driver/Backends.h) keeps them alive for as
/// long as it compiles, whatever happens to the Compilation.
struct Compilation {
  CompileOptions options;
  SourceManager sources;
  DiagnosticEngine diags;
  sym::Context ctx;
  std::unique_ptr<ast::StoredDefinition> ast;
  std::unique_ptr<LibraryLoader> libraries;  ///< the packages the model imports (their trees)
  std::optional<sema::CheckedModel> checked;
  std::optional<flat::FlatModel> flat;
  std::optional<mech::EquationsOfMotion> eom;
  std::optional<dae::Dae> dae;
  dae::PruneReport pruned;  ///< what --outputs kept
  dae::EliminationReport eliminated;  ///< explicit algebraic unknowns solved out (eliminateAlgebraics)
  /// Whether the model's repeated structure (sums, loops) is compiled as loops (docs/loops.md):
  /// nullopt if it has none, "" if it is, else why it is expanded to scalars (`qdot run --stats`).
  std::optional<std::string> loops;
  /// Arrays of components whose energies were summed over their connections (flat::sumConnectedEnergies):
  /// their connectors' flows are not computed (`qdot run --stats` says so).
  bool componentsSummed = false;
  /// Runs of repeating rows of a model expanded to scalars made loops again (dae::rerollRows).
  dae::RerollResult rerolled;
  flat::Experiment experiment;  ///< the DAE's experiment annotation (kept when the DAE is released)
  std::shared_ptr<const kernel::KernelModule> kernels;
  std::optional<bc::Module> bytecode;
  ModelPtr native;                ///< the JIT-compiled model (Stage::Native)
  llvmbackend::JitStats jitStats;  ///< how it was compiled
  StageTimes times;
  Stage reached = Stage::Parse;  ///< the last stage that ran without errors (valid once `ok`)
  bool ok = false;               ///< every stage run so far succeeded
  std::string internalError;     ///< why a backend failed on valid kernels (a bug, not a model error)
  /// Destroys what releaseStages lets go of on another thread (last: joined before the rest goes).
  std::jthread releasing;

  Compilation() = default;
  Compilation(const Compilation&) = delete;
  Compilation& operator=(const Compilation&) = delete;
};

/// The file name that means standard input.
inline constexpr std::string_view kStandardInput = "-";

/// Reads `path` ("-": standard input) and runs the stages up to `until` on the model
/// c.options.model. Returns false if any stage reported an error (see c.diags).
bool compileFile(Compilation& c, const std::string& path, Stage until);
/// The same for text in memory (tests, fuzzing); `name` is used in diagnostics.
bool compileSource(Compilation& c, std::string name, std::string text, Stage until);
/// Continues a successful compilation up to `until` (no-op for stages already run).
bool continueTo(Compilation& c, Stage until);

/// Integer parameters are structural: they size arrays, so their values are applied before
/// flattening. Moves the `NAME=VALUE` assignments (qdot run -p) that name a scalar Integer parameter
/// of the checked model (Stage::Check reached) into c.options.structural; the others stay for the
/// run. Returns "" or what is wrong with a structural assignment (a usage error).
std::string takeStructuralParameters(Compilation& c, std::vector<std::string>& assignments);
/// The model's Integer parameters, for help texts: "n" (or "" if there are none).
std::string structuralParameterList(const Compilation& c);

/// Shorthands with the model name (the last model of the file when empty).
bool compileFile(Compilation& c, const std::string& path, std::string_view model, Stage until);
bool compileSource(Compilation& c, std::string name, std::string text, std::string_view model, Stage until);

}  // namespace qdot::driver
