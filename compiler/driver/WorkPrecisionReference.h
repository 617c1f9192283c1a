// The reference of a work–precision study on the output grid: exact solutions (--exact), a CSV file
// (--reference, interpolated linearly in time onto the grid) or the rows of a run at a much
// tighter tolerance.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "driver/WorkPrecisionExact.h"

namespace qdot::driver {

/// For each compared column: its index among the run's result columns and its reference value at
/// each output time.
struct ReferenceValues {
  std::vector<std::size_t> columns;         ///< indices into the result columns
  std::vector<std::string> names;           ///< their names
  std::vector<std::vector<double>> values;  ///< [column][output time]
  std::string description;                  ///< a sentence for the report
};

/// The exact solutions evaluated on `times`; nullopt after diagnostics (located in "--exact").
std::optional<ReferenceValues> exactReference(const std::vector<std::string>& exact,
                                              const std::vector<std::string>& columns, const NameValues& names,
                                              const std::vector<double>& times, SourceManager& sources,
                                              DiagnosticEngine& diags);

/// The columns of a CSV file (header: time, then names as qdot run writes them) that are result
/// columns, interpolated linearly onto `times`. Throws std::runtime_error with a sentence if the
/// file cannot be read, has no such column, or does not cover the times.
ReferenceValues csvReference(const std::string& path, const std::vector<std::string>& columns,
                             const std::vector<double>& times);

/// Every column of a run's rows (one row per output time).
ReferenceValues runReference(const std::vector<std::vector<double>>& rows, const std::vector<std::string>& columns,
                             std::string description);

}  // namespace qdot::driver
