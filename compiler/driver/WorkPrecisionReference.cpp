// References on the output grid. The CSV reader takes what qdot run writes (quoted names such as
// "der(x)" only when they contain a comma or quote) and any other CSV with a header row.
#include "driver/WorkPrecisionReference.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "sim/RunOptions.h"

namespace qdot::driver {
namespace {

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) fields.emplace_back();
    else if (c != '\r') fields.back() += c;
  }
  return fields;
}

/// The value of a column at t by linear interpolation between the bracketing rows.
double interpolate(const std::vector<double>& times, const std::vector<double>& values, double t) {
  auto upper = std::lower_bound(times.begin(), times.end(), t);
  std::size_t j = static_cast<std::size_t>(upper - times.begin());
  if (j < times.size() && times[j] == t) return values[j];
  double w = (t - times[j - 1]) / (times[j] - times[j - 1]);
  return values[j - 1] + w * (values[j] - values[j - 1]);
}

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> columns;  // [column][row]
};

CsvTable readCsv(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(fmt::format("--reference: cannot read {}", path));
  CsvTable table;
  std::string line;
  if (!std::getline(file, line)) throw std::runtime_error(fmt::format("--reference: {} is empty", path));
  table.header = splitCsvLine(line);
  table.columns.resize(table.header.size());
  for (std::size_t row = 2; std::getline(file, line); ++row) {
    if (line.empty()) continue;
    std::vector<std::string> fields = splitCsvLine(line);
    if (fields.size() != table.header.size())
      throw std::runtime_error(fmt::format("--reference: {}:{}: {} fields, the header has {}", path, row, fields.size(),
                                           table.header.size()));
    for (std::size_t c = 0; c < fields.size(); ++c) {
      std::optional<double> v = rt::parseNumber(fields[c]);
      if (!v) throw std::runtime_error(fmt::format("--reference: {}:{}: '{}' is not a number", path, row, fields[c]));
      table.columns[c].push_back(*v);
    }
  }
  return table;
}

void checkTimes(const std::string& path, const std::vector<double>& refTimes, const std::vector<double>& times) {
  if (refTimes.size() < 2 || !std::is_sorted(refTimes.begin(), refTimes.end()))
    throw std::runtime_error(fmt::format("--reference: the times in {} must be at least two and increasing", path));
  if (times.front() < refTimes.front() || times.back() > refTimes.back())
    throw std::runtime_error(fmt::format("--reference: {} covers [{:g}, {:g}], the runs [{:g}, {:g}]", path,
                                         refTimes.front(), refTimes.back(), times.front(), times.back()));
}

}  // namespace

std::optional<ReferenceValues> exactReference(const std::vector<std::string>& exact,
                                              const std::vector<std::string>& columns, const NameValues& names,
                                              const std::vector<double>& times, SourceManager& sources,
                                              DiagnosticEngine& diags) {
  ReferenceValues ref;
  ref.description = "the exact solution";
  for (const std::string& text : exact) {
    std::optional<ExactSolution> solution = parseExact(text, columns, names, sources, diags);
    if (!solution) continue;
    auto at = std::find(columns.begin(), columns.end(), solution->column);
    ref.columns.push_back(static_cast<std::size_t>(at - columns.begin()));
    ref.names.push_back(solution->column);
    std::vector<double>& values = ref.values.emplace_back();
    for (double t : times) values.push_back(evaluateExact(*solution, t, names));
    ref.description += (ref.names.size() == 1 ? " " : "; ") + text;
  }
  if (diags.hasErrors()) return std::nullopt;
  ref.description += " (--exact)";
  return ref;
}

ReferenceValues csvReference(const std::string& path, const std::vector<std::string>& columns,
                             const std::vector<double>& times) {
  CsvTable table = readCsv(path);
  if (table.header.empty() || table.header.front() != "time")
    throw std::runtime_error(fmt::format("--reference: the first column of {} must be 'time'", path));
  checkTimes(path, table.columns.front(), times);
  ReferenceValues ref;
  for (std::size_t c = 1; c < table.header.size(); ++c) {
    auto at = std::find(columns.begin(), columns.end(), table.header[c]);
    if (at == columns.end()) continue;
    ref.columns.push_back(static_cast<std::size_t>(at - columns.begin()));
    ref.names.push_back(table.header[c]);
    std::vector<double>& values = ref.values.emplace_back();
    for (double t : times) values.push_back(interpolate(table.columns.front(), table.columns[c], t));
  }
  if (ref.columns.empty())
    throw std::runtime_error(fmt::format("--reference: no column of {} is a result column of the model", path));
  ref.description = fmt::format("{} (--reference; interpolated linearly in time where its times differ from the "
                                "output grid)",
                                path);
  return ref;
}

ReferenceValues runReference(const std::vector<std::vector<double>>& rows, const std::vector<std::string>& columns,
                             std::string description) {
  ReferenceValues ref;
  ref.description = std::move(description);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    ref.columns.push_back(c);
    ref.names.push_back(columns[c]);
    std::vector<double>& values = ref.values.emplace_back();
    for (const std::vector<double>& row : rows) values.push_back(row[c]);
  }
  return ref;
}

}  // namespace qdot::driver
