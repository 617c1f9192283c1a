// The recursive-descent parser behind syntax::parse (private to compiler/syntax). Each parse
// function carries its grammar production in a `///` comment. Token access, error reporting and
// recovery live in Parser.cpp, classes and declarations too; sections in ParseSections.cpp;
// expressions in ParseExpr.cpp.
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ast/AST.h"
#include "support/Diagnostic.h"
#include "syntax/Lexer.h"
#include "syntax/Parser.h"

namespace qdot::syntax {

class Parser {
 public:
  Parser(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags);
  std::unique_ptr<ast::StoredDefinition> parseStoredDefinition();

 private:
  using ExprPtr = ast::ExprPtr;

  /// Declaration prefixes shared by all declarators of one component clause.
  struct Prefixes {
    ast::Variability variability = ast::Variability::Continuous;
    ast::Causality causality = ast::Causality::None;
    bool isCoordinate = false;
    bool isFlow = false;
    uint32_t begin = UINT32_MAX;  ///< offset of the first prefix (UINT32_MAX if none)
  };

  /// Counts one level of nesting for the lifetime of a parse function.
  class DepthGuard {
   public:
    explicit DepthGuard(Parser& p) : p_(p) { ok_ = ++p_.depth_ <= kMaxNestingDepth; }
    ~DepthGuard() { --p_.depth_; }
    DepthGuard(const DepthGuard&) = delete;
    DepthGuard& operator=(const DepthGuard&) = delete;
    bool ok() const { return ok_; }

   private:
    Parser& p_;
    bool ok_;
  };

  /// Counts each link of a left-associative chain (a + b + c, x[1][2], a.b[1].c) as one level,
  /// since it deepens the tree just as parentheses do.
  class ChainGuard {
   public:
    explicit ChainGuard(Parser& p) : p_(p) {}
    ~ChainGuard() { p_.depth_ -= links_; }
    ChainGuard(const ChainGuard&) = delete;
    ChainGuard& operator=(const ChainGuard&) = delete;
    /// Adds one link; false (and E0110 reported) when the chain is too deep.
    bool next() {
      ++links_;
      if (++p_.depth_ <= kMaxNestingDepth) return true;
      p_.tooDeep("expression");
      return false;
    }

   private:
    Parser& p_;
    int links_ = 0;
  };

  // --- tokens (Parser.cpp) -------------------------------------------------------------------
  /// The kind and place of a consumed token: what the recursive expression functions keep
  /// (a whole Token would bloat their stack frames).
  struct OpTok {
    TokenKind kind;
    SourceRange range;
  };

  const Token& tok() { return peek(0); }
  const Token& peek(size_t n);
  /// Consumes the current token (not EOF) and returns it; the reference stays valid until the
  /// next take().
  const Token& take();
  OpTok takeOp() {
    const Token& t = take();
    return {t.kind, t.range};
  }
  bool at(TokenKind k) { return tok().kind == k; }
  bool accept(TokenKind k);
  bool atClassKeyword();
  bool atPrefixKeyword();
  bool atSectionStart();
  bool atElementStart();
  bool atDeclarationStart();
  bool atStatementListEnd(bool nested);
  bool atUnsupportedWord();
  bool skipUnsupported();
  bool parseVisibility();
  bool atSyncPoint();
  /// From `begin` to the end of the last consumed token (never an inverted range).
  SourceRange rangeFrom(uint32_t begin) const { return {file_, begin, std::max(begin, prev_.range.end)}; }
  SourceRange afterPrev() const { return {file_, prev_.range.end, prev_.range.end}; }
  uint32_t lineOf(uint32_t offset) const { return sm_.lineCol(file_, offset).line; }

  // --- diagnostics and recovery (Parser.cpp) -------------------------------------------------
  Diagnostic* report(SourceRange r, DiagCode code, std::string msg, std::string help = {});
  Diagnostic* fail(SourceRange r, DiagCode code, std::string msg, std::string help = {});
  void failExpected(const std::string& what, DiagCode code, std::string help = {});
  bool expect(TokenKind k, const std::string& context);
  bool expectSemi(const std::string& context);
  bool expectClose(TokenKind close, OpTok open, bool inList = false);
  bool expectEnd(TokenKind kw, SourceRange open);
  void synchronize();
  void skipToSyncPoint();
  bool resyncTo(TokenKind k);
  void recover(uint64_t start);
  bool skipStrayEnd();
  void tooDeep(const char* what);

  // --- classes and declarations (Parser.cpp) -------------------------------------------------
  void parseWithin(ast::StoredDefinition& def);
  std::unique_ptr<ast::ClassDef> parseClass();
  void parseShortClass(ast::ClassDef& cls);
  void parseComposition(ast::ClassDef& cls);
  void parseClassEnd(ast::ClassDef& cls);
  void parseElement(ast::ClassDef& cls);
  void parseExtends(ast::ClassDef& cls);
  void parseImport(std::vector<ast::ImportClause>& into);
  void parseComponentClause(ast::ClassDef& cls);
  Prefixes parsePrefixes();
  bool parseTypeSpecifier(std::vector<std::string>& parts, SourceRange& range);
  bool parseDeclarator(ast::Declaration& decl);
  std::vector<ast::Modification> parseClassModification();
  std::optional<ast::Modification> parseArgument();
  ast::Annotation parseAnnotation();
  std::string parseDescription();
  bool parseDottedName(std::vector<std::string>& parts, std::vector<SourceRange>* ranges);

  // --- sections (ParseSections.cpp) ----------------------------------------------------------
  void parseSection(ast::ClassDef& cls);
  void parseEquationList(std::vector<ast::Equation>& out, bool nested);
  std::optional<ast::Equation> parseEquation();
  std::optional<ast::Equation> parseSimpleEquation();
  ast::Equation parseForEquation();
  ast::Equation parseConditionalEquation();
  ast::Equation parseConnect();
  void parseAnnotationStatement();
  void parseMechanicsList(std::vector<ast::MechanicsStmt>& out);
  std::optional<ast::MechanicsStmt> parseMechanicsStmt();
  ast::MechanicsStmt parseEnergyStmt(ast::MechanicsKind kind);
  ast::MechanicsStmt parseForceStmt();
  void parseForceQualifier(ast::MechanicsStmt& s, bool torque);
  ast::MechanicsStmt parseConstraintStmt();
  ast::MechanicsStmt parseMechanicsFor();
  std::vector<ast::Iterator> parseForIndices();

  // --- expressions (ParseExpr.cpp) -----------------------------------------------------------
  ExprPtr parseExpression();
  ExprPtr parseIfExpression();
  ExprPtr parseRange();
  ExprPtr parseOr();
  ExprPtr parseAnd();
  ExprPtr parseNot();
  ExprPtr parseRelation();
  ExprPtr parseArithmetic();
  ExprPtr parsePowerOperand();
  ExprPtr parseUnaryTerm();
  ExprPtr parseTerm();
  ExprPtr parseSignedFactor();
  ExprPtr parseFactor();
  ExprPtr parsePostfix();
  ExprPtr parsePrimary(bool& plainName);
  ExprPtr parseNamePrimary();
  ExprPtr parseKeywordCall();
  ExprPtr parseParenthesized();
  ExprPtr parseArrayConstructor();
  ExprPtr parseSubscripts(ExprPtr base, uint32_t begin);
  std::vector<ExprPtr> parseArraySubscripts();
  ExprPtr parseCall(std::unique_ptr<ast::NameExpr> callee, uint32_t begin);
  bool parseCallArgument(ast::CallExpr& call, bool& sawNamed);
  ExprPtr parseComprehension(ExprPtr body, uint32_t begin);
  ExprPtr makeBinary(ast::BinaryOp op, SourceRange opRange, ExprPtr lhs, ExprPtr rhs, uint32_t begin);
  void reportChainedPower(const ast::BinaryExpr& first, const ast::Expr* third, SourceRange at);
  void failNotCallable(const ast::Expr& e);
  void failNotComponent(const ast::Expr& e);
  ExprPtr failKeywordCall(std::string_view keyword);
  ExprPtr unexpectedInExpression();
  bool canStartExpression();

  const SourceManager& sm_;
  uint32_t file_;
  DiagnosticEngine& diags_;
  Lexer lexer_;
  std::deque<Token> lookahead_;
  Token prev_;                       ///< the last consumed token
  uint64_t consumed_ = 0;            ///< tokens consumed so far (progress checks)
  bool panic_ = false;               ///< an error was reported; stay quiet until resynchronised
  bool reportedTooDeep_ = false;     ///< E0110 is reported once per file
  bool reportedAtEof_ = false;       ///< one "found end of file" error is enough
  int depth_ = 0;                    ///< current nesting (DepthGuard)
  int subscriptDepth_ = 0;           ///< inside `[...]`, where `end` is an expression
  int branchDepth_ = 0;              ///< inside if/when equation bodies
  std::vector<TokenKind> blockStack_;  ///< open for/if/when blocks, innermost last
  std::vector<TokenKind> brokenBlocks_;  ///< blocks abandoned after an error: their `end X;` comes later
  bool quietStrayEnds_ = false;          ///< after E0110, skipped blocks leave many `end X;` behind
  bool protected_ = false;                ///< after `protected` in a function: declarations are locals
  ast::ClassDef* currentClass_ = nullptr;     ///< receives annotations and misplaced elements
  std::vector<const ast::ClassDef*> openClasses_;  ///< enclosing classes, outermost first
};

}  // namespace qdot::syntax
