#include "support/Diagnostic.h"

#include <algorithm>

namespace qdot {
namespace {

const char* severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}

// Prints "   | line" and a caret line under [begin, end) of that line (clamped to the line).
void renderSnippet(std::ostream& os, const SourceManager& sm, SourceRange r) {
  LineCol lc = sm.lineCol(r.file, r.begin);
  std::string_view text = sm.lineText(r.file, lc.line);
  std::string num = std::to_string(lc.line);
  std::string pad(num.size(), ' ');
  std::string shown;
  for (char c : text) shown += (c == '\t') ? ' ' : (static_cast<unsigned char>(c) < 32 ? '?' : c);
  os << ' ' << pad << " |\n" << ' ' << num << " | " << shown << '\n';
  size_t col = lc.col - 1;
  size_t len = std::max<size_t>(1, r.end > r.begin ? r.end - r.begin : 1);
  if (col > text.size()) col = text.size();
  len = std::min(len, std::max<size_t>(1, text.size() - std::min(col, text.size())));
  os << ' ' << pad << " | " << std::string(col, ' ') << '^' << std::string(len - 1, '~') << '\n';
}

}  // namespace

void DiagnosticEngine::report(Diagnostic d) {
  if (d.severity == Severity::Error) {
    if (errors_ >= errorLimit_) return;
    ++errors_;
  }
  diags_.push_back(std::move(d));
}

Diagnostic& DiagnosticEngine::error(SourceRange range, DiagCode code, std::string message,
                                    std::string help) {
  if (errors_ >= errorLimit_) return overflow_ = Diagnostic{};
  report({Severity::Error, code, range, std::move(message), std::move(help), {}});
  return diags_.back();
}

Diagnostic& DiagnosticEngine::warning(SourceRange range, DiagCode code, std::string message,
                                      std::string help) {
  report({Severity::Warning, code, range, std::move(message), std::move(help), {}});
  return diags_.back();
}

void DiagnosticEngine::renderOne(std::ostream& os, const SourceManager& sm, const Diagnostic& d,
                                 bool color) {
  const char* bold = color ? "\033[1m" : "";
  const char* red = color ? "\033[1;31m" : "";
  const char* reset = color ? "\033[0m" : "";
  if (d.range.valid()) {
    LineCol lc = sm.lineCol(d.range.file, d.range.begin);
    os << bold << sm.name(d.range.file) << ':' << lc.line << ':' << lc.col << ": " << reset;
  }
  os << red << severityName(d.severity);
  os << '[' << diagCodeName(d.code) << ']';
  os << reset << bold << ": " << d.message << reset << '\n';
  if (d.range.valid()) renderSnippet(os, sm, d.range);
  for (const auto& n : d.notes) {
    if (n.range.valid()) {
      LineCol lc = sm.lineCol(n.range.file, n.range.begin);
      os << sm.name(n.range.file) << ':' << lc.line << ':' << lc.col << ": note: " << n.message << '\n';
      renderSnippet(os, sm, n.range);
    } else {
      os << "note: " << n.message << '\n';
    }
  }
  if (!d.help.empty()) os << "help: " << d.help << '\n';
}

void DiagnosticEngine::render(std::ostream& os, const SourceManager& sm, bool color) const {
  for (const auto& d : diags_) renderOne(os, sm, d, color);
  if (errors_ >= errorLimit_) os << "note: stopped after " << errorLimit_ << " errors\n";
}

}  // namespace qdot
