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

// The most columns of a source line echoed under a diagnostic: a longer line (a generated model,
// a binary file read by mistake) is shown as a window around the caret, cut with "…" marks.
constexpr size_t kMaxShownBytes = 120;
constexpr size_t kBytesBeforeCaret = 40;

// Bytes of the valid UTF-8 character starting at s[i] (0 if none).
size_t utf8Length(std::string_view s, size_t i) {
  auto c = static_cast<unsigned char>(s[i]);
  size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 && c < 0xF0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  return n;
}

// Echoes the character at text[i] as one column: tabs as spaces (the caret line counts columns,
// not tab stops), control bytes and bytes that are not UTF-8 as '?', a UTF-8 character as itself.
// Returns the bytes it took.
size_t echoCharacter(std::string& out, std::string_view text, size_t i) {
  auto c = static_cast<unsigned char>(text[i]);
  size_t n = c >= 0x80 ? utf8Length(text, i) : 1;
  if (n > 1) out.append(text.substr(i, n));
  else out += c == '\t' ? ' ' : (c < 0x20 || c >= 0x7F) ? '?' : static_cast<char>(c);
  return n > 1 ? n : 1;
}

// Prints "   | line" and a caret line under [begin, end) of that line (clamped to the line and to
// the part of it that is shown).
void renderSnippet(std::ostream& os, const SourceManager& sm, SourceRange r) {
  LineCol lc = sm.lineCol(r.file, r.begin);
  std::string_view text = sm.lineText(r.file, lc.line);
  std::string num = std::to_string(lc.line);
  std::string pad(num.size(), ' ');
  size_t col = std::min<size_t>(lc.col - 1, text.size());
  size_t stop = std::min<size_t>(col + std::max<uint32_t>(1, r.end > r.begin ? r.end - r.begin : 1), text.size());
  size_t first = 0, last = text.size();  // the shown bytes [first, last)
  if (text.size() > kMaxShownBytes) {
    first = std::min(col > kBytesBeforeCaret ? col - kBytesBeforeCaret : 0, text.size() - kMaxShownBytes);
    last = first + kMaxShownBytes;
  }
  std::string shown = first > 0 ? "…" : "";
  size_t columns = first > 0 ? 1 : 0, caret = columns, caretEnd = 0;
  for (size_t i = first; i < last; ++columns) {
    if (i <= col) caret = columns;
    if (i < stop) caretEnd = columns + 1;
    i += echoCharacter(shown, text, i);
  }
  if (col >= last) caret = columns;
  if (last < text.size()) shown += "…";
  size_t width = caretEnd > caret ? caretEnd - caret : 1;
  os << ' ' << pad << " |\n" << ' ' << num << " | " << shown << '\n';
  os << ' ' << pad << " | " << std::string(caret, ' ') << '^' << std::string(width - 1, '~') << '\n';
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
