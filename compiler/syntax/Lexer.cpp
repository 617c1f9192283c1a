// The .qd lexer: comments, identifiers and keywords, numbers, strings with escapes, operators.
// Bad bytes are reported once per run (E0102) and skipped, so lexing always makes progress.
#include "syntax/Lexer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace qdot::syntax {
namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool isIdentChar(char c) { return isIdentStart(c) || isDigit(c); }
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Length of the valid UTF-8 sequence starting at s[i] (0 if invalid).
size_t utf8Length(std::string_view s, size_t i) {
  auto c = static_cast<unsigned char>(s[i]);
  size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  return n;
}

// Shows a run of bad bytes: printable ASCII and valid UTF-8 as they are, other bytes as \xNN.
std::string showBytes(std::string_view run) {
  std::string out;
  for (size_t i = 0; i < run.size() && out.size() < 32;) {
    auto c = static_cast<unsigned char>(run[i]);
    size_t n = c >= 0x80 ? utf8Length(run, i) : 0;
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c), ++i;
    } else if (n > 0) {
      out.append(run.substr(i, n)), i += n;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf, ++i;
    }
  }
  return out.size() < 32 ? out : out + "...";
}

}  // namespace

bool isTokenStartOrSpace(unsigned char c) {
  static constexpr std::string_view kPunct = "+-*/^=<>:;,.()[]{}\"";
  char ch = static_cast<char>(c);
  return isIdentChar(ch) || isSpace(ch) || (c != 0 && kPunct.find(ch) != std::string_view::npos);
}

Lexer::Lexer(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags)
    : file_(file), text_(sm.text(file)), diags_(diags) {
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;  // a UTF-8 byte-order mark is not text
  // No text file has a NUL byte: one error for the file, not one per run of bad bytes in it.
  if (size_t nul = text_.find('\0'); nul != std::string_view::npos) {
    pos_ = nul + 1;
    error({file_, static_cast<uint32_t>(nul), static_cast<uint32_t>(nul + 1)}, DiagCode::E0102,
          "this is not a text file (it has a NUL byte)", "give qdot a model source file (.qd)");
    pos_ = text_.size();
  }
}

char Lexer::peekChar(size_t ahead) const {
  return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
}

SourceRange Lexer::rangeFrom(size_t begin) const {
  return {file_, static_cast<uint32_t>(begin), static_cast<uint32_t>(pos_)};
}

Token Lexer::make(TokenKind kind, size_t begin) {
  Token tok;
  tok.kind = kind;
  tok.range = rangeFrom(begin);
  tok.text = text_.substr(begin, pos_ - begin);
  tok.afterLexError = pendingError_;
  pendingError_ = false;
  return tok;
}

void Lexer::error(SourceRange range, DiagCode code, std::string message, std::string help) {
  diags_.error(range, code, std::move(message), std::move(help));
  pendingError_ = true;
}

Token Lexer::next() {
  skipTrivia();
  if (atEnd() || diags_.limitReached()) {
    pos_ = text_.size();
    return make(TokenKind::eof, pos_);
  }
  char c = peekChar();
  if (isIdentStart(c)) return lexIdentifier();
  if (isDigit(c) || (c == '.' && isDigit(peekChar(1)))) return lexNumber();
  if (c == '"') return lexString();
  return lexPunct();
}

/// trivia := { whitespace | "//" ... newline | "/*" ... "*/" | bad-byte-run }
void Lexer::skipTrivia() {
  while (!atEnd()) {
    char c = peekChar();
    if (isSpace(c)) {
      ++pos_;
    } else if (c == '/' && (peekChar(1) == '/' || peekChar(1) == '*')) {
      if (!skipComment()) return;
    } else if (!isTokenStartOrSpace(static_cast<unsigned char>(c))) {
      skipBadRun();
    } else {
      return;
    }
  }
}

// Skips one comment; returns false if an unterminated block comment ran to the end of the file.
bool Lexer::skipComment() {
  size_t begin = pos_;
  if (peekChar(1) == '/') {
    size_t nl = text_.find('\n', pos_);
    pos_ = nl == std::string_view::npos ? text_.size() : nl;
    return true;
  }
  size_t close = text_.find("*/", pos_ + 2);
  if (close == std::string_view::npos) {
    pos_ = begin + 2;
    error(rangeFrom(begin), DiagCode::E0101, "unterminated block comment",
          "close the comment with '*/' (block comments do not nest)");
    pos_ = text_.size();
    return false;
  }
  pos_ = close + 2;
  return true;
}

// Reports one E0102 for a run of consecutive bytes that cannot start a token.
void Lexer::skipBadRun() {
  size_t begin = pos_;
  while (!atEnd() && !isTokenStartOrSpace(static_cast<unsigned char>(peekChar()))) ++pos_;
  std::string_view run = text_.substr(begin, pos_ - begin);
  bool ascii = true;
  for (char c : run) ascii = ascii && static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7F;
  bool one = run.size() == 1 || (!ascii && utf8Length(run, 0) == run.size());
  std::string what = one ? "unexpected character" : "unexpected characters";
  std::string help = ascii ? std::string(one ? "remove it" : "remove them") +
                                 "; operators are + - * / ^ = == <> < <= > >= and names use letters, digits and '_'"
                           : "non-ASCII and control characters may appear only inside strings and comments";
  error(rangeFrom(begin), DiagCode::E0102, what + " '" + showBytes(run) + "'", help);
}

/// identifier := [A-Za-z_] [A-Za-z0-9_]*   (keywords are looked up in TokenKinds.def)
Token Lexer::lexIdentifier() {
  size_t begin = pos_;
  while (!atEnd() && isIdentChar(peekChar())) ++pos_;
  return make(keywordKind(text_.substr(begin, pos_ - begin)), begin);
}

/// number := digits ["." digits*] [("e"|"E") ["+"|"-"] digits]  |  "." digits [exponent]
Token Lexer::lexNumber() {
  size_t begin = pos_;
  bool integer = true;
  while (isDigit(peekChar())) ++pos_;
  if (peekChar() == '.') {
    integer = false;
    ++pos_;
    while (isDigit(peekChar())) ++pos_;
  }
  bool malformed = false;
  if (peekChar() == 'e' || peekChar() == 'E') {
    integer = false;
    ++pos_;
    if (peekChar() == '+' || peekChar() == '-') ++pos_;
    malformed = !isDigit(peekChar());
    while (isIdentChar(peekChar())) ++pos_;  // digits, or the junk of a malformed exponent
  }
  std::string_view text = text_.substr(begin, pos_ - begin);
  double value = 0;
  auto res = std::from_chars(text.data(), text.data() + text.size(), value);
  if (malformed) {
    error(rangeFrom(begin), DiagCode::E0104, "malformed number '" + std::string(text) + "'",
          "an exponent needs digits, as in 1e-3 or 2.5E+4");
  } else if (res.ptr != text.data() + text.size()) {
    error(rangeFrom(begin), DiagCode::E0104, "malformed number '" + std::string(text) + "'",
          "numbers look like 1, 1.5, 1e-3 or 2.5E+4");
  } else if (res.ec == std::errc::result_out_of_range) {
    value = std::strtod(std::string(text).c_str(), nullptr);
    if (std::isinf(value))
      error(rangeFrom(begin), DiagCode::E0106, "number '" + std::string(text) + "' is too large", "");
  }
  Token tok = make(TokenKind::number, begin);
  tok.number = value;
  tok.isInteger = integer;
  return tok;
}

/// string := '"' { char | escape } '"'   (may span lines)
Token Lexer::lexString() {
  size_t begin = pos_++;
  size_t close = pos_;
  while (close < text_.size() && text_[close] != '"') close += text_[close] == '\\' ? 2 : 1;
  std::string value;
  if (close >= text_.size()) {
    // Unterminated: report at the quote and end the token at the end of its line.
    size_t nl = text_.find('\n', begin);
    size_t stop = nl == std::string_view::npos ? text_.size() : nl;
    pos_ = begin + 1;
    error(rangeFrom(begin), DiagCode::E0103, "unterminated string", "add the closing '\"'");
    value.assign(text_.substr(begin + 1, stop - begin - 1));
    pos_ = stop;
    Token tok = make(TokenKind::string, begin);
    tok.value = std::move(value);
    tok.afterLexError = pendingError_ = true;
    return tok;
  }
  while (pos_ < close) {
    if (peekChar() == '\\') {
      lexEscape(value);
    } else {
      value += text_[pos_++];
    }
  }
  ++pos_;  // closing quote
  Token tok = make(TokenKind::string, begin);
  tok.value = std::move(value);
  return tok;
}

// escape := "\" ( '"' | "'" | "?" | "\" | "a" | "b" | "f" | "n" | "r" | "t" | "v" )
bool Lexer::lexEscape(std::string& out) {
  size_t begin = pos_;
  char c = peekChar(1);
  pos_ += 2;
  switch (c) {
    case '"': case '\'': case '?': case '\\': out += c; return true;
    case 'a': out += '\a'; return true;
    case 'b': out += '\b'; return true;
    case 'f': out += '\f'; return true;
    case 'n': out += '\n'; return true;
    case 'r': out += '\r'; return true;
    case 't': out += '\t'; return true;
    case 'v': out += '\v'; return true;
    default: break;
  }
  if (c == '\n' || static_cast<unsigned char>(c) >= 0x80 || static_cast<unsigned char>(c) < 0x20) --pos_;
  error(rangeFrom(begin), DiagCode::E0105, "unknown escape sequence '" + showBytes(text_.substr(begin, pos_ - begin)) + "'",
        "known escapes are \\\" \\' \\? \\\\ \\a \\b \\f \\n \\r \\t \\v; write \\\\ for a backslash");
  out.append(text_.substr(begin + 1, pos_ - begin - 1));
  return false;
}

/// punct := "==" | "<>" | "<=" | ">=" | one of + - * / ^ = < > : ; , . ( ) [ ] { }
Token Lexer::lexPunct() {
  size_t begin = pos_;
  char c = peekChar(), d = peekChar(1);
  TokenKind kind = TokenKind::error;
  pos_ += 2;
  if (c == '=' && d == '=') return make(TokenKind::equalEqual, begin);
  if (c == '<' && d == '>') return make(TokenKind::notEqual, begin);
  if (c == '<' && d == '=') return make(TokenKind::lessEqual, begin);
  if (c == '>' && d == '=') return make(TokenKind::greaterEqual, begin);
  pos_ = begin + 1;
  switch (c) {
    case '+': kind = TokenKind::plus; break;
    case '-': kind = TokenKind::minus; break;
    case '*': kind = TokenKind::star; break;
    case '/': kind = TokenKind::slash; break;
    case '^': kind = TokenKind::caret; break;
    case '=': kind = TokenKind::equal; break;
    case '<': kind = TokenKind::less; break;
    case '>': kind = TokenKind::greater; break;
    case ':': kind = TokenKind::colon; break;
    case ';': kind = TokenKind::semi; break;
    case ',': kind = TokenKind::comma; break;
    case '.': kind = TokenKind::dot; break;
    case '(': kind = TokenKind::lParen; break;
    case ')': kind = TokenKind::rParen; break;
    case '[': kind = TokenKind::lBracket; break;
    case ']': kind = TokenKind::rBracket; break;
    case '{': kind = TokenKind::lBrace; break;
    case '}': kind = TokenKind::rBrace; break;
    default: break;  // unreachable: skipTrivia removed every other byte
  }
  return make(kind, begin);
}

}  // namespace qdot::syntax
