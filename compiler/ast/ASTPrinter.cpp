// printAST / printExpr (the indented tree dump with @line:col) and toSource (expressions back to
// source syntax with minimal parentheses). Both are deterministic: no addresses, no hashing.
#include "ast/ASTPrinter.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <sstream>

namespace qdot::ast {
namespace {

// A string literal in source syntax (escapes the lexer understands). For the tree dump
// (`forDump`), other control characters are shown as \xNN so the dump stays printable.
std::string quote(const std::string& s, bool forDump = false) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      case '\a': out += "\\a"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case '\v': out += "\\v"; break;
      default:
        if (forDump && static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned char>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string join(const std::vector<std::string>& parts) {
  std::string s;
  for (size_t i = 0; i < parts.size(); ++i) s += (i ? "." : "") + parts[i];
  return s;
}

const char* unarySpelling(UnaryOp op) {
  switch (op) {
    case UnaryOp::Neg: return "-";
    case UnaryOp::Plus: return "+";
    case UnaryOp::Not: return "not";
  }
  return "?";
}

const char* className(ClassKind k) {
  switch (k) {
    case ClassKind::Model: return "model";
    case ClassKind::Connector: return "connector";
    case ClassKind::Package: return "package";
    case ClassKind::Record: return "record";
    case ClassKind::Block: return "block";
    case ClassKind::Function: return "function";
    case ClassKind::Type: return "type";
  }
  return "?";
}

const char* mechanicsName(MechanicsKind k) {
  switch (k) {
    case MechanicsKind::Kinetic: return "kinetic";
    case MechanicsKind::Potential: return "potential";
    case MechanicsKind::Dissipation: return "dissipation";
    case MechanicsKind::Force: return "force";
    case MechanicsKind::Constraint: return "constraint";
    case MechanicsKind::For: return "for";
    case MechanicsKind::Gravity: return "gravity";
    case MechanicsKind::Torque: return "torque";
  }
  return "?";
}

const char* equationName(EquationKind k) {
  switch (k) {
    case EquationKind::Simple: return "simple";
    case EquationKind::For: return "for";
    case EquationKind::Connect: return "connect";
    case EquationKind::When: return "when";
    case EquationKind::If: return "if";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// Tree dump
// ---------------------------------------------------------------------------------------------

class TreePrinter {
 public:
  TreePrinter(std::ostream& os, const SourceManager& sm) : os_(os), sm_(sm) {}

  void file(const StoredDefinition& def);
  void imports(const std::vector<ImportClause>& list, int indent);
  void expr(const Expr* e, int indent, const std::string& label = {});

 private:
  std::ostream& line(int indent, const std::string& label = {}) {
    os_ << std::string(2 * indent, ' ');
    if (!label.empty()) os_ << label << ": ";
    return os_;
  }
  std::string at(SourceRange r) const {
    if (!r.valid()) return " @?";
    LineCol lc = sm_.lineCol(r.file, r.begin);
    return " @" + std::to_string(lc.line) + ":" + std::to_string(lc.col);
  }
  void exprChildren(const Expr& e, int indent);
  void iterators(const std::vector<Iterator>& its, int indent);
  void classDef(const ClassDef& c, int indent);
  void declaration(const Declaration& d, int indent);
  void modifications(const std::vector<Modification>& mods, int indent);
  void annotation(const Annotation& a, int indent);
  void equation(const Equation& eq, int indent);
  void equations(const std::vector<Equation>& eqs, int indent, const std::string& label);
  void mechanics(const MechanicsStmt& s, int indent);

  std::ostream& os_;
  const SourceManager& sm_;
};

void TreePrinter::file(const StoredDefinition& def) {
  os_ << "StoredDefinition";
  if (!def.within.empty()) os_ << " within " << join(def.within);
  os_ << '\n';
  imports(def.imports, 1);
  for (const auto& c : def.classes)
    if (c) classDef(*c, 1);
}

void TreePrinter::imports(const std::vector<ImportClause>& list, int indent) {
  for (const auto& imp : list) {
    line(indent) << "Import " << join(imp.path) << (imp.wildcard ? ".*" : "");
    if (!imp.alias.empty()) os_ << " as " << imp.alias;
    os_ << at(imp.range) << '\n';
  }
}

void TreePrinter::classDef(const ClassDef& c, int indent) {
  line(indent) << "Class " << className(c.kind) << ' ' << c.name;
  if (!c.description.empty()) os_ << ' ' << quote(c.description, true);
  os_ << at(c.range) << '\n';
  imports(c.imports, indent + 1);
  for (const auto& ext : c.extends) {
    line(indent + 1) << "Extends " << join(ext.baseName) << at(ext.range) << '\n';
    modifications(ext.mods, indent + 2);
  }
  for (const auto& d : c.declarations) declaration(d, indent + 1);
  for (const auto& nested : c.classes)
    if (nested) classDef(*nested, indent + 1);
  for (const auto& s : c.mechanics) mechanics(s, indent + 1);
  equations(c.equations, indent + 1, "Equations");
  equations(c.initialEquations, indent + 1, "InitialEquations");
  for (const auto& a : c.annotations) annotation(a, indent + 1);
}

void TreePrinter::declaration(const Declaration& d, int indent) {
  line(indent) << "Declaration " << d.name << " :";
  if (d.variability == Variability::Parameter) os_ << " parameter";
  if (d.variability == Variability::Constant) os_ << " constant";
  if (d.causality == Causality::Input) os_ << " input";
  if (d.causality == Causality::Output) os_ << " output";
  if (d.isFlow) os_ << " flow";
  if (d.isCoordinate) os_ << " coordinate";
  if (d.isProtected) os_ << " protected";
  os_ << ' ' << join(d.typeName);
  if (!d.description.empty()) os_ << ' ' << quote(d.description, true);
  os_ << at(d.range) << '\n';
  for (const auto& e : d.typeDims) expr(e.get(), indent + 1, "typeDim");
  for (const auto& e : d.dims) expr(e.get(), indent + 1, "dim");
  modifications(d.mods, indent + 1);
  if (d.binding) expr(d.binding.get(), indent + 1, "binding");
  if (d.annotation) annotation(*d.annotation, indent + 1);
}

void TreePrinter::modifications(const std::vector<Modification>& mods, int indent) {
  for (const auto& m : mods) {
    line(indent) << "Modification " << m.name << at(m.range) << '\n';
    modifications(m.nested, indent + 1);
    if (m.value) expr(m.value.get(), indent + 1, "value");
  }
}

void TreePrinter::annotation(const Annotation& a, int indent) {
  line(indent) << "Annotation" << at(a.range) << '\n';
  modifications(a.mods, indent + 1);
}

void TreePrinter::equations(const std::vector<Equation>& eqs, int indent, const std::string& label) {
  if (eqs.empty()) return;
  line(indent) << label << '\n';
  for (const auto& eq : eqs) equation(eq, indent + 1);
}

void TreePrinter::equation(const Equation& eq, int indent) {
  line(indent) << "Equation " << equationName(eq.kind) << at(eq.range) << '\n';
  bool twoSided = eq.kind == EquationKind::Simple || eq.kind == EquationKind::Connect;
  if (twoSided) expr(eq.lhs.get(), indent + 1, "lhs");
  if (eq.rhs || eq.kind == EquationKind::Connect) expr(eq.rhs.get(), indent + 1, "rhs");  // reinit(...) has none
  iterators(eq.iterators, indent + 1);
  for (const auto& b : eq.body) equation(b, indent + 1);
  for (size_t i = 0; i < std::max(eq.branches.size(), eq.conditions.size()); ++i) {
    line(indent + 1) << "branch\n";
    expr(i < eq.conditions.size() ? eq.conditions[i].get() : nullptr, indent + 2, "condition");
    if (i < eq.branches.size())
      for (const auto& b : eq.branches[i]) equation(b, indent + 2);
  }
  if (!eq.elseBranch.empty()) line(indent + 1) << "else\n";
  for (const auto& b : eq.elseBranch) equation(b, indent + 2);
}

void TreePrinter::mechanics(const MechanicsStmt& s, int indent) {
  line(indent) << "Mechanics " << mechanicsName(s.kind) << at(s.range) << '\n';
  if (s.kind == MechanicsKind::Force || s.kind == MechanicsKind::Torque) expr(s.target.get(), indent + 1, "target");
  if (s.at) expr(s.at.get(), indent + 1, "at");
  if (s.kind != MechanicsKind::For) expr(s.value.get(), indent + 1, s.kind == MechanicsKind::Constraint ? "lhs" : "value");
  if (s.kind == MechanicsKind::Constraint) expr(s.rhs.get(), indent + 1, "rhs");
  iterators(s.iterators, indent + 1);
  for (const auto& b : s.body) mechanics(b, indent + 1);
}

void TreePrinter::iterators(const std::vector<Iterator>& its, int indent) {
  for (const auto& it : its) {
    line(indent) << "Iterator " << it.name << at(it.nameRange) << '\n';
    expr(it.range.get(), indent + 1, "in");
  }
}

void TreePrinter::expr(const Expr* e, int indent, const std::string& label) {
  if (!e) {
    line(indent, label) << "<null>\n";
    return;
  }
  line(indent, label);
  switch (e->kind) {
    case ExprKind::Number: {
      auto* n = cast<NumberExpr>(e);
      os_ << "Number " << formatNumber(n->value, n->isInteger) << (n->isInteger ? " int" : "");
      break;
    }
    case ExprKind::Bool: os_ << "Bool " << (cast<BoolExpr>(e)->value ? "true" : "false"); break;
    case ExprKind::String: os_ << "String " << quote(cast<StringExpr>(e)->value, true); break;
    case ExprKind::Name: os_ << "Name " << cast<NameExpr>(e)->dotted(); break;
    case ExprKind::Member: os_ << "Member ." << cast<MemberExpr>(e)->field; break;
    case ExprKind::Index: os_ << "Index"; break;
    case ExprKind::Unary: os_ << "Unary " << unarySpelling(cast<UnaryExpr>(e)->op); break;
    case ExprKind::Binary: os_ << "Binary " << spelling(cast<BinaryExpr>(e)->op); break;
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(e);
      os_ << "Call " << (c->callee ? c->callee->dotted() : "<null>");
      break;
    }
    case ExprKind::Range: os_ << "Range"; break;
    case ExprKind::Array: os_ << "Array"; break;
    case ExprKind::Comprehension: os_ << "Comprehension"; break;
    case ExprKind::If: os_ << "If"; break;
    case ExprKind::End: os_ << "End"; break;
  }
  os_ << at(e->range) << '\n';
  exprChildren(*e, indent + 1);
}

void TreePrinter::exprChildren(const Expr& e, int indent) {
  switch (e.kind) {
    case ExprKind::Member: expr(cast<MemberExpr>(&e)->base.get(), indent); break;
    case ExprKind::Index:
      expr(cast<IndexExpr>(&e)->base.get(), indent, "base");
      for (const auto& s : cast<IndexExpr>(&e)->subscripts) expr(s.get(), indent, "sub");
      break;
    case ExprKind::Unary: expr(cast<UnaryExpr>(&e)->operand.get(), indent); break;
    case ExprKind::Binary:
      expr(cast<BinaryExpr>(&e)->lhs.get(), indent);
      expr(cast<BinaryExpr>(&e)->rhs.get(), indent);
      break;
    case ExprKind::Call:
      for (const auto& a : cast<CallExpr>(&e)->args) expr(a.get(), indent);
      for (const auto& a : cast<CallExpr>(&e)->namedArgs) expr(a.value.get(), indent, a.name);
      break;
    case ExprKind::Range: {
      auto* r = cast<RangeExpr>(&e);
      if (r->start) expr(r->start.get(), indent, "start");
      if (r->step) expr(r->step.get(), indent, "step");
      if (r->stop) expr(r->stop.get(), indent, "stop");
      break;
    }
    case ExprKind::Array:
      for (const auto& a : cast<ArrayExpr>(&e)->elements) expr(a.get(), indent);
      break;
    case ExprKind::Comprehension:
      expr(cast<ComprehensionExpr>(&e)->body.get(), indent, "body");
      iterators(cast<ComprehensionExpr>(&e)->iterators, indent);
      break;
    case ExprKind::If: {
      auto* i = cast<IfExpr>(&e);
      for (size_t k = 0; k < i->conditions.size(); ++k) {
        expr(i->conditions[k].get(), indent, "if");
        expr(k < i->values.size() ? i->values[k].get() : nullptr, indent, "then");
      }
      expr(i->elseValue.get(), indent, "else");
      break;
    }
    default: break;
  }
}

// ---------------------------------------------------------------------------------------------
// Source printer
// ---------------------------------------------------------------------------------------------

// Binding strength, low to high, matching the parser's precedence levels.
enum Prec { PIf, PRange, POr, PAnd, PNot, PRel, PAdd, PMul, PPow, PPostfix, PPrimary };

int precOf(const Expr& e) {
  switch (e.kind) {
    case ExprKind::If: return PIf;
    case ExprKind::Range: return cast<RangeExpr>(&e)->start ? PRange : PPrimary;
    case ExprKind::Unary: return cast<UnaryExpr>(&e)->op == UnaryOp::Not ? PNot : PAdd;
    case ExprKind::Binary:
      switch (cast<BinaryExpr>(&e)->op) {
        case BinaryOp::Or: return POr;
        case BinaryOp::And: return PAnd;
        case BinaryOp::Add: case BinaryOp::Sub: return PAdd;
        case BinaryOp::Mul: case BinaryOp::Div: return PMul;
        case BinaryOp::Pow: return PPow;
        default: return PRel;
      }
    case ExprKind::Index: case ExprKind::Member: case ExprKind::Call: return PPostfix;
    default: return PPrimary;
  }
}

void source(std::ostream& os, const Expr* e, int minPrec);

void list(std::ostream& os, const std::vector<ExprPtr>& v) {
  for (size_t i = 0; i < v.size(); ++i) {
    if (i) os << ", ";
    source(os, v[i].get(), PIf);
  }
}

void comprehensionBody(std::ostream& os, const ComprehensionExpr& c) {
  source(os, c.body.get(), PIf);
  os << " for ";
  for (size_t i = 0; i < c.iterators.size(); ++i) {
    os << (i ? ", " : "") << c.iterators[i].name << " in ";
    source(os, c.iterators[i].range.get(), PIf);
  }
}

void binarySource(std::ostream& os, const BinaryExpr& b) {
  int p = precOf(b);
  bool leftAssoc = p != PRel && p != PPow;
  bool tight = p == PMul || p == PPow;
  source(os, b.lhs.get(), leftAssoc ? p : p + 1);
  os << (tight ? "" : " ") << spelling(b.op) << (tight ? "" : " ");
  source(os, b.rhs.get(), p + 1);
}

void callSource(std::ostream& os, const CallExpr& c) {
  os << (c.callee ? c.callee->dotted() : "<null>") << '(';
  if (c.args.size() == 1 && isa<ComprehensionExpr>(c.args[0].get())) {
    comprehensionBody(os, *cast<ComprehensionExpr>(c.args[0].get()));
  } else {
    list(os, c.args);
  }
  for (size_t i = 0; i < c.namedArgs.size(); ++i) {
    os << (i || !c.args.empty() ? ", " : "") << c.namedArgs[i].name << " = ";
    source(os, c.namedArgs[i].value.get(), PIf);
  }
  os << ')';
}

void rangeSource(std::ostream& os, const RangeExpr& r) {
  if (!r.start && !r.step && !r.stop) {
    os << ':';
    return;
  }
  source(os, r.start.get(), POr);
  if (r.step) os << ':', source(os, r.step.get(), POr);
  os << ':';
  source(os, r.stop.get(), POr);
}

void ifSource(std::ostream& os, const IfExpr& i) {
  for (size_t k = 0; k < i.conditions.size(); ++k) {
    os << (k ? " elseif " : "if ");
    source(os, i.conditions[k].get(), PIf);
    os << " then ";
    source(os, k < i.values.size() ? i.values[k].get() : nullptr, PIf);
  }
  os << " else ";
  source(os, i.elseValue.get(), PIf);
}

void sourceInner(std::ostream& os, const Expr& e) {
  switch (e.kind) {
    case ExprKind::Number: {
      auto* n = cast<NumberExpr>(&e);
      os << formatNumber(n->value, n->isInteger);
      break;
    }
    case ExprKind::Bool: os << (cast<BoolExpr>(&e)->value ? "true" : "false"); break;
    case ExprKind::String: os << quote(cast<StringExpr>(&e)->value); break;
    case ExprKind::Name: os << cast<NameExpr>(&e)->dotted(); break;
    case ExprKind::Member:
      source(os, cast<MemberExpr>(&e)->base.get(), PPostfix);
      os << '.' << cast<MemberExpr>(&e)->field;
      break;
    case ExprKind::Index:
      source(os, cast<IndexExpr>(&e)->base.get(), PPostfix);
      os << '[';
      list(os, cast<IndexExpr>(&e)->subscripts);
      os << ']';
      break;
    case ExprKind::Unary: {
      auto* u = cast<UnaryExpr>(&e);
      os << unarySpelling(u->op) << (u->op == UnaryOp::Not ? " " : "");
      source(os, u->operand.get(), u->op == UnaryOp::Not ? PRel : PMul);
      break;
    }
    case ExprKind::Binary: binarySource(os, *cast<BinaryExpr>(&e)); break;
    case ExprKind::Call: callSource(os, *cast<CallExpr>(&e)); break;
    case ExprKind::Range: rangeSource(os, *cast<RangeExpr>(&e)); break;
    case ExprKind::Array:
      os << '{';
      list(os, cast<ArrayExpr>(&e)->elements);
      os << '}';
      break;
    case ExprKind::Comprehension:
      os << '{';
      comprehensionBody(os, *cast<ComprehensionExpr>(&e));
      os << '}';
      break;
    case ExprKind::If: ifSource(os, *cast<IfExpr>(&e)); break;
    case ExprKind::End: os << "end"; break;
  }
}

void source(std::ostream& os, const Expr* e, int minPrec) {
  if (!e) {
    os << "<?>";
    return;
  }
  bool parens = precOf(*e) < minPrec;
  if (parens) os << '(';
  sourceInner(os, *e);
  if (parens) os << ')';
}

}  // namespace

std::string formatNumber(double value, bool isInteger) {
  char buf[64];
  std::to_chars_result res{};
  if (isInteger && std::isfinite(value) && std::fabs(value) < 1e18)
    res = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed, 0);
  else
    res = std::to_chars(buf, buf + sizeof buf, value);
  std::string shortest(buf, res.ptr);
  if (shortest.find('e') == std::string::npos || !std::isfinite(value)) return shortest;
  // Prefer 0.0001 to 1e-04 while the plain form stays short.
  res = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed);
  std::string fixed(buf, res.ec == std::errc() ? res.ptr : buf);
  return !fixed.empty() && fixed.size() <= 12 ? fixed : shortest;
}

void printAST(std::ostream& os, const StoredDefinition& def, const SourceManager& sm) {
  TreePrinter(os, sm).file(def);
}

void printExpr(std::ostream& os, const Expr& e, const SourceManager& sm, int indent) {
  TreePrinter(os, sm).expr(&e, indent);
}

std::string toSource(const Expr& e) {
  std::ostringstream os;
  source(os, &e, PIf);
  return os.str();
}

}  // namespace qdot::ast
