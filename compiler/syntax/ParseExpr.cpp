// The grammar of expressions (spec §6), from the if-expression down to primaries. Precedence,
// low to high: if, range, or, and, not, relations (non-associative), + - (and leading unary),
// * /, ^ (non-associative), postfix (call, subscript, member). Every recursion is depth-guarded.
#include "syntax/ParserImpl.h"

namespace qdot::syntax {

using ast::ExprPtr;

namespace {

using ast::BinaryOp;

std::optional<BinaryOp> relationalOp(TokenKind k) {
  switch (k) {
    case TokenKind::less: return BinaryOp::Lt;
    case TokenKind::lessEqual: return BinaryOp::Le;
    case TokenKind::greater: return BinaryOp::Gt;
    case TokenKind::greaterEqual: return BinaryOp::Ge;
    case TokenKind::equalEqual: return BinaryOp::Eq;
    case TokenKind::notEqual: return BinaryOp::Ne;
    default: return std::nullopt;
  }
}

bool isSign(TokenKind k) { return k == TokenKind::plus || k == TokenKind::minus; }

ast::UnaryOp signOp(TokenKind k) { return k == TokenKind::minus ? ast::UnaryOp::Neg : ast::UnaryOp::Plus; }

}  // namespace

ExprPtr Parser::makeBinary(BinaryOp op, SourceRange opRange, ExprPtr lhs, ExprPtr rhs, uint32_t begin) {
  return std::make_unique<ast::BinaryExpr>(rangeFrom(begin), op, opRange, std::move(lhs), std::move(rhs));
}

bool Parser::canStartExpression() {
  switch (tok().kind) {
    case TokenKind::number: case TokenKind::string: case TokenKind::kw_true: case TokenKind::kw_false:
    case TokenKind::kw_time: case TokenKind::identifier: case TokenKind::kw_der: case TokenKind::kw_initial:
    case TokenKind::kw_pre: case TokenKind::kw_reinit: case TokenKind::lParen: case TokenKind::lBrace:
    case TokenKind::plus: case TokenKind::minus: case TokenKind::kw_not: case TokenKind::kw_if: return true;
    default: return false;
  }
}

/// expression := "if" expression "then" expression
///               {"elseif" expression "then" expression} "else" expression
///             | range_expression
ExprPtr Parser::parseExpression() {
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("expression");
    return nullptr;
  }
  if (at(TokenKind::kw_if)) return parseIfExpression();
  return parseRange();
}

ExprPtr Parser::parseIfExpression() {
  uint32_t begin = take().range.begin;
  std::vector<ExprPtr> conditions, values;
  do {
    conditions.push_back(parseExpression());
    if (panic_ || !expect(TokenKind::kw_then, "after the condition of the if-expression")) return nullptr;
    values.push_back(parseExpression());
    if (panic_) return nullptr;
  } while (accept(TokenKind::kw_elseif));
  if (!at(TokenKind::kw_else)) {
    failExpected("'else' in the if-expression", DiagCode::E0117, "an if-expression needs an 'else' branch: if c then a else b");
    return nullptr;
  }
  take();
  ExprPtr elseValue = parseExpression();
  return std::make_unique<ast::IfExpr>(rangeFrom(begin), std::move(conditions), std::move(values),
                                       std::move(elseValue));
}

/// range_expression := logical_expression [":" logical_expression [":" logical_expression]]
/// (a:b is start:stop; a:s:b is start:step:stop)
ExprPtr Parser::parseRange() {
  uint32_t begin = tok().range.begin;
  ExprPtr first = parseOr();
  if (panic_ || !at(TokenKind::colon)) return first;
  take();
  ExprPtr second = parseOr();
  if (panic_ || !accept(TokenKind::colon))
    return std::make_unique<ast::RangeExpr>(rangeFrom(begin), std::move(first), nullptr, std::move(second));
  ExprPtr third = parseOr();
  if (!panic_ && at(TokenKind::colon))
    fail(tok().range, DiagCode::E0115, "a range has at most three parts", "write start:stop or start:step:stop");
  return std::make_unique<ast::RangeExpr>(rangeFrom(begin), std::move(first), std::move(second), std::move(third));
}

/// logical_expression := logical_term {"or" logical_term}
ExprPtr Parser::parseOr() {
  uint32_t begin = tok().range.begin;
  ExprPtr lhs = parseAnd();
  ChainGuard chain(*this);
  while (!panic_ && at(TokenKind::kw_or) && chain.next()) {
    SourceRange op = take().range;
    ExprPtr rhs = parseAnd();
    lhs = makeBinary(BinaryOp::Or, op, std::move(lhs), std::move(rhs), begin);
  }
  return lhs;
}

/// logical_term := logical_factor {"and" logical_factor}
ExprPtr Parser::parseAnd() {
  uint32_t begin = tok().range.begin;
  ExprPtr lhs = parseNot();
  ChainGuard chain(*this);
  while (!panic_ && at(TokenKind::kw_and) && chain.next()) {
    SourceRange op = take().range;
    ExprPtr rhs = parseNot();
    lhs = makeBinary(BinaryOp::And, op, std::move(lhs), std::move(rhs), begin);
  }
  return lhs;
}

/// logical_factor := "not" logical_factor | relation
ExprPtr Parser::parseNot() {
  if (!at(TokenKind::kw_not)) return parseRelation();
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("expression");
    return nullptr;
  }
  uint32_t begin = take().range.begin;
  ExprPtr operand = parseNot();
  return std::make_unique<ast::UnaryExpr>(rangeFrom(begin), ast::UnaryOp::Not, std::move(operand));
}

/// relation := arithmetic_expression [rel_op arithmetic_expression]
/// rel_op := "<" | "<=" | ">" | ">=" | "==" | "<>"        (a < b < c is an error, E0115)
ExprPtr Parser::parseRelation() {
  uint32_t begin = tok().range.begin;
  ExprPtr lhs = parseArithmetic();
  bool chained = false;
  ChainGuard chain(*this);
  while (!panic_ && relationalOp(tok().kind) && chain.next()) {
    if (chained)
      report(tok().range, DiagCode::E0115, "comparison operators cannot be chained",
             "combine the comparisons with 'and': a < b and b < c");
    OpTok op = takeOp();
    ExprPtr rhs = parseArithmetic();
    lhs = makeBinary(*relationalOp(op.kind), op.range, std::move(lhs), std::move(rhs), begin);
    chained = true;
  }
  return lhs;
}

/// arithmetic_expression := unary_term {("+" | "-") unary_term}
ExprPtr Parser::parseArithmetic() {
  uint32_t begin = tok().range.begin;
  ExprPtr lhs = parseUnaryTerm();
  ChainGuard chain(*this);
  while (!panic_ && isSign(tok().kind) && chain.next()) {
    OpTok op = takeOp();
    ExprPtr rhs = parseUnaryTerm();
    lhs = makeBinary(op.kind == TokenKind::plus ? BinaryOp::Add : BinaryOp::Sub, op.range, std::move(lhs), std::move(rhs),
                     begin);
  }
  return lhs;
}

/// unary_term := ("+" | "-") unary_term | term         (-x^2 is -(x^2); -a*b is -(a*b))
ExprPtr Parser::parseUnaryTerm() {
  if (!isSign(tok().kind)) return parseTerm();
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("expression");
    return nullptr;
  }
  OpTok op = takeOp();
  ExprPtr operand = parseUnaryTerm();
  return std::make_unique<ast::UnaryExpr>(rangeFrom(op.range.begin), signOp(op.kind), std::move(operand));
}

/// term := factor {("*" | "/") signed_factor}
ExprPtr Parser::parseTerm() {
  uint32_t begin = tok().range.begin;
  ExprPtr lhs = parseFactor();
  ChainGuard chain(*this);
  while (!panic_ && (at(TokenKind::star) || at(TokenKind::slash)) && chain.next()) {
    OpTok op = takeOp();
    ExprPtr rhs = parseSignedFactor();
    lhs = makeBinary(op.kind == TokenKind::star ? BinaryOp::Mul : BinaryOp::Div, op.range, std::move(lhs), std::move(rhs),
                     begin);
  }
  return lhs;
}

/// signed_factor := ("+" | "-") signed_factor | factor      (2*-3 is 2*(-3))
ExprPtr Parser::parseSignedFactor() {
  if (!isSign(tok().kind)) return parseFactor();
  DepthGuard guard(*this);
  if (!guard.ok()) {
    tooDeep("expression");
    return nullptr;
  }
  OpTok op = takeOp();
  ExprPtr operand = parseSignedFactor();
  return std::make_unique<ast::UnaryExpr>(rangeFrom(op.range.begin), signOp(op.kind), std::move(operand));
}

/// factor := postfix ["^" power_operand]          (a^b^c is an error, E0114)
ExprPtr Parser::parseFactor() {
  uint32_t begin = tok().range.begin;
  ExprPtr base = parsePostfix();
  if (panic_ || !at(TokenKind::caret)) return base;
  SourceRange op = take().range;
  ExprPtr exponent = parsePowerOperand();
  ExprPtr result = makeBinary(BinaryOp::Pow, op, std::move(base), std::move(exponent), begin);
  ChainGuard chain(*this);
  for (bool first = true; !panic_ && at(TokenKind::caret) && chain.next(); first = false) {
    SourceRange op2 = take().range;
    ExprPtr rhs = parsePowerOperand();
    if (first) reportChainedPower(*ast::cast<ast::BinaryExpr>(result.get()), rhs.get(), op2);
    result = makeBinary(BinaryOp::Pow, op2, std::move(result), std::move(rhs), begin);
  }
  return result;
}

// Out of line so that parseFactor's frame stays small (it recurses).
[[gnu::noinline]] void Parser::reportChainedPower(const ast::BinaryExpr& first, const ast::Expr* third, SourceRange at) {
  std::string a(first.lhs ? sm_.slice(first.lhs->range) : "");
  std::string b(first.rhs ? sm_.slice(first.rhs->range) : "");
  std::string c(third ? sm_.slice(third->range) : "");
  if (a.empty() || b.empty() || c.empty() || a.size() + b.size() + c.size() > 40)
    a = std::string(1, 'a'), b = std::string(1, 'b'), c = std::string(1, 'c');
  std::string help = "add parentheses: (";  // (a^b)^c or a^(b^c); append() avoids a GCC 12 -Wrestrict false alarm
  help.append(a).append("^").append(b).append(")^").append(c).append(" or ");
  help.append(a).append("^(").append(b).append("^").append(c);
  report(at, DiagCode::E0114, "the power operator '^' is not associative", help + ")");
}

/// power_operand := ["+" | "-"] postfix                  (a^-1)
ExprPtr Parser::parsePowerOperand() {
  if (!isSign(tok().kind)) return parsePostfix();
  OpTok op = takeOp();
  ExprPtr operand = parsePostfix();
  return std::make_unique<ast::UnaryExpr>(rangeFrom(op.range.begin), signOp(op.kind), std::move(operand));
}

/// postfix := primary {array_subscripts | "." IDENT | function_call_args}
/// (a dotted name without subscripts stays one NameExpr; only a name can be called; only a name
///  or a subscripted/member expression can have a `.field`)
ExprPtr Parser::parsePostfix() {
  uint32_t begin = tok().range.begin;
  bool plainName = false;
  ExprPtr e = parsePrimary(plainName);
  ChainGuard chain(*this);
  while (e && !panic_) {
    if (at(TokenKind::lBracket)) {
      if (!chain.next()) break;
      e = parseSubscripts(std::move(e), begin);
      plainName = false;
    } else if (at(TokenKind::dot)) {
      if (!plainName && !ast::isa<ast::IndexExpr>(e.get()) && !ast::isa<ast::MemberExpr>(e.get())) {
        failNotComponent(*e);  // 5.0.x, (a + b).x, f(x).y
        break;
      }
      take();
      if (!at(TokenKind::identifier)) {
        failExpected("a name after '.'", DiagCode::E0116);
        break;
      }
      std::string_view field = tok().text;
      SourceRange fieldRange = take().range;
      if (!plainName && !chain.next()) break;
      if (plainName) {
        auto* name = static_cast<ast::NameExpr*>(e.get());
        name->parts.emplace_back(field);
        name->partRanges.push_back(fieldRange);
        name->range = rangeFrom(begin);
      } else {
        e = std::make_unique<ast::MemberExpr>(rangeFrom(begin), std::move(e), std::string(field), fieldRange);
      }
    } else if (at(TokenKind::lParen) && plainName) {
      std::unique_ptr<ast::NameExpr> callee(static_cast<ast::NameExpr*>(e.release()));
      e = parseCall(std::move(callee), begin);
      plainName = false;
    } else if (at(TokenKind::lParen) && (ast::isa<ast::IndexExpr>(e.get()) || ast::isa<ast::MemberExpr>(e.get()))) {
      failNotCallable(*e);
      break;
    } else {
      break;
    }
  }
  return e;
}

[[gnu::noinline]] void Parser::failNotComponent(const ast::Expr& e) {
  fail(tok().range, DiagCode::E0118, "only a component can have members, not " + quote(sm_.slice(e.range)),
       "member access looks like a.b or ms[2].a");
}

[[gnu::noinline]] void Parser::failNotCallable(const ast::Expr& e) {
  fail(tok().range, DiagCode::E0118, "only a name can be called, not " + quote(sm_.slice(e.range)),
       "call functions by name, as in f(x) or Package.f(x)");
}

/// primary := NUMBER | STRING | "true" | "false" | "time" | IDENT
///          | ("der" | "initial" | "pre" | "reinit") function_call_args
///          | "(" expression ")" | "{" array_arguments "}" | "end"  (inside subscripts)
ExprPtr Parser::parsePrimary(bool& plainName) {
  const Token& t = tok();
  switch (t.kind) {
    case TokenKind::number: {
      const Token& n = take();
      return std::make_unique<ast::NumberExpr>(n.range, n.number, n.isInteger);
    }
    case TokenKind::string: {
      const Token& s = take();
      return std::make_unique<ast::StringExpr>(s.range, s.value);
    }
    case TokenKind::kw_true: case TokenKind::kw_false: {
      const Token& b = take();
      return std::make_unique<ast::BoolExpr>(b.range, b.is(TokenKind::kw_true));
    }
    case TokenKind::identifier: case TokenKind::kw_time: {
      plainName = t.is(TokenKind::identifier);
      const Token& n = take();
      return std::make_unique<ast::NameExpr>(n.range, std::vector<std::string>{std::string(n.text)},
                                             std::vector<SourceRange>{n.range});
    }
    case TokenKind::kw_der: case TokenKind::kw_initial: case TokenKind::kw_pre: case TokenKind::kw_reinit:
      return parseKeywordCall();
    case TokenKind::lParen: return parseParenthesized();
    case TokenKind::lBrace: return parseArrayConstructor();
    case TokenKind::kw_end:
      if (subscriptDepth_ > 0 && !atSyncPoint()) return std::make_unique<ast::EndExpr>(take().range);
      [[fallthrough]];
    default: return unexpectedInExpression();
  }
}

ExprPtr Parser::unexpectedInExpression() {
  std::string help;
  if (at(TokenKind::kw_if)) help = "an if-expression inside a larger expression needs parentheses: (if c then a else b)";
  if (at(TokenKind::lBracket)) help = "array literals are written with braces: {1, 2, 3}";
  failExpected("an expression", DiagCode::E0111, help);
  return nullptr;
}

/// keyword_call := ("der" | "initial" | "pre" | "reinit") function_call_args
ExprPtr Parser::parseKeywordCall() {
  const Token& kw = take();
  auto callee = std::make_unique<ast::NameExpr>(kw.range, std::vector<std::string>{std::string(kw.text)},
                                                std::vector<SourceRange>{kw.range});
  if (!at(TokenKind::lParen)) return failKeywordCall(callee->parts[0]);
  uint32_t begin = callee->range.begin;
  return parseCall(std::move(callee), begin);
}

[[gnu::noinline]] ExprPtr Parser::failKeywordCall(std::string_view keyword) {
  failExpected("'(' after " + quote(keyword), DiagCode::E0117,
               quote(keyword) + " is called like a function: " + std::string(keyword) + "(...)");
  return nullptr;
}

/// parenthesized := "(" expression ")"
ExprPtr Parser::parseParenthesized() {
  OpTok open = takeOp();
  ExprPtr e = parseExpression();
  if (!panic_) expectClose(TokenKind::rParen, open);
  return e;
}

/// array_constructor := "{" [expression ("for" for_indices | {"," expression})] "}"
ExprPtr Parser::parseArrayConstructor() {
  OpTok open = takeOp();
  uint32_t begin = open.range.begin;
  std::vector<ExprPtr> elements;
  if (accept(TokenKind::rBrace)) return std::make_unique<ast::ArrayExpr>(rangeFrom(begin), std::move(elements));
  ExprPtr first = parseExpression();
  if (!panic_ && at(TokenKind::kw_for)) {
    ExprPtr c = parseComprehension(std::move(first), tok().range.begin);
    if (!panic_) expectClose(TokenKind::rBrace, open);
    c->range = rangeFrom(begin);
    return c;
  }
  elements.push_back(std::move(first));
  while (!panic_ && accept(TokenKind::comma)) elements.push_back(parseExpression());
  if (!panic_ && at(TokenKind::kw_for))
    fail(tok().range, DiagCode::E0118, "an array comprehension has a single body expression",
         "write {e for i in 1:n}, or list the elements: {a, b, c}");
  if (!panic_) expectClose(TokenKind::rBrace, open, true);
  return std::make_unique<ast::ArrayExpr>(rangeFrom(begin), std::move(elements));
}

/// comprehension := expression "for" for_indices
ExprPtr Parser::parseComprehension(ExprPtr body, uint32_t begin) {
  if (body) begin = body->range.begin;
  take();  // for
  std::vector<ast::Iterator> its = parseForIndices();
  return std::make_unique<ast::ComprehensionExpr>(rangeFrom(begin), std::move(body), std::move(its));
}

ExprPtr Parser::parseSubscripts(ExprPtr base, uint32_t begin) {
  std::vector<ExprPtr> subs = parseArraySubscripts();
  return std::make_unique<ast::IndexExpr>(rangeFrom(begin), std::move(base), std::move(subs));
}

/// array_subscripts := "[" subscript {"," subscript} "]"
/// subscript := ":" | expression
std::vector<ExprPtr> Parser::parseArraySubscripts() {
  OpTok open = takeOp();
  std::vector<ExprPtr> subs;
  ++subscriptDepth_;
  do {
    if (at(TokenKind::colon) && (peek(1).is(TokenKind::comma) || peek(1).is(TokenKind::rBracket))) {
      subs.push_back(std::make_unique<ast::RangeExpr>(take().range, nullptr, nullptr, nullptr));
    } else {
      subs.push_back(parseExpression());
    }
  } while (!panic_ && accept(TokenKind::comma));
  --subscriptDepth_;
  if (!panic_) expectClose(TokenKind::rBracket, open, true);
  return subs;
}

/// function_call_args := "(" [function_arguments] ")"
/// function_arguments := expression "for" for_indices | argument {"," argument}
/// argument := IDENT "=" expression | expression
ExprPtr Parser::parseCall(std::unique_ptr<ast::NameExpr> callee, uint32_t begin) {
  OpTok open = takeOp();
  auto call = std::make_unique<ast::CallExpr>(SourceRange{}, std::move(callee), std::vector<ExprPtr>{},
                                              std::vector<ast::NamedArg>{});
  if (!accept(TokenKind::rParen)) {
    bool sawNamed = false;
    while (parseCallArgument(*call, sawNamed) && accept(TokenKind::comma)) {
    }
    if (!panic_) expectClose(TokenKind::rParen, open, true);
  }
  call->range = rangeFrom(begin);
  return call;
}

// Parses one argument into `call`; returns false after an error.
bool Parser::parseCallArgument(ast::CallExpr& call, bool& sawNamed) {
  if (at(TokenKind::identifier) && peek(1).is(TokenKind::equal)) {
    ast::NamedArg arg{std::string(tok().text), take().range, nullptr};
    take();
    arg.value = parseExpression();
    call.namedArgs.push_back(std::move(arg));
    sawNamed = true;
    return !panic_;
  }
  if (sawNamed)
    report(tok().range, DiagCode::E0118, "positional argument after a named argument", "put the positional arguments first");
  uint32_t begin = tok().range.begin;
  ExprPtr e = parseExpression();
  if (panic_) return false;
  if (!at(TokenKind::kw_for)) {
    call.args.push_back(std::move(e));
    return true;
  }
  bool alone = call.args.empty() && call.namedArgs.empty();
  if (alone) call.args.push_back(parseComprehension(std::move(e), begin));
  if (!panic_ && (!alone || at(TokenKind::comma)))
    fail(tok().range, DiagCode::E0118, "a reduction 'e for i in r' must be the only argument",
         "write e.g. sum(x[i] for i in 1:n)");
  return false;
}

}  // namespace qdot::syntax
