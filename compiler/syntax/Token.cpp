// Spelling table and keyword lookup, generated from TokenKinds.def.
#include "syntax/Token.h"

#include <algorithm>
#include <array>
#include <utility>

namespace qdot::syntax {
namespace {

constexpr const char* kSpellings[] = {
#define TOKEN(Name, Desc) Desc,
#include "syntax/TokenKinds.def"
};

constexpr bool kIsKeyword[] = {
#define TOKEN(Name, Desc) false,
#define KEYWORD(Name, Spelling) true,
#include "syntax/TokenKinds.def"
};

constexpr std::pair<std::string_view, TokenKind> kKeywords[] = {
#define KEYWORD(Name, Spelling) {Spelling, TokenKind::kw_##Name},
#include "syntax/TokenKinds.def"
};

// Keywords sorted once for binary search.
const auto& sortedKeywords() {
  static const auto table = [] {
    std::array<std::pair<std::string_view, TokenKind>, std::size(kKeywords)> t{};
    std::copy(std::begin(kKeywords), std::end(kKeywords), t.begin());
    std::sort(t.begin(), t.end());
    return t;
  }();
  return table;
}

// Shortens a token's text for a message (long strings) and keeps it on one line.
std::string clip(std::string_view text) {
  constexpr size_t kMax = 24;
  std::string out;
  for (char c : text.substr(0, kMax)) {
    if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += '?';
    } else {
      out += c;
    }
  }
  if (text.size() > kMax) out += "...";
  return out;
}

}  // namespace

const char* spelling(TokenKind kind) { return kSpellings[static_cast<size_t>(kind)]; }

bool isKeyword(TokenKind kind) { return kIsKeyword[static_cast<size_t>(kind)]; }

TokenKind keywordKind(std::string_view text) {
  const auto& table = sortedKeywords();
  auto it = std::lower_bound(table.begin(), table.end(), text,
                             [](const auto& entry, std::string_view t) { return entry.first < t; });
  if (it != table.end() && it->first == text) return it->second;
  return TokenKind::identifier;
}

std::string quote(std::string_view text) {
  std::string s;
  s.reserve(text.size() + 2);
  s += '\'';
  s.append(text);
  s += '\'';
  return s;
}

std::string describe(const Token& tok) {
  switch (tok.kind) {
    case TokenKind::eof: return "end of file";
    case TokenKind::identifier: return "identifier '" + clip(tok.text) + "'";
    case TokenKind::number: return "number '" + clip(tok.text) + "'";
    case TokenKind::string: return "string " + clip(tok.text);
    case TokenKind::error: return quote(clip(tok.text));
    default: return quote(spelling(tok.kind));
  }
}

}  // namespace qdot::syntax
