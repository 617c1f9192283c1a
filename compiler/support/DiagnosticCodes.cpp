#include "support/DiagnosticCodes.h"

#include <cstddef>

namespace qdot {
namespace {

constexpr DiagCodeInfo kCodes[] = {
#define QDOT_DIAG(Code, Stage, Title) {DiagCode::Code, #Code, #Stage, Title},
#include "support/DiagnosticCodes.def"
};

}  // namespace

std::span<const DiagCodeInfo> allDiagCodes() { return kCodes; }

const DiagCodeInfo& diagCodeInfo(DiagCode code) { return kCodes[static_cast<size_t>(code)]; }

}  // namespace qdot
