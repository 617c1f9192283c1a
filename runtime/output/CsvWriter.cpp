// CsvWriter: builds each line in a buffer, writes and flushes it at once. Numbers use
// std::to_chars without a precision, which gives the shortest string that round-trips.
#include "output/CsvWriter.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace qdot::rt {

void appendNumber(std::string& out, double v) {
  char buffer[32];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
  if (ec != std::errc()) throw std::runtime_error("cannot format a number");  // 32 chars always suffice
  out.append(buffer, end);
}

std::string formatNumber(double v) {
  std::string text;
  appendNumber(text, v);
  return text;
}

std::string csvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

CsvWriter::CsvWriter(std::ostream& out, ColumnNaming naming)
    : out_(&out), path_("standard output"), naming_(naming) {}

CsvWriter::CsvWriter(std::unique_ptr<std::ofstream> file, std::string path, ColumnNaming naming)
    : file_(std::move(file)), out_(file_.get()), path_(std::move(path)), naming_(naming) {}

std::unique_ptr<CsvWriter> CsvWriter::openFile(const std::string& path, ColumnNaming naming) {
  auto file = std::make_unique<std::ofstream>(path, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!*file) throw std::runtime_error("cannot open " + path + " for writing: " + std::strerror(errno));
  return std::unique_ptr<CsvWriter>(new CsvWriter(std::move(file), path, naming));
}

void CsvWriter::writeLine() {
  line_ += '\n';
  out_->write(line_.data(), static_cast<std::streamsize>(line_.size()));
  out_->flush();
  line_.clear();
  if (!*out_) throw std::runtime_error("writing results to " + path_ + " failed");
}

void CsvWriter::begin(std::span<const std::string> columnNames) {
  std::vector<std::string> identifiers;
  if (naming_ == ColumnNaming::Identifier) columnNames = identifiers = identifierNames(columnNames);
  line_ = "time";
  for (const std::string& name : columnNames) {
    line_ += ',';
    line_ += csvField(name);
  }
  writeLine();
}

void CsvWriter::row(double time, std::span<const double> values) {
  appendNumber(line_, time);
  for (double v : values) {
    line_ += ',';
    appendNumber(line_, v);
  }
  writeLine();
}

void CsvWriter::finish() {
  out_->flush();
  if (file_) file_->close();
}

}  // namespace qdot::rt
