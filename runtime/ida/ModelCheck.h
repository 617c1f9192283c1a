// Checks a QdotModel table before the runtime trusts it: ABI version, the functions the runtime
// needs, and a well-formed CSC Jacobian pattern (KLU would read out of bounds on a bad one).
// Also the small accessors that read the table's C arrays safely.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot::rt {

/// Empty if the model can be simulated, else what is wrong with it (one sentence).
std::optional<std::string> checkModel(const QdotModel& model);

/// The model's lastError text, or "" when it has none.
std::string modelLastError(const QdotModel& model);

/// Names from one of the table's name arrays (a null array or entry gives "").
std::vector<std::string_view> nameList(const char* const* names, uint32_t count);

}  // namespace qdot::rt
