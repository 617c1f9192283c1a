// DiagCode: the registered diagnostic codes of support/DiagnosticCodes.def, and what the registry
// says about each (its spelling, the stage that reports it, a short title).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace qdot {

enum class DiagCode : uint16_t {
#define QDOT_DIAG(Code, Stage, Title) Code,
#include "support/DiagnosticCodes.def"
};

struct DiagCodeInfo {
  DiagCode code;
  std::string_view name;   ///< "E0201"
  std::string_view stage;  ///< "sema"
  std::string_view title;  ///< "unknown name"
};

/// Every registered code, in the order of DiagnosticCodes.def.
std::span<const DiagCodeInfo> allDiagCodes();
const DiagCodeInfo& diagCodeInfo(DiagCode code);
inline std::string_view diagCodeName(DiagCode code) { return diagCodeInfo(code).name; }

}  // namespace qdot
