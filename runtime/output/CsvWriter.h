// CSV result writer: a header `time,<names>` and one line per output time, numbers in their
// shortest round-trip form (std::to_chars), every row flushed as it is written so that the rows
// computed before a failure are on disk.
#pragma once

#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

#include "output/ColumnNames.h"
#include "output/ResultSink.h"

namespace qdot::rt {

/// Appends the shortest text that reads back as exactly v ("0.1", "1e-07", "nan", "-inf").
void appendNumber(std::string& out, double v);
/// The same as a string.
std::string formatNumber(double v);
/// A CSV field: as is, or in double quotes (inner quotes doubled) if it holds , " or a line break.
std::string csvField(std::string_view text);

/// Writes CSV to a stream it does not own, or to a file it opens.
class CsvWriter final : public ResultSink {
 public:
  /// Writes to out (e.g. std::cout); out must outlive the writer.
  explicit CsvWriter(std::ostream& out, ColumnNaming naming = ColumnNaming::Modelica);
  /// Opens (truncates) path; throws std::runtime_error with the reason if it cannot.
  static std::unique_ptr<CsvWriter> openFile(const std::string& path, ColumnNaming naming = ColumnNaming::Modelica);

  void begin(std::span<const std::string> columnNames) override;
  /// Throws std::runtime_error if the stream fails (disk full, closed pipe).
  void row(double time, std::span<const double> values) override;
  void finish() override;

 private:
  CsvWriter(std::unique_ptr<std::ofstream> file, std::string path, ColumnNaming naming);
  void writeLine();

  std::unique_ptr<std::ofstream> file_;
  std::ostream* out_;
  std::string path_;
  std::string line_;
  ColumnNaming naming_;
};

}  // namespace qdot::rt
