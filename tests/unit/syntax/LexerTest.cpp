// Lexer tests: token kinds, spellings and ranges; comments, numbers, strings and escapes; lexical
// errors with their locations (E0101-E0106).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/Diagnostic.h"
#include "syntax/Lexer.h"

namespace qdot::syntax {
namespace {

struct Lexed {
  SourceManager sm;
  DiagnosticEngine diags;
  std::vector<Token> tokens;  // without the final eof
};

std::unique_ptr<Lexed> lex(const std::string& text) {
  auto l = std::make_unique<Lexed>();
  uint32_t f = l->sm.addBuffer("lex.qd", text);
  Lexer lexer(l->sm, f, l->diags);
  for (Token t = lexer.next(); !t.is(TokenKind::eof); t = lexer.next()) l->tokens.push_back(t);
  return l;
}

std::vector<TokenKind> kinds(const Lexed& l) {
  std::vector<TokenKind> k;
  for (const auto& t : l.tokens) k.push_back(t.kind);
  return k;
}

std::string where(const Lexed& l, SourceRange r) {
  LineCol lc = l.sm.lineCol(r.file, r.begin);
  return std::to_string(lc.line) + ":" + std::to_string(lc.col);
}

using K = TokenKind;

TEST(Lexer, KeywordsIdentifiersAndPunctuation) {
  auto l = lex("model M parameter Real k_1 = 2; end M;");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::kw_model, K::identifier, K::kw_parameter, K::kw_Real, K::identifier,
                                       K::equal, K::number, K::semi, K::kw_end, K::identifier, K::semi}));
  EXPECT_EQ(l->tokens[4].text, "k_1");
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, EverySpecKeywordIsAKeyword) {
  const char* words[] = {"model", "end", "parameter", "constant", "coordinate", "input", "output", "Real",
                         "Integer", "Boolean", "mechanics", "equation", "initial", "for", "in", "loop", "if",
                         "then", "elseif", "else", "and", "or", "not", "true", "false", "der", "time",
                         "annotation", "connector", "flow", "connect", "package", "import", "extends", "within",
                         "when", "reinit", "pre", "constraint"};
  for (const char* w : words) {
    TokenKind k = keywordKind(w);
    EXPECT_TRUE(isKeyword(k)) << w;
    EXPECT_STREQ(spelling(k), w);
  }
  EXPECT_EQ(keywordKind("kinetic"), K::identifier);  // contextual in the mechanics section
  EXPECT_EQ(keywordKind("force"), K::identifier);
  EXPECT_EQ(keywordKind("Model"), K::identifier);  // case-sensitive
}

TEST(Lexer, Operators) {
  auto l = lex("+ - * / ^ = == <> < <= > >= : ; , . ( ) [ ] { }");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::plus, K::minus, K::star, K::slash, K::caret, K::equal, K::equalEqual,
                                       K::notEqual, K::less, K::lessEqual, K::greater, K::greaterEqual, K::colon,
                                       K::semi, K::comma, K::dot, K::lParen, K::rParen, K::lBracket, K::rBracket,
                                       K::lBrace, K::rBrace}));
  auto m = lex("a<=b<>c>=d==e");
  EXPECT_EQ(kinds(*m), (std::vector<K>{K::identifier, K::lessEqual, K::identifier, K::notEqual, K::identifier,
                                       K::greaterEqual, K::identifier, K::equalEqual, K::identifier}));
}

TEST(Lexer, RangesAreByteOffsets) {
  auto l = lex("model M\n  Real xy;\nend M;");
  ASSERT_EQ(l->tokens.size(), 8u);
  const Token& xy = l->tokens[3];
  EXPECT_EQ(xy.range.begin, 15u);
  EXPECT_EQ(xy.range.end, 17u);
  EXPECT_EQ(where(*l, xy.range), "2:8");
  EXPECT_EQ(where(*l, l->tokens[5].range), "3:1");
}

TEST(Lexer, Numbers) {
  auto l = lex("1 1.5 1e-3 2.5E+4 .5 3. 007 1E2");
  ASSERT_EQ(l->tokens.size(), 8u);
  double expected[] = {1, 1.5, 1e-3, 2.5e4, 0.5, 3.0, 7, 100};
  bool integer[] = {true, false, false, false, false, false, true, false};
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(l->tokens[i].kind, K::number) << i;
    EXPECT_DOUBLE_EQ(l->tokens[i].number, expected[i]) << i;
    EXPECT_EQ(l->tokens[i].isInteger, integer[i]) << i;
  }
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, NumberFollowedByMemberDotIsNotSwallowed) {
  auto l = lex("ms[2].a");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::identifier, K::lBracket, K::number, K::rBracket, K::dot, K::identifier}));
}

TEST(Lexer, MalformedExponentIsOneLocatedError) {
  auto l = lex("x = 1e;\ny = 2.5E+;\nz = 3ex;");
  ASSERT_EQ(l->diags.errorCount(), 3u);
  const auto& d = l->diags.diagnostics();
  EXPECT_EQ(diagCodeName(d[0].code), "E0104");
  EXPECT_EQ(d[0].message, "malformed number '1e'");
  EXPECT_EQ(where(*l, d[0].range), "1:5");
  EXPECT_EQ(d[0].range.end - d[0].range.begin, 2u);
  EXPECT_EQ(d[1].message, "malformed number '2.5E+'");
  EXPECT_EQ(d[2].message, "malformed number '3ex'");
  // The bad number is still one number token, so parsing goes on normally.
  EXPECT_EQ(kinds(*l)[2], K::number);
  EXPECT_EQ(kinds(*l)[3], K::semi);
}

TEST(Lexer, HugeNumberIsAnError) {
  auto l = lex("1e999 1e-999");
  ASSERT_EQ(l->diags.errorCount(), 1u);
  EXPECT_EQ(diagCodeName(l->diags.diagnostics()[0].code), "E0106");
  EXPECT_EQ(l->tokens[1].number, 0.0);
}

TEST(Lexer, CommentsAreSkipped) {
  auto l = lex("a // line comment ( [\n/* block\n comment */ b /**/ c//end");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::identifier, K::identifier, K::identifier}));
  EXPECT_EQ(where(*l, l->tokens[1].range), "3:13");
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, UnterminatedBlockCommentIsReportedAtItsStart) {
  auto l = lex("a\n  /* never closed\n b c");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::identifier}));
  ASSERT_EQ(l->diags.errorCount(), 1u);
  const Diagnostic& d = l->diags.diagnostics()[0];
  EXPECT_EQ(diagCodeName(d.code), "E0101");
  EXPECT_EQ(where(*l, d.range), "2:3");
  EXPECT_EQ(d.message, "unterminated block comment");
}

TEST(Lexer, StringsWithEscapes) {
  auto l = lex(R"("plain" "a\"b\\c\nd\te" "multi
line" "")");
  ASSERT_EQ(l->tokens.size(), 4u);
  EXPECT_EQ(l->tokens[0].value, "plain");
  EXPECT_EQ(l->tokens[1].value, "a\"b\\c\nd\te");
  EXPECT_EQ(l->tokens[2].value, "multi\nline");
  EXPECT_EQ(l->tokens[3].value, "");
  EXPECT_EQ(l->tokens[0].text, "\"plain\"");
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, NonAsciiInsideStringsAndCommentsIsFine) {
  auto l = lex("\"Dichte ρ [kg/m³]\" // größe\n/* ½ */ x");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::string, K::identifier}));
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, UnknownEscape) {
  auto l = lex(R"("a\qb")");
  ASSERT_EQ(l->diags.errorCount(), 1u);
  EXPECT_EQ(diagCodeName(l->diags.diagnostics()[0].code), "E0105");
  EXPECT_EQ(l->diags.diagnostics()[0].message, "unknown escape sequence '\\q'");
  EXPECT_EQ(where(*l, l->diags.diagnostics()[0].range), "1:3");
  EXPECT_EQ(l->tokens[0].value, "aqb");
}

TEST(Lexer, UnterminatedStringEndsAtItsLine) {
  auto l = lex("x = \"open;\ny = 2;");
  ASSERT_EQ(l->diags.errorCount(), 1u);
  EXPECT_EQ(diagCodeName(l->diags.diagnostics()[0].code), "E0103");
  EXPECT_EQ(where(*l, l->diags.diagnostics()[0].range), "1:5");
  EXPECT_EQ(l->tokens[2].value, "open;");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::identifier, K::equal, K::string, K::identifier, K::equal, K::number,
                                       K::semi}));
  EXPECT_TRUE(l->tokens[3].afterLexError);  // the parser stays quiet about the missing ';'
}

TEST(Lexer, OneErrorPerRunOfBadBytes) {
  auto l = lex("a @#$ b \xC3\xA9\xC3\xA9 c \x01\x02 d ` e");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::identifier, K::identifier, K::identifier, K::identifier, K::identifier}));
  ASSERT_EQ(l->diags.errorCount(), 4u);
  const auto& d = l->diags.diagnostics();
  EXPECT_EQ(diagCodeName(d[0].code), "E0102");
  EXPECT_EQ(d[0].message, "unexpected characters '@#$'");
  EXPECT_EQ(where(*l, d[0].range), "1:3");
  EXPECT_EQ(d[1].message, "unexpected characters '\xC3\xA9\xC3\xA9'");
  EXPECT_EQ(d[2].message, "unexpected characters '\\x01\\x02'");
  EXPECT_EQ(d[3].message, "unexpected character '`'");
  EXPECT_TRUE(l->tokens[1].afterLexError);
}

TEST(Lexer, InvalidUtf8IsShownAsHex) {
  auto l = lex("x \xFF\xFE y");
  ASSERT_EQ(l->diags.errorCount(), 1u);
  EXPECT_EQ(l->diags.diagnostics()[0].message, "unexpected characters '\\xFF\\xFE'");
}

// No text has a NUL byte: the file is one error (at the byte), not a token stream with holes.
TEST(Lexer, NulByteMeansNotATextFile) {
  auto l = lex(std::string("a\0b @ c", 7));
  EXPECT_EQ(kinds(*l), std::vector<K>{});
  ASSERT_EQ(l->diags.errorCount(), 1u);
  EXPECT_EQ(l->diags.diagnostics()[0].message, "this is not a text file (it has a NUL byte)");
  EXPECT_EQ(l->diags.diagnostics()[0].range.begin, 1u);
}

TEST(Lexer, StopsAtTheErrorLimit) {
  std::string garbage;
  for (int i = 0; i < 1000; ++i) garbage += "@ ";
  auto l = lex(garbage);
  EXPECT_TRUE(l->diags.limitReached());
  EXPECT_EQ(l->diags.diagnostics().size(), 50u);
}

TEST(Lexer, ByteOrderMarkIsSkipped) {
  auto l = lex("\xEF\xBB\xBFmodel M");
  EXPECT_EQ(kinds(*l), (std::vector<K>{K::kw_model, K::identifier}));
  EXPECT_FALSE(l->diags.hasErrors());
  auto m = lex("x \xEF\xBB\xBF");  // elsewhere it is an error
  EXPECT_EQ(m->diags.errorCount(), 1u);
}

TEST(Lexer, CrLfAndTabs) {
  auto l = lex("model M\r\n\tReal x;\r\nend M;\r\n");
  ASSERT_EQ(l->tokens.size(), 8u);
  EXPECT_EQ(where(*l, l->tokens[3].range), "2:7");
  EXPECT_EQ(where(*l, l->tokens[5].range), "3:1");
  EXPECT_FALSE(l->diags.hasErrors());
}

TEST(Lexer, DescribeTokens) {
  auto l = lex("x 1.5 ; model \"s\"");
  EXPECT_EQ(describe(l->tokens[0]), "identifier 'x'");
  EXPECT_EQ(describe(l->tokens[1]), "number '1.5'");
  EXPECT_EQ(describe(l->tokens[2]), "';'");
  EXPECT_EQ(describe(l->tokens[3]), "'model'");
  EXPECT_EQ(describe(l->tokens[4]), "string \"s\"");
  Token eof;
  EXPECT_EQ(describe(eof), "end of file");
  auto m = lex("\"two\nlines\" \"a very long description string indeed\"");
  EXPECT_EQ(describe(m->tokens[0]), "string \"two\\nlines\"");
  EXPECT_EQ(describe(m->tokens[1]), "string \"a very long description...");
}

}  // namespace
}  // namespace qdot::syntax
