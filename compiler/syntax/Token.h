// Tokens of the .qd language: the TokenKind enum generated from TokenKinds.def, the Token the
// lexer hands to the parser, and helpers to spell a kind or describe a token in a message.
#pragma once

#include <string>
#include <string_view>

#include "support/SourceManager.h"

namespace qdot::syntax {

/// Every kind of token; keywords are `kw_<spelling>`.
enum class TokenKind : unsigned char {
#define TOKEN(Name, Desc) Name,
#include "syntax/TokenKinds.def"
};

/// The source spelling of a keyword or operator ("model", "<="), or a description of a special
/// token ("identifier", "end of file").
const char* spelling(TokenKind kind);
/// True for the reserved words of TokenKinds.def.
bool isKeyword(TokenKind kind);
/// The keyword kind spelled `text`, or TokenKind::identifier if `text` is no keyword.
TokenKind keywordKind(std::string_view text);

/// One token. `text` views the source buffer; `value` holds the unescaped contents of a string.
struct Token {
  TokenKind kind = TokenKind::eof;
  SourceRange range;
  std::string_view text;
  std::string value;
  double number = 0;       ///< value of a number token
  bool isInteger = false;  ///< number written without '.' and exponent
  /// A lexical error was reported while producing this token or just before it; the parser
  /// keeps quiet about an error at this token, since it is most likely a consequence.
  bool afterLexError = false;

  bool is(TokenKind k) const { return kind == k; }
  bool isNot(TokenKind k) const { return kind != k; }
  /// True if this is an identifier spelled `word` (for contextual keywords such as `kinetic`).
  bool isWord(std::string_view word) const { return kind == TokenKind::identifier && text == word; }
};

/// `text` in single quotes, as messages name source text: quote("x") is "'x'".
std::string quote(std::string_view text);

/// How a token is named in a message: "';'", "'model'", "identifier 'x'", "number '1.5'",
/// "end of file".
std::string describe(const Token& tok);

}  // namespace qdot::syntax
