// Emit: `--emit=STAGE` on every command prints one stage's output in a stable, readable text form
// and stops (tests/golden holds the expected output of each).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "driver/Pipeline.h"

namespace qdot::driver {

/// What --emit can print, in pipeline order.
enum class EmitStage { Ast, Flat, Eom, Dae, Kernel, Bytecode, Llvm };

/// The stage spelled `name` ("ast", "kernel", ...), or nullopt.
std::optional<EmitStage> parseEmitStage(std::string_view name);
/// Every spelling, in pipeline order (for the option's check).
std::vector<std::string> emitStageNames();
/// "ast, flat, ..." (for help texts).
std::string emitStageList();
/// The pipeline stage a compilation must reach before `stage` can be printed.
Stage stageNeeded(EmitStage stage);
/// Prints the output of `stage` of a compilation that reached stageNeeded(stage). False if the
/// printer itself failed (c.internalError says why).
bool emit(Compilation& c, EmitStage stage, std::ostream& os);

}  // namespace qdot::driver
