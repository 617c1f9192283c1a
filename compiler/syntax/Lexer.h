// The byte-level lexer of .qd files: turns one SourceManager buffer into Tokens on demand,
// skipping whitespace and comments and reporting lexical errors (E0101-E0106) to the
// DiagnosticEngine. It never fails: after an error it goes on with the next plausible token.
#pragma once

#include <cstdint>
#include <string_view>

#include "support/Diagnostic.h"
#include "support/SourceManager.h"
#include "syntax/Token.h"

namespace qdot::syntax {

class Lexer {
 public:
  /// Lexes buffer `file` of `sm`; errors go to `diags`.
  Lexer(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags);

  /// The next token; after the end of the buffer (or once the diagnostic limit is reached) it
  /// returns TokenKind::eof forever.
  Token next();

 private:
  bool atEnd() const { return pos_ >= text_.size(); }
  char peekChar(size_t ahead = 0) const;
  SourceRange rangeFrom(size_t begin) const;
  Token make(TokenKind kind, size_t begin);

  void skipTrivia();
  bool skipComment();
  void skipBadRun();
  Token lexIdentifier();
  Token lexNumber();
  Token lexString();
  bool lexEscape(std::string& out);
  Token lexPunct();

  void error(SourceRange range, DiagCode code, std::string message, std::string help = {});

  uint32_t file_;
  std::string_view text_;
  DiagnosticEngine& diags_;
  size_t pos_ = 0;
  bool pendingError_ = false;  ///< a lexical error since the last token was made
};

/// True for bytes that may start a token or be whitespace; every other byte is reported as an
/// unexpected character (E0102).
bool isTokenStartOrSpace(unsigned char c);

}  // namespace qdot::syntax
