// The parser's token handling, error reporting and recovery, and the grammar of files, classes
// and declarations. Recovery: the first error of a statement sets panic mode (later errors are
// dropped as consequences), then the statement loop skips to a synchronisation point.
#include "syntax/ParserImpl.h"

#include <algorithm>
#include <iterator>
#include <utility>

namespace qdot::syntax {
namespace {

std::string quoted(TokenKind k) { return std::string("'") + spelling(k) + "'"; }

std::string join(const std::vector<std::string>& parts) {
  std::string s;
  for (size_t i = 0; i < parts.size(); ++i) s += (i ? "." : "") + parts[i];
  return s;
}

ast::ClassKind classKindOf(TokenKind k) {
  switch (k) {
    case TokenKind::kw_connector: return ast::ClassKind::Connector;
    case TokenKind::kw_package: return ast::ClassKind::Package;
    case TokenKind::kw_record: return ast::ClassKind::Record;
    case TokenKind::kw_block: return ast::ClassKind::Block;
    case TokenKind::kw_function: return ast::ClassKind::Function;
    case TokenKind::kw_type: return ast::ClassKind::Type;
    default: return ast::ClassKind::Model;
  }
}

bool isClassKeyword(TokenKind k) {
  switch (k) {
    case TokenKind::kw_model: case TokenKind::kw_connector: case TokenKind::kw_package:
    case TokenKind::kw_record: case TokenKind::kw_block: case TokenKind::kw_function:
    case TokenKind::kw_type: return true;
    default: return false;
  }
}

bool isMechanicsWord(const Token& t) {
  return t.isWord("kinetic") || t.isWord("potential") || t.isWord("dissipation") || t.isWord("force") ||
         t.isWord("torque") || t.isWord("gravity");
}

}  // namespace

std::unique_ptr<ast::StoredDefinition> parse(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags) {
  Parser parser(sm, file, diags);
  return parser.parseStoredDefinition();
}

Parser::Parser(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags)
    : sm_(sm), file_(file), diags_(diags), lexer_(sm, file, diags) {
  prev_.range = {file, 0, 0};
}

// ---------------------------------------------------------------------------------------------
// Tokens
// ---------------------------------------------------------------------------------------------

const Token& Parser::peek(size_t n) {
  while (lookahead_.size() <= n) lookahead_.push_back(lexer_.next());
  return lookahead_[n];
}

const Token& Parser::take() {
  peek(0);
  if (lookahead_.front().is(TokenKind::eof)) return lookahead_.front();
  prev_ = std::move(lookahead_.front());
  lookahead_.pop_front();
  ++consumed_;
  return prev_;
}

bool Parser::accept(TokenKind k) {
  if (!at(k)) return false;
  take();
  return true;
}

bool Parser::atClassKeyword() { return isClassKeyword(tok().kind); }

bool Parser::atPrefixKeyword() {
  switch (tok().kind) {
    case TokenKind::kw_parameter: case TokenKind::kw_constant: case TokenKind::kw_input:
    case TokenKind::kw_output: case TokenKind::kw_flow: case TokenKind::kw_coordinate: return true;
    default: return false;
  }
}

bool Parser::atSectionStart() {
  return at(TokenKind::kw_equation) || at(TokenKind::kw_mechanics) ||
         (at(TokenKind::kw_initial) && peek(1).is(TokenKind::kw_equation));
}

/// True where a declaration, nested class, extends or import starts.
bool Parser::atElementStart() {
  if (atClassKeyword() || atPrefixKeyword()) return true;
  switch (tok().kind) {
    case TokenKind::kw_Real: case TokenKind::kw_Integer: case TokenKind::kw_Boolean:
    case TokenKind::kw_extends: case TokenKind::kw_import: return true;
    default: return atDeclarationStart();
  }
}

/// declaration_start := IDENT {"." IDENT} ["[" ... "]"] IDENT   (bounded lookahead)
bool Parser::atDeclarationStart() {
  constexpr size_t kMaxScan = 64;
  if (!at(TokenKind::identifier)) return false;
  size_t i = 1;
  while (i < kMaxScan && peek(i).is(TokenKind::dot) && peek(i + 1).is(TokenKind::identifier)) i += 2;
  if (peek(i).is(TokenKind::lBracket)) {
    int depth = 0;
    for (; i < kMaxScan && !peek(i).is(TokenKind::eof); ++i) {
      if (peek(i).is(TokenKind::lBracket)) ++depth;
      if (peek(i).is(TokenKind::rBracket) && --depth == 0) break;
    }
    ++i;
  }
  return i < kMaxScan && peek(i).is(TokenKind::identifier);
}

bool Parser::atStatementListEnd(bool nested) {
  switch (tok().kind) {
    case TokenKind::eof: case TokenKind::kw_end: return true;
    case TokenKind::kw_else: case TokenKind::kw_elseif: case TokenKind::kw_elsewhen: return nested;
    default: return atSectionStart() || atElementStart() || atUnsupportedWord();
  }
}

/// Modelica words this language does not have: `algorithm`, `initial algorithm`, `protected`,
/// `public` (sections) and `partial` (before a class keyword). They are identifiers, so only their
/// position tells.
bool Parser::atUnsupportedWord() {
  const Token& t = tok();
  if (t.is(TokenKind::kw_initial)) return peek(1).isWord("algorithm");
  if (t.isNot(TokenKind::identifier)) return false;
  TokenKind next = peek(1).kind;
  if (t.isWord("partial")) return isClassKeyword(next);
  if (!t.isWord("algorithm") && !t.isWord("protected") && !t.isWord("public")) return false;
  return next != TokenKind::equal && next != TokenKind::dot && next != TokenKind::lBracket && next != TokenKind::lParen;
}

/// visibility := "protected" | "public"   (only in a function: its protected declarations are its
/// local variables, each bound to an expression; elsewhere E0119)
bool Parser::parseVisibility() {
  bool inFunction = currentClass_ && currentClass_->kind == ast::ClassKind::Function;
  if (!inFunction || !atUnsupportedWord() || !(tok().isWord("protected") || tok().isWord("public"))) return false;
  protected_ = take().isWord("protected");
  return true;
}

/// Reports an unsupported Modelica word (E0119) and skips it; an `algorithm` section is skipped
/// whole, up to the next section or the end of the class.
bool Parser::skipUnsupported() {
  if (!atUnsupportedWord()) return false;
  if (at(TokenKind::kw_initial)) take();
  std::string word(tok().text);
  const char* help = word == "partial" ? "remove 'partial'"
                     : word == "algorithm" ? "write the relations as equations in an 'equation' section"
                                           : "remove it; all declarations are public and come before the first section";
  report(tok().range, DiagCode::E0119, quote(word) + (word == "partial" ? " classes are" : " sections are") + " not supported",
         help);
  take();
  if (word != "algorithm") return true;
  auto atClassEnd = [&] {
    TokenKind k = peek(1).kind;
    return at(TokenKind::kw_end) && (k == TokenKind::identifier || k == TokenKind::semi || k == TokenKind::eof);
  };
  while (!at(TokenKind::eof) && !atClassEnd() && !atSectionStart() && !atUnsupportedWord()) take();
  return true;
}

/// sync_point := ";" | "end" (IDENT | "for" | "if" | "when" | ";") | section keyword
///             | element keyword | "annotation" | "when" | "connect" | "constraint" | EOF
bool Parser::atSyncPoint() {
  switch (tok().kind) {
    case TokenKind::eof: case TokenKind::semi: case TokenKind::kw_equation: case TokenKind::kw_mechanics:
    case TokenKind::kw_Real: case TokenKind::kw_Integer: case TokenKind::kw_Boolean:
    case TokenKind::kw_extends: case TokenKind::kw_import: case TokenKind::kw_annotation:
    case TokenKind::kw_when: case TokenKind::kw_connect: case TokenKind::kw_constraint:
    case TokenKind::kw_within: return true;
    case TokenKind::kw_initial: return peek(1).is(TokenKind::kw_equation);
    case TokenKind::kw_else: case TokenKind::kw_elseif: case TokenKind::kw_elsewhen: return branchDepth_ > 0;
    case TokenKind::kw_end: {
      TokenKind k = peek(1).kind;
      return k == TokenKind::identifier || k == TokenKind::kw_for || k == TokenKind::kw_if ||
             k == TokenKind::kw_when || k == TokenKind::semi || k == TokenKind::eof;
    }
    default: return atClassKeyword() || atPrefixKeyword();
  }
}

// ---------------------------------------------------------------------------------------------
// Diagnostics and recovery
// ---------------------------------------------------------------------------------------------

Diagnostic* Parser::report(SourceRange r, DiagCode code, std::string msg, std::string help) {
  if (panic_ || diags_.limitReached()) return nullptr;
  // An error right after a lexical error is most likely its consequence.
  if (tok().afterLexError && r.begin >= prev_.range.end) return nullptr;
  // Unclosed blocks all end at the end of the file; report only the innermost.
  if (at(TokenKind::eof) && std::exchange(reportedAtEof_, true)) return nullptr;
  return &diags_.error(r, code, std::move(msg), std::move(help));
}

Diagnostic* Parser::fail(SourceRange r, DiagCode code, std::string msg, std::string help) {
  Diagnostic* d = report(r, code, std::move(msg), std::move(help));
  panic_ = true;
  return d;
}

void Parser::failExpected(const std::string& what, DiagCode code, std::string help) {
  fail(tok().range, code, "expected " + what + ", found " + describe(tok()), std::move(help));
}

bool Parser::expect(TokenKind k, const std::string& context) {
  if (accept(k)) return true;
  failExpected(quoted(k) + (context.empty() ? "" : " " + context), DiagCode::E0117);
  return false;
}

/// A missing ';' is reported just after the previous token. If the next token starts a new line
/// or a new statement, parsing simply goes on there.
bool Parser::expectSemi(const std::string& context) {
  if (accept(TokenKind::semi)) return true;
  std::string msg = "expected ';' " + context + ", found " + describe(tok());
  bool newLine = at(TokenKind::eof) || lineOf(tok().range.begin) > lineOf(prev_.range.end);
  if (newLine || atSyncPoint())
    report(afterPrev(), DiagCode::E0112, msg, "add ';' here");
  else
    fail(afterPrev(), DiagCode::E0112, msg, "add ';' here");
  return false;
}

bool Parser::expectClose(TokenKind close, OpTok open, bool inList) {
  if (accept(close)) return true;
  std::string what = inList ? "',' or " + quoted(close) : quoted(close);
  Diagnostic* d = fail(tok().range, DiagCode::E0113, "expected " + what + ", found " + describe(tok()),
                       "add " + quoted(close) + " to close the " + quoted(open.kind));
  if (d) d->notes.push_back({open.range, "this " + quoted(open.kind) + " is not closed"});
  return false;
}

/// Expects `end for` / `end if` / `end when` closing the block opened by `open`.
bool Parser::expectEnd(TokenKind kw, SourceRange open) {
  if (at(TokenKind::kw_end) && peek(1).is(kw)) {
    take();
    take();
    return true;
  }
  brokenBlocks_.push_back(kw);
  std::string closer = std::string("'end ") + spelling(kw) + "'";
  Diagnostic* d = fail(tok().range, DiagCode::E0117, "expected " + closer + ", found " + describe(tok()),
                       std::string("close the block with 'end ") + spelling(kw) + ";'");
  if (d) d->notes.push_back({open, "the " + quoted(kw) + " block starts here"});
  return false;
}

void Parser::skipToSyncPoint() {
  while (!atSyncPoint()) take();
}

/// Leaves panic mode: skips to a synchronisation point and consumes a ';' found there.
void Parser::synchronize() {
  skipToSyncPoint();
  accept(TokenKind::semi);
  panic_ = false;
}

/// Skips to `k` (unless a synchronisation point comes first); consumes it and leaves panic mode.
bool Parser::resyncTo(TokenKind k) {
  while (!at(k) && !at(TokenKind::semi) && !atSyncPoint()) take();
  if (!accept(k)) return false;
  panic_ = false;
  return true;
}

/// Called after each statement of a loop that began at token count `start`: guarantees progress
/// and resynchronises after an error.
void Parser::recover(uint64_t start) {
  if (consumed_ == start && !at(TokenKind::eof)) {
    bool semi = at(TokenKind::semi);
    take();
    if (semi) {
      panic_ = false;
      return;
    }
  }
  if (panic_) synchronize();
}

/// `end for;` / `end if;` / `end when;` closing no open block: the end of a block abandoned after
/// an error (quietly skipped), or a stray (E0123).
bool Parser::skipStrayEnd() {
  if (!at(TokenKind::kw_end)) return false;
  TokenKind k = peek(1).kind;
  if (k != TokenKind::kw_for && k != TokenKind::kw_if && k != TokenKind::kw_when) return false;
  if (!blockStack_.empty() && blockStack_.back() == k) return false;
  auto broken = std::find(brokenBlocks_.rbegin(), brokenBlocks_.rend(), k);
  if (broken != brokenBlocks_.rend())
    brokenBlocks_.erase(std::next(broken).base());
  else if (!quietStrayEnds_)
    report(tok().range, DiagCode::E0123, std::string("'end ") + spelling(k) + "' without a matching " + quoted(k),
           "remove it, or open the block before it");
  take();
  take();
  accept(TokenKind::semi);
  return true;
}

void Parser::tooDeep(const char* what) {
  quietStrayEnds_ = true;
  if (!std::exchange(reportedTooDeep_, true))
    fail(tok().range, DiagCode::E0110, std::string(what) + " nested too deeply",
         "at most " + std::to_string(kMaxNestingDepth) +
             " levels of nesting are allowed (a long chain such as a + b + c counts one level per operator); "
             "split it up with intermediate variables");
  panic_ = true;
  skipToSyncPoint();
}

// ---------------------------------------------------------------------------------------------
// Files and classes
// ---------------------------------------------------------------------------------------------

/// stored_definition := ["within" [name] ";"] {import_clause | class_definition}
/// (an import at the top of a file applies to every class of the file)
std::unique_ptr<ast::StoredDefinition> Parser::parseStoredDefinition() {
  auto def = std::make_unique<ast::StoredDefinition>();
  def->file = file_;
  bool reported = false;
  while (!at(TokenKind::eof)) {
    uint64_t start = consumed_;
    if (at(TokenKind::kw_within)) {
      parseWithin(*def);
    } else if (at(TokenKind::kw_import)) {
      panic_ = false;
      parseImport(def->imports);
    } else if (atClassKeyword()) {
      panic_ = false;
      def->classes.push_back(parseClass());
    } else if (skipUnsupported()) {
      continue;
    } else {
      if (!panic_) failExpected("'model', 'connector' or 'package'", DiagCode::E0120, "a .qd file contains classes: model M ... end M;");
      reported = true;
      while (!at(TokenKind::eof) && !atClassKeyword() && !at(TokenKind::kw_within) && !at(TokenKind::kw_import)) take();
    }
    if (consumed_ == start) take();
  }
  if (def->classes.empty() && !reported)
    report(tok().range, DiagCode::E0120, "expected 'model', 'connector' or 'package', found end of file",
           "a .qd file contains at least one class: model M ... end M;");
  return def;
}

/// within_clause := "within" [name] ";"
void Parser::parseWithin(ast::StoredDefinition& def) {
  Token kw = take();
  bool misplaced = !def.classes.empty() || consumed_ > 1;
  std::vector<std::string> parts;
  if (at(TokenKind::identifier)) parseDottedName(parts, nullptr);
  if (misplaced)
    report(kw.range, DiagCode::E0127, "'within' must come first in the file", "move the 'within' clause to the top");
  else
    def.within = std::move(parts);
  expectSemi("after the 'within' clause");
  panic_ = false;
}

/// class_definition := class_prefix IDENT ( "=" short_class_specifier
///                                        | [description] composition "end" IDENT ";" )
/// class_prefix := "model" | "connector" | "package" | "record" | "block" | "function" | "type"
std::unique_ptr<ast::ClassDef> Parser::parseClass() {
  auto cls = std::make_unique<ast::ClassDef>();
  Token kw = take();
  cls->kind = classKindOf(kw.kind);
  cls->range = kw.range;
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("classes");
    return cls;
  }
  if (!at(TokenKind::identifier)) {
    failExpected("a class name after " + quoted(kw.kind), DiagCode::E0116);
    return cls;
  }
  Token name = take();
  cls->name = std::string(name.text);
  cls->nameRange = name.range;
  if (accept(TokenKind::equal)) {
    parseShortClass(*cls);
  } else {
    cls->description = parseDescription();
    ast::ClassDef* outer = currentClass_;
    bool outerProtected = std::exchange(protected_, false);
    currentClass_ = cls.get();
    openClasses_.push_back(cls.get());
    parseComposition(*cls);
    parseClassEnd(*cls);
    openClasses_.pop_back();
    currentClass_ = outer;
    protected_ = outerProtected;
  }
  cls->range = rangeFrom(kw.range.begin);
  return cls;
}

/// short_class_specifier := type_specifier [class_modification] [description] ";"
/// (`type Length = Real(unit = "m");` is stored as a class that extends Real(unit = "m"))
void Parser::parseShortClass(ast::ClassDef& cls) {
  ast::ExtendsClause ext;
  uint32_t begin = tok().range.begin;
  if (!parseTypeSpecifier(ext.baseName, ext.range)) {
    failExpected("a type name after '='", DiagCode::E0116, "write e.g. 'type Length = Real(unit = \"m\");'");
    return;
  }
  if (at(TokenKind::lParen)) ext.mods = parseClassModification();
  ext.range = rangeFrom(begin);
  cls.extends.push_back(std::move(ext));
  if (panic_) return;
  cls.description = parseDescription();
  expectSemi("after the definition of '" + cls.name + "'");
}

/// composition := {element | visibility} {section}
/// (elements after the first section are reported, E0125, and kept)
/// A function is a class whose elements are `input` declarations (a binding is the default),
/// one `output` declaration bound to the result, and `protected` locals bound in order:
///   function f "description"  input Real x;  input Real k = 2;  output Real y = k*t;
///                             protected Real t = x^2;  end f;
void Parser::parseComposition(ast::ClassDef& cls) {
  SourceRange firstSection;
  while (!at(TokenKind::eof) && !at(TokenKind::kw_end)) {
    uint64_t start = consumed_;
    if (parseVisibility() || skipUnsupported()) continue;
    if (atSectionStart()) {
      if (!firstSection.valid()) firstSection = tok().range;
      parseSection(cls);
    } else {
      if (firstSection.valid() && !at(TokenKind::kw_annotation)) {
        Diagnostic* d = report(tok().range, DiagCode::E0125, "declarations must come before the first section",
                               "move this above the '" + std::string(sm_.slice(firstSection)) + "' line");
        if (d) d->notes.push_back({firstSection, "the first section starts here"});
      }
      parseElement(cls);
    }
    recover(start);
  }
}

/// class_end := "end" IDENT ";"
void Parser::parseClassEnd(ast::ClassDef& cls) {
  std::string closer = "'end " + cls.name + ";'";
  if (at(TokenKind::eof)) {
    Diagnostic* d = report(afterPrev(), DiagCode::E0126, "expected " + closer + " before the end of the file", "add " + closer);
    if (d) d->notes.push_back({cls.nameRange, "'" + cls.name + "' starts here"});
    return;
  }
  const Token& next = peek(1);
  bool closesOuter = next.is(TokenKind::identifier) && next.text != cls.name &&
                     std::any_of(openClasses_.begin(), openClasses_.end() - 1,
                                 [&](const ast::ClassDef* c) { return c->name == next.text; });
  if (closesOuter) {  // the inner class lacks its end: leave `end Outer` to the outer class
    Diagnostic* d = report(tok().range, DiagCode::E0126, "expected " + closer + " before 'end " + std::string(next.text) + "'",
                           "add " + closer);
    if (d) d->notes.push_back({cls.nameRange, "'" + cls.name + "' starts here"});
    return;
  }
  take();  // end
  if (at(TokenKind::identifier)) {
    Token name = take();
    if (name.text != cls.name) {
      Diagnostic* d = report(name.range, DiagCode::E0121,
                             "'end " + std::string(name.text) + "' does not match the class name '" + cls.name + "'",
                             "write " + closer);
      if (d) d->notes.push_back({cls.nameRange, "the class is named here"});
    }
  } else {
    report(tok().range, DiagCode::E0121, "expected the class name '" + cls.name + "' after 'end', found " + describe(tok()),
           "write " + closer);
    if (at(TokenKind::kw_for) || at(TokenKind::kw_if) || at(TokenKind::kw_when)) take();
  }
  expectSemi("after " + closer.substr(0, closer.size() - 2) + "'");
}

/// element := class_definition | extends_clause | import_clause | annotation ";"
///          | component_clause
void Parser::parseElement(ast::ClassDef& cls) {
  if (atClassKeyword()) {
    cls.classes.push_back(parseClass());
  } else if (at(TokenKind::kw_extends)) {
    parseExtends(cls);
  } else if (at(TokenKind::kw_import)) {
    parseImport(cls.imports);
  } else if (at(TokenKind::kw_annotation)) {
    parseAnnotationStatement();
  } else if (atElementStart()) {
    parseComponentClause(cls);
  } else {
    std::string help;
    if (isMechanicsWord(tok()))
      help = "mechanics statements go after the 'mechanics' keyword";
    else if (at(TokenKind::identifier) || canStartExpression())
      help = "equations go after the 'equation' keyword";
    failExpected("a declaration", DiagCode::E0123, help);
  }
}

/// extends_clause := "extends" type_specifier [class_modification] [annotation] ";"
void Parser::parseExtends(ast::ClassDef& cls) {
  Token kw = take();
  ast::ExtendsClause ext;
  SourceRange typeRange;
  if (!parseTypeSpecifier(ext.baseName, typeRange)) {
    failExpected("a class name after 'extends'", DiagCode::E0116);
    return;
  }
  if (at(TokenKind::lParen)) ext.mods = parseClassModification();
  if (!panic_ && at(TokenKind::kw_annotation)) parseAnnotation();
  ext.range = rangeFrom(kw.range.begin);
  cls.extends.push_back(std::move(ext));
  if (!panic_) expectSemi("after the 'extends' clause");
}

/// import_clause := "import" ( IDENT "=" name | name [".*"] ) [description] ";"
void Parser::parseImport(std::vector<ast::ImportClause>& into) {
  Token kw = take();
  ast::ImportClause imp;
  if (at(TokenKind::identifier) && peek(1).is(TokenKind::equal)) {
    imp.alias = std::string(take().text);
    take();
  }
  if (!at(TokenKind::identifier)) {
    failExpected("a package name after " + std::string(imp.alias.empty() ? "'import'" : "'='"), DiagCode::E0116);
    return;
  }
  imp.path.emplace_back(take().text);
  while (at(TokenKind::dot)) {
    take();
    if (imp.alias.empty() && accept(TokenKind::star)) {
      imp.wildcard = true;
      break;
    }
    if (!at(TokenKind::identifier)) return failExpected("a name or '*' after '.'", DiagCode::E0116);
    imp.path.emplace_back(take().text);
  }
  parseDescription();
  imp.range = rangeFrom(kw.range.begin);
  into.push_back(std::move(imp));
  expectSemi("after the 'import' clause");
}

// ---------------------------------------------------------------------------------------------
// Declarations
// ---------------------------------------------------------------------------------------------

/// component_clause := {type_prefix} type_specifier [array_subscripts]
///                     declarator {"," declarator} ";"
void Parser::parseComponentClause(ast::ClassDef& cls) {
  Prefixes pre = parsePrefixes();
  std::vector<std::string> type;
  SourceRange typeRange;
  if (!parseTypeSpecifier(type, typeRange)) {
    failExpected(pre.begin == UINT32_MAX ? "a type name" : "a type name after the prefixes", DiagCode::E0116,
                 "declarations look like 'parameter Real k = 1;'");
    return;
  }
  if (pre.begin != UINT32_MAX && type.size() == 1 && !at(TokenKind::identifier) && !at(TokenKind::lBracket) &&
      prev_.is(TokenKind::identifier)) {  // `parameter k = 1;`
    fail(typeRange, DiagCode::E0116, "missing type in the declaration of '" + type[0] + "'",
         "write the type before the name, as in 'parameter Real " + type[0] + " = 1;'");
    return;
  }
  std::vector<ExprPtr> typeDims;
  if (at(TokenKind::lBracket)) typeDims = parseArraySubscripts();
  do {
    ast::Declaration d;
    d.variability = pre.variability;
    d.causality = pre.causality;
    d.isCoordinate = pre.isCoordinate;
    d.isFlow = pre.isFlow;
    d.isProtected = protected_;
    d.typeName = type;
    d.typeRange = typeRange;
    for (const auto& e : typeDims) d.typeDims.push_back(e ? ast::clone(*e) : nullptr);
    bool ok = !panic_ && parseDeclarator(d);
    if (!d.name.empty()) cls.declarations.push_back(std::move(d));
    if (!ok) return;
  } while (accept(TokenKind::comma));
  expectSemi("after the declaration of '" + cls.declarations.back().name + "'");
}

/// type_prefix := "parameter" | "constant" | "input" | "output" | "flow" | "coordinate"
/// (any order, each at most once; parameter/constant and input/output exclude each other)
Parser::Prefixes Parser::parsePrefixes() {
  Prefixes p;
  while (atPrefixKeyword()) {
    Token t = take();
    if (p.begin == UINT32_MAX) p.begin = t.range.begin;
    std::string name = quoted(t.kind);
    std::string conflict;  // the earlier prefix this one clashes with, if any
    bool duplicate = false;
    if (t.is(TokenKind::kw_parameter) || t.is(TokenKind::kw_constant)) {
      auto v = t.is(TokenKind::kw_parameter) ? ast::Variability::Parameter : ast::Variability::Constant;
      duplicate = p.variability == v;
      if (!duplicate && p.variability != ast::Variability::Continuous) conflict = "parameter' or 'constant";
      p.variability = v;
    } else if (t.is(TokenKind::kw_input) || t.is(TokenKind::kw_output)) {
      auto c = t.is(TokenKind::kw_input) ? ast::Causality::Input : ast::Causality::Output;
      duplicate = p.causality == c;
      if (!duplicate && p.causality != ast::Causality::None) conflict = "input' or 'output";
      p.causality = c;
    } else {
      bool& flag = t.is(TokenKind::kw_flow) ? p.isFlow : p.isCoordinate;
      duplicate = flag;
      flag = true;
    }
    if (duplicate) report(t.range, DiagCode::E0122, "duplicate prefix " + name, "remove the repeated " + name);
    if (!conflict.empty())
      report(t.range, DiagCode::E0122, name + " conflicts with an earlier prefix", "a declaration is either '" + conflict + "'");
  }
  return p;
}

/// type_specifier := "Real" | "Integer" | "Boolean" | IDENT {"." IDENT}
bool Parser::parseTypeSpecifier(std::vector<std::string>& parts, SourceRange& range) {
  uint32_t begin = tok().range.begin;
  if (at(TokenKind::kw_Real) || at(TokenKind::kw_Integer) || at(TokenKind::kw_Boolean)) {
    parts.emplace_back(take().text);
  } else if (!at(TokenKind::identifier) || !parseDottedName(parts, nullptr)) {
    return false;
  }
  range = rangeFrom(begin);
  return true;
}

/// name := IDENT {"." IDENT}
bool Parser::parseDottedName(std::vector<std::string>& parts, std::vector<SourceRange>* ranges) {
  if (!at(TokenKind::identifier)) return false;
  do {
    Token t = take();
    parts.emplace_back(t.text);
    if (ranges) ranges->push_back(t.range);
  } while (at(TokenKind::dot) && peek(1).is(TokenKind::identifier) && (take(), true));
  return true;
}

/// declarator := IDENT [array_subscripts] [class_modification] ["=" expression]
///               [description] [annotation]
bool Parser::parseDeclarator(ast::Declaration& d) {
  if (!at(TokenKind::identifier)) {
    failExpected("a name after the type '" + join(d.typeName) + "'", DiagCode::E0116);
    return false;
  }
  Token name = take();
  d.name = std::string(name.text);
  d.nameRange = name.range;
  if (at(TokenKind::lBracket)) d.dims = parseArraySubscripts();
  if (!panic_ && at(TokenKind::lParen)) d.mods = parseClassModification();
  if (!panic_ && accept(TokenKind::equal)) d.binding = parseExpression();
  if (!panic_) d.description = parseDescription();
  if (!panic_ && at(TokenKind::kw_annotation)) d.annotation = parseAnnotation();
  d.range = rangeFrom(name.range.begin);
  return !panic_;
}

/// class_modification := "(" [argument {"," argument}] ")"
std::vector<ast::Modification> Parser::parseClassModification() {
  std::vector<ast::Modification> mods;
  OpTok open = takeOp();
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("modifications");
    return mods;
  }
  if (accept(TokenKind::rParen)) return mods;
  do {
    auto m = parseArgument();
    if (m) mods.push_back(std::move(*m));
    if (panic_) return mods;
  } while (accept(TokenKind::comma));
  expectClose(TokenKind::rParen, open, true);
  return mods;
}

/// argument := {"each" | "final"} name [class_modification] ["=" expression] [description]
std::optional<ast::Modification> Parser::parseArgument() {
  while (at(TokenKind::kw_each) || at(TokenKind::kw_final)) take();
  uint32_t begin = tok().range.begin;
  std::vector<std::string> parts;
  std::vector<SourceRange> ranges;
  if (!parseDottedName(parts, &ranges)) {
    failExpected("a name in the modification", DiagCode::E0116, "modifications look like (start = 0, fixed = true)");
    return std::nullopt;
  }
  ast::Modification m;
  m.name = join(parts);
  m.nameRange = SourceRange::cover(ranges.front(), ranges.back());
  if (at(TokenKind::lParen)) m.nested = parseClassModification();
  if (!panic_ && accept(TokenKind::equal)) m.value = parseExpression();
  if (!panic_) parseDescription();
  m.range = rangeFrom(begin);
  return m;
}

/// annotation := "annotation" class_modification
ast::Annotation Parser::parseAnnotation() {
  Token kw = take();
  ast::Annotation a;
  if (!at(TokenKind::lParen))
    failExpected("'(' after 'annotation'", DiagCode::E0117, "write annotation(experiment(StopTime = 10))");
  else
    a.mods = parseClassModification();
  a.range = rangeFrom(kw.range.begin);
  return a;
}

/// description := [STRING {"+" STRING}]
std::string Parser::parseDescription() {
  if (!at(TokenKind::string)) return {};
  std::string s = take().value;
  while (at(TokenKind::plus) && peek(1).is(TokenKind::string)) {
    take();
    s += take().value;
  }
  return s;
}

}  // namespace qdot::syntax
