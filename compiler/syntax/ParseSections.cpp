// The grammar of sections: `equation`, `initial equation` (equations, for, if, when, connect)
// and `mechanics` (kinetic, potential, dissipation, force, constraint, for), spec §4-§5.
#include "syntax/ParserImpl.h"

namespace qdot::syntax {

/// section := "equation" {equation} | "initial" "equation" {equation}
///          | "mechanics" {mechanics_statement}
void Parser::parseSection(ast::ClassDef& cls) {
  if (accept(TokenKind::kw_equation)) {
    parseEquationList(cls.equations, false);
  } else if (accept(TokenKind::kw_initial)) {
    take();  // equation
    parseEquationList(cls.initialEquations, false);
  } else {
    take();  // mechanics
    parseMechanicsList(cls.mechanics);
  }
}

void Parser::parseEquationList(std::vector<ast::Equation>& out, bool nested) {
  while (true) {
    if (skipStrayEnd()) continue;
    if (atStatementListEnd(nested)) break;
    uint64_t start = consumed_;
    if (auto eq = parseEquation()) out.push_back(std::move(*eq));
    recover(start);
  }
}

/// equation := for_equation | if_equation | when_equation | connect_equation
///           | annotation ";" | simple_equation
std::optional<ast::Equation> Parser::parseEquation() {
  switch (tok().kind) {
    case TokenKind::kw_for: case TokenKind::kw_if: case TokenKind::kw_when: {
      DepthGuard guard(*this);
      if (!guard.ok()) {
        tooDeep("equations");
        return std::nullopt;
      }
      return at(TokenKind::kw_for) ? parseForEquation() : parseConditionalEquation();
    }
    case TokenKind::kw_connect: return parseConnect();
    case TokenKind::kw_annotation: parseAnnotationStatement(); return std::nullopt;
    default: break;
  }
  if (canStartExpression()) return parseSimpleEquation();
  std::string help;
  if (at(TokenKind::semi)) help = "remove the extra ';'";
  if (at(TokenKind::kw_constraint)) help = "'constraint' statements belong in the 'mechanics' section";
  if (at(TokenKind::kw_else) || at(TokenKind::kw_elseif)) help = "there is no open 'if' for this";
  if (at(TokenKind::kw_elsewhen)) help = "there is no open 'when' for this";
  failExpected("an equation", DiagCode::E0123, help);
  return std::nullopt;
}

/// simple_equation := simple_expression "=" expression [description] [annotation] ";"
///                  | function_call [description] ";"            (reinit(x, e); assert(...);)
std::optional<ast::Equation> Parser::parseSimpleEquation() {
  ast::Equation eq;
  eq.kind = ast::EquationKind::Simple;
  uint32_t begin = tok().range.begin;
  eq.lhs = parseExpression();
  if (panic_) return std::nullopt;
  if (accept(TokenKind::equal)) {
    eq.rhs = parseExpression();
    if (panic_) return std::nullopt;
  } else if (!ast::isa<ast::CallExpr>(eq.lhs.get())) {
    auto* bin = ast::dyn_cast<ast::BinaryExpr>(eq.lhs.get());
    failExpected("'=' in the equation", DiagCode::E0117,
                 bin && bin->op == ast::BinaryOp::Eq ? "'==' compares two values; an equation is written 'lhs = rhs;'"
                                                     : "an equation is written 'lhs = rhs;'");
    return std::nullopt;
  }
  parseDescription();
  if (at(TokenKind::kw_annotation)) parseAnnotation();
  eq.range = rangeFrom(begin);
  if (!panic_) expectSemi("after the equation");
  return eq;
}

/// for_equation := "for" for_indices "loop" {equation} "end" "for" ";"
ast::Equation Parser::parseForEquation() {
  Token kw = take();
  ast::Equation eq;
  eq.kind = ast::EquationKind::For;
  eq.iterators = parseForIndices();
  if (!panic_) expect(TokenKind::kw_loop, "after the for-indices");
  if (!panic_ || resyncTo(TokenKind::kw_loop)) {
    blockStack_.push_back(TokenKind::kw_for);
    parseEquationList(eq.body, true);
    blockStack_.pop_back();
    bool closed = expectEnd(TokenKind::kw_for, kw.range);
    eq.range = rangeFrom(kw.range.begin);
    if (closed) expectSemi("after 'end for'");
  } else {
    brokenBlocks_.push_back(TokenKind::kw_for);
  }
  if (!eq.range.valid()) eq.range = rangeFrom(kw.range.begin);
  return eq;
}

/// if_equation := "if" expression "then" {equation}
///                {"elseif" expression "then" {equation}} ["else" {equation}] "end" "if" ";"
/// when_equation := "when" expression "then" {equation}
///                  {"elsewhen" expression "then" {equation}} "end" "when" ";"
ast::Equation Parser::parseConditionalEquation() {
  Token kw = take();
  bool isIf = kw.is(TokenKind::kw_if);
  TokenKind elseKw = isIf ? TokenKind::kw_elseif : TokenKind::kw_elsewhen;
  ast::Equation eq;
  eq.kind = isIf ? ast::EquationKind::If : ast::EquationKind::When;
  blockStack_.push_back(kw.kind);
  ++branchDepth_;
  bool ok = true;
  do {
    eq.conditions.push_back(parseExpression());
    if (!panic_) expect(TokenKind::kw_then, "after the condition");
    if (panic_ && !resyncTo(TokenKind::kw_then)) {
      ok = false;
      break;
    }
    eq.branches.emplace_back();
    parseEquationList(eq.branches.back(), true);
  } while (accept(elseKw));
  if (ok && isIf && accept(TokenKind::kw_else)) parseEquationList(eq.elseBranch, true);
  --branchDepth_;
  blockStack_.pop_back();
  if (!ok) brokenBlocks_.push_back(kw.kind);
  bool closed = ok && expectEnd(kw.kind, kw.range);
  eq.range = rangeFrom(kw.range.begin);
  if (closed) expectSemi(std::string("after 'end ") + spelling(kw.kind) + "'");
  return eq;
}

/// connect_equation := "connect" "(" expression "," expression ")" [description] ";"
ast::Equation Parser::parseConnect() {
  Token kw = take();
  ast::Equation eq;
  eq.kind = ast::EquationKind::Connect;
  eq.range = kw.range;
  if (!at(TokenKind::lParen)) {
    failExpected("'(' after 'connect'", DiagCode::E0117, "write connect(a, b);");
    return eq;
  }
  OpTok open = takeOp();
  eq.lhs = parseExpression();
  if (!panic_) expect(TokenKind::comma, "between the two connectors");
  if (!panic_) eq.rhs = parseExpression();
  if (!panic_) expectClose(TokenKind::rParen, open);
  if (!panic_) parseDescription();
  eq.range = rangeFrom(kw.range.begin);
  if (!panic_) expectSemi("after the connect equation");
  return eq;
}

/// annotation_statement := annotation ";"   (kept in ClassDef::annotations)
void Parser::parseAnnotationStatement() {
  ast::Annotation a = parseAnnotation();
  if (currentClass_) currentClass_->annotations.push_back(std::move(a));
  if (!panic_) expectSemi("after the annotation");
}

void Parser::parseMechanicsList(std::vector<ast::MechanicsStmt>& out) {
  while (true) {
    if (skipStrayEnd()) continue;
    bool statementWord = tok().isWord("kinetic") || tok().isWord("potential") || tok().isWord("dissipation") ||
                         tok().isWord("force") || tok().isWord("torque") || tok().isWord("gravity");  // `force q = 1;` is a broken statement, not a declaration
    if (!statementWord && atStatementListEnd(false)) break;
    uint64_t start = consumed_;
    if (auto s = parseMechanicsStmt()) out.push_back(std::move(*s));
    recover(start);
  }
}

/// mechanics_statement := ("kinetic" | "potential" | "dissipation") "=" expression ";"
///                      | "force" "(" expression ["," "at" "=" expression] ")" "=" expression ";"
///                      | "torque" "(" expression ["," "world"] ")" "=" expression ";"
///                      | "gravity" "=" expression ";"
///                      | "constraint" expression "=" expression ";"
///                      | "for" for_indices "loop" {mechanics_statement} "end" "for" ";"
///                      | annotation ";"
/// (kinetic, potential, dissipation, force, torque and gravity are contextual words; a description string may
///  precede each ';')
std::optional<ast::MechanicsStmt> Parser::parseMechanicsStmt() {
  if (tok().isWord("kinetic")) return parseEnergyStmt(ast::MechanicsKind::Kinetic);
  if (tok().isWord("potential")) return parseEnergyStmt(ast::MechanicsKind::Potential);
  if (tok().isWord("dissipation")) return parseEnergyStmt(ast::MechanicsKind::Dissipation);
  if (tok().isWord("force")) return parseForceStmt();
  if (tok().isWord("torque")) return parseForceStmt();
  if (tok().isWord("gravity")) return parseEnergyStmt(ast::MechanicsKind::Gravity);
  if (at(TokenKind::kw_constraint)) return parseConstraintStmt();
  if (at(TokenKind::kw_for)) {
    DepthGuard guard(*this);
    if (guard.ok()) return parseMechanicsFor();
    tooDeep("statements");
    return std::nullopt;
  }
  if (at(TokenKind::kw_annotation)) {
    parseAnnotationStatement();
    return std::nullopt;
  }
  failExpected("a mechanics statement", DiagCode::E0124,
               "the mechanics section holds 'kinetic = e;', 'potential = e;', 'dissipation = e;', "
               "'force(q) = e;', 'constraint lhs = rhs;', for-loops and, for rigid bodies, 'gravity = {…};', "
               "'torque(b) = {…};' and 'force(b, at = {…}) = {…};'; equations go in an 'equation' section");
  return std::nullopt;
}

/// energy_statement := ("kinetic" | "potential" | "dissipation") "=" expression [description] ";"
ast::MechanicsStmt Parser::parseEnergyStmt(ast::MechanicsKind kind) {
  Token kw = take();
  ast::MechanicsStmt s;
  s.kind = kind;
  s.keywordRange = kw.range;
  if (expect(TokenKind::equal, "after '" + std::string(kw.text) + "'")) s.value = parseExpression();
  if (!panic_) parseDescription();
  s.range = rangeFrom(kw.range.begin);
  if (!panic_) expectSemi("after the '" + std::string(kw.text) + "' statement");
  return s;
}

/// force_statement := "force" "(" expression ["," "at" "=" expression] ")" "=" expression [description] ";"
///                  | "torque" "(" expression ["," "world"] ")" "=" expression [description] ";"
/// (`at` and `world` only make sense for a rigid body; the body lowering checks that the target is one)
ast::MechanicsStmt Parser::parseForceStmt() {
  Token kw = take();
  bool torque = kw.text == "torque";
  std::string word(kw.text);
  ast::MechanicsStmt s;
  s.kind = torque ? ast::MechanicsKind::Torque : ast::MechanicsKind::Force;
  s.keywordRange = kw.range;
  if (!at(TokenKind::lParen)) {
    failExpected("'(' after '" + word + "'", DiagCode::E0117,
                 torque ? "write torque(b) = {…}; with the body b in parentheses"
                        : "write force(q) = e; with the coordinate q in parentheses");
  } else {
    OpTok open = takeOp();
    s.target = parseExpression();
    if (!panic_ && accept(TokenKind::comma)) parseForceQualifier(s, torque);
    if (!panic_) expectClose(TokenKind::rParen, open);
    if (!panic_ && expect(TokenKind::equal, "after '" + word + "(...)'")) s.value = parseExpression();
  }
  if (!panic_) parseDescription();
  s.range = rangeFrom(kw.range.begin);
  if (!panic_) expectSemi("after the '" + word + "' statement");
  return s;
}

/// What follows the target: `at = {…}` for a force on a body, `world` for a torque in world axes.
void Parser::parseForceQualifier(ast::MechanicsStmt& s, bool torque) {
  if (torque) {
    if (tok().isWord("world")) {
      take();
      s.world = true;
    } else {
      failExpected("'world' after the body", DiagCode::E0116,
                   "torque(b) = {…} is in body axes, torque(b, world) = {…} in world axes");
    }
    return;
  }
  if (tok().isWord("at") && peek(1).is(TokenKind::equal)) {
    take();
    take();
    s.at = parseExpression();
  } else {
    failExpected("'at = {…}' after the body", DiagCode::E0116,
                 "force(b, at = {x, y, z}) = {Fx, Fy, Fz}; applies a force in world axes at a point given in body axes");
  }
}

/// constraint_statement := "constraint" expression "=" expression [description] ";"
ast::MechanicsStmt Parser::parseConstraintStmt() {
  Token kw = take();
  ast::MechanicsStmt s;
  s.kind = ast::MechanicsKind::Constraint;
  s.keywordRange = kw.range;
  s.value = parseExpression();
  if (!panic_ && expect(TokenKind::equal, "in the constraint")) s.rhs = parseExpression();
  if (!panic_) parseDescription();
  s.range = rangeFrom(kw.range.begin);
  if (!panic_) expectSemi("after the constraint");
  return s;
}

/// mechanics_for := "for" for_indices "loop" {mechanics_statement} "end" "for" ";"
ast::MechanicsStmt Parser::parseMechanicsFor() {
  Token kw = take();
  ast::MechanicsStmt s;
  s.kind = ast::MechanicsKind::For;
  s.keywordRange = kw.range;
  s.iterators = parseForIndices();
  if (!panic_) expect(TokenKind::kw_loop, "after the for-indices");
  if (!panic_ || resyncTo(TokenKind::kw_loop)) {
    blockStack_.push_back(TokenKind::kw_for);
    parseMechanicsList(s.body);
    blockStack_.pop_back();
    bool closed = expectEnd(TokenKind::kw_for, kw.range);
    s.range = rangeFrom(kw.range.begin);
    if (closed) expectSemi("after 'end for'");
  } else {
    brokenBlocks_.push_back(TokenKind::kw_for);
  }
  if (!s.range.valid()) s.range = rangeFrom(kw.range.begin);
  return s;
}

/// for_indices := for_index {"," for_index}
/// for_index := IDENT "in" expression
std::vector<ast::Iterator> Parser::parseForIndices() {
  std::vector<ast::Iterator> its;
  do {
    if (!at(TokenKind::identifier)) {
      failExpected("a loop variable", DiagCode::E0116, "write 'for i in 1:n'");
      break;
    }
    Token name = take();
    if (!at(TokenKind::kw_in)) {
      failExpected("'in' after the loop variable '" + std::string(name.text) + "'", DiagCode::E0117, "write 'for i in 1:n'");
      break;
    }
    take();
    its.push_back({std::string(name.text), name.range, parseExpression()});
  } while (!panic_ && accept(TokenKind::comma));
  return its;
}

}  // namespace qdot::syntax
