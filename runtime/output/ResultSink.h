// Where simulation results go, one row at a time. The simulation loop writes through this
// interface only, so formats other than CSV (binary, in-memory for tests, a plotting pipe) can be
// added without touching it.
#pragma once

#include <span>
#include <string>

namespace qdot::rt {

/// A destination for result rows: time first, then one value per column.
class ResultSink {
 public:
  virtual ~ResultSink() = default;
  /// Called once, before any row, with the names of the columns after time.
  virtual void begin(std::span<const std::string> columnNames) = 0;
  /// One row. When it returns, the row must be safe from a later failure of the run (flushed).
  virtual void row(double time, std::span<const double> values) = 0;
  /// Called once after the last row, whether the run succeeded or failed.
  virtual void finish() = 0;
};

}  // namespace qdot::rt
