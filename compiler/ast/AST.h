// The abstract syntax tree of a .qd file. Every node carries the SourceRange it was parsed from.
// Nodes are plain structs owned by unique_ptr; expression kinds are one enum with a classof per
// subclass so `isa<>/dyn_cast<>` work without RTTI. The tree is what the parser hands to sema.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "support/SourceManager.h"

namespace qdot::ast {

// ---------------------------------------------------------------------------------------------
// Expressions
// ---------------------------------------------------------------------------------------------

enum class ExprKind {
  Number,         ///< 1, 1.5, 2.5E+4 (isInteger tells whether it was written without . or e)
  Bool,           ///< true, false
  String,         ///< "…" (only in annotations and modifiers such as unit = "m")
  Name,           ///< x, time, pi, Vibration.Mass (a dotted name without subscripts)
  Member,         ///< base.field where base has subscripts, e.g. ms[2].a
  Index,          ///< base[i, j]
  Unary,          ///< -e, +e, not e
  Binary,         ///< a + b, a and b, a < b, ...
  Call,           ///< f(args) including der(e), sum(e for i in 1:n), fill(v, n)
  Range,          ///< a:b or a:step:b
  Array,          ///< {a, b, c}
  Comprehension,  ///< e for i in 1:n, j in 1:m   (inside {} or as the one argument of a call)
  If,             ///< if c then a elseif c2 then b else d
  End,            ///< `end` inside a subscript (x[end])
};

struct Expr {
  ExprKind kind;
  SourceRange range;
  explicit Expr(ExprKind k, SourceRange r) : kind(k), range(r) {}
  virtual ~Expr() = default;
};
using ExprPtr = std::unique_ptr<Expr>;

template <class T> bool isa(const Expr* e) { return e && T::classof(e); }
template <class T> const T* dyn_cast(const Expr* e) { return isa<T>(e) ? static_cast<const T*>(e) : nullptr; }
template <class T> T* dyn_cast(Expr* e) { return isa<T>(e) ? static_cast<T*>(e) : nullptr; }
template <class T> const T* cast(const Expr* e) { return static_cast<const T*>(e); }

struct NumberExpr : Expr {
  double value;
  bool isInteger;  ///< written as an integer literal (no '.', no exponent)
  NumberExpr(SourceRange r, double v, bool integer) : Expr(ExprKind::Number, r), value(v), isInteger(integer) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Number; }
};

struct BoolExpr : Expr {
  bool value;
  BoolExpr(SourceRange r, bool v) : Expr(ExprKind::Bool, r), value(v) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Bool; }
};

struct StringExpr : Expr {
  std::string value;  ///< unescaped contents
  StringExpr(SourceRange r, std::string v) : Expr(ExprKind::String, r), value(std::move(v)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::String; }
};

/// A possibly dotted identifier: `x`, `time`, `a.s`, `Vibration.Mass`. One part per identifier.
struct NameExpr : Expr {
  std::vector<std::string> parts;
  std::vector<SourceRange> partRanges;
  NameExpr(SourceRange r, std::vector<std::string> p, std::vector<SourceRange> pr)
      : Expr(ExprKind::Name, r), parts(std::move(p)), partRanges(std::move(pr)) {}
  std::string dotted() const {
    std::string s;
    for (size_t i = 0; i < parts.size(); ++i) s += (i ? "." : "") + parts[i];
    return s;
  }
  static bool classof(const Expr* e) { return e->kind == ExprKind::Name; }
};

/// `base.field` where base is not a plain dotted name (it has subscripts): `ms[2].a`.
struct MemberExpr : Expr {
  ExprPtr base;
  std::string field;
  SourceRange fieldRange;
  MemberExpr(SourceRange r, ExprPtr b, std::string f, SourceRange fr)
      : Expr(ExprKind::Member, r), base(std::move(b)), field(std::move(f)), fieldRange(fr) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Member; }
};

/// `base[s1, s2]`; a subscript may be a Range (`x[2:3]`) or `:` (represented as a Range with
/// null bounds).
struct IndexExpr : Expr {
  ExprPtr base;
  std::vector<ExprPtr> subscripts;
  IndexExpr(SourceRange r, ExprPtr b, std::vector<ExprPtr> s)
      : Expr(ExprKind::Index, r), base(std::move(b)), subscripts(std::move(s)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Index; }
};

enum class UnaryOp { Neg, Plus, Not };

struct UnaryExpr : Expr {
  UnaryOp op;
  ExprPtr operand;
  UnaryExpr(SourceRange r, UnaryOp o, ExprPtr e) : Expr(ExprKind::Unary, r), op(o), operand(std::move(e)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Unary; }
};

enum class BinaryOp { Add, Sub, Mul, Div, Pow, Lt, Le, Gt, Ge, Eq, Ne, And, Or };
const char* spelling(BinaryOp op);

struct BinaryExpr : Expr {
  BinaryOp op;
  SourceRange opRange;
  ExprPtr lhs, rhs;
  BinaryExpr(SourceRange r, BinaryOp o, SourceRange orng, ExprPtr a, ExprPtr b)
      : Expr(ExprKind::Binary, r), op(o), opRange(orng), lhs(std::move(a)), rhs(std::move(b)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Binary; }
};

/// A named argument `name = value` (in annotation calls like experiment(StopTime = 10)).
struct NamedArg {
  std::string name;
  SourceRange nameRange;
  ExprPtr value;
};

/// `f(a, b)`, `der(x)`, `sum(e for i in 1:n)` (args = one ComprehensionExpr), `Foo.bar(x)`.
struct CallExpr : Expr {
  std::unique_ptr<NameExpr> callee;
  std::vector<ExprPtr> args;
  std::vector<NamedArg> namedArgs;
  CallExpr(SourceRange r, std::unique_ptr<NameExpr> c, std::vector<ExprPtr> a, std::vector<NamedArg> n)
      : Expr(ExprKind::Call, r), callee(std::move(c)), args(std::move(a)), namedArgs(std::move(n)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Call; }
};

/// `start:stop` or `start:step:stop`. In a subscript, a bare `:` has all three null.
struct RangeExpr : Expr {
  ExprPtr start, step, stop;  ///< step may be null
  RangeExpr(SourceRange r, ExprPtr a, ExprPtr s, ExprPtr b)
      : Expr(ExprKind::Range, r), start(std::move(a)), step(std::move(s)), stop(std::move(b)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Range; }
};

/// `{a, b, c}`; a 2-D literal is an array of arrays: `{{1, 2}, {3, 4}}`.
struct ArrayExpr : Expr {
  std::vector<ExprPtr> elements;
  ArrayExpr(SourceRange r, std::vector<ExprPtr> e) : Expr(ExprKind::Array, r), elements(std::move(e)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Array; }
};

/// One `i in 1:n` of a for-loop or comprehension. A missing range (`for i loop`) is not supported.
struct Iterator {
  std::string name;
  SourceRange nameRange;
  ExprPtr range;
};

/// `body for i in 1:n, j in 1:m`. As `{body for …}` it builds an array; as the single argument of
/// a call (`sum(body for …)`) it is a reduction.
struct ComprehensionExpr : Expr {
  ExprPtr body;
  std::vector<Iterator> iterators;
  ComprehensionExpr(SourceRange r, ExprPtr b, std::vector<Iterator> it)
      : Expr(ExprKind::Comprehension, r), body(std::move(b)), iterators(std::move(it)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::Comprehension; }
};

/// `if c1 then v1 elseif c2 then v2 else vElse`.
struct IfExpr : Expr {
  std::vector<ExprPtr> conditions;  ///< one per branch
  std::vector<ExprPtr> values;      ///< same length as conditions
  ExprPtr elseValue;
  IfExpr(SourceRange r, std::vector<ExprPtr> c, std::vector<ExprPtr> v, ExprPtr e)
      : Expr(ExprKind::If, r), conditions(std::move(c)), values(std::move(v)), elseValue(std::move(e)) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::If; }
};

struct EndExpr : Expr {
  explicit EndExpr(SourceRange r) : Expr(ExprKind::End, r) {}
  static bool classof(const Expr* e) { return e->kind == ExprKind::End; }
};

/// A deep copy of `e` (used where one written expression applies to several declarations, e.g.
/// the `[3]` of `Real[3] x, y;`). Defined in AST.cpp.
ExprPtr clone(const Expr& e);

// ---------------------------------------------------------------------------------------------
// Modifications: `(start = h/2, fixed = true)`, `Mass m1(m = 2)`, `experiment(StopTime = 10)`
// ---------------------------------------------------------------------------------------------

/// `name = value`, `name(nested...) = value`, or `name(nested...)`. Names may be dotted (`a.m = 1`).
struct Modification {
  std::string name;
  SourceRange nameRange;
  std::vector<Modification> nested;
  ExprPtr value;  ///< may be null
  SourceRange range;
};

/// `annotation(...)`: kept as a modification list. `experiment` is read from it by sema.
struct Annotation {
  std::vector<Modification> mods;
  SourceRange range;
};

// ---------------------------------------------------------------------------------------------
// Declarations
// ---------------------------------------------------------------------------------------------

enum class Variability { Continuous, Parameter, Constant };
enum class Causality { None, Input, Output };

/// One declared name. `parameter Real m = 1, l = 1;` gives two Declarations that share prefixes
/// and type (each with its own range, name, dims, modifications and binding).
struct Declaration {
  SourceRange range;  ///< the whole declarator (name … binding/description)
  Variability variability = Variability::Continuous;
  Causality causality = Causality::None;
  bool isCoordinate = false;
  bool isFlow = false;
  bool isProtected = false;  ///< after `protected` in a function: a local variable
  std::vector<std::string> typeName;  ///< {"Real"}, {"Integer"}, {"Vibration", "Mass"}
  SourceRange typeRange;
  std::vector<ExprPtr> typeDims;  ///< `Real[3] x` (dims written on the type), usually empty
  std::string name;
  SourceRange nameRange;
  std::vector<ExprPtr> dims;  ///< `x[n, 2]`
  std::vector<Modification> mods;
  ExprPtr binding;  ///< `= expr` (null if none)
  std::string description;
  std::optional<Annotation> annotation;
};

struct ExtendsClause {
  std::vector<std::string> baseName;
  SourceRange range;
  std::vector<Modification> mods;
};

struct ImportClause {
  std::vector<std::string> path;  ///< `import A.B.*;` → {"A","B"} with wildcard = true
  bool wildcard = false;
  std::string alias;  ///< `import M = A.B;`
  SourceRange range;
};

// ---------------------------------------------------------------------------------------------
// Equations (equation / initial equation sections)
// ---------------------------------------------------------------------------------------------

enum class EquationKind { Simple, For, Connect, When, If };

struct Equation {
  EquationKind kind;
  SourceRange range;
  // Simple: lhs = rhs.   Connect: connect(lhs, rhs).
  ExprPtr lhs, rhs;
  // For: iterators + body.   When/If: conditions[i] guards branches[i]; elseBranch for If.
  std::vector<Iterator> iterators;
  std::vector<Equation> body;
  std::vector<ExprPtr> conditions;
  std::vector<std::vector<Equation>> branches;
  std::vector<Equation> elseBranch;
  // When: reinit(x, e) statements are Simple equations whose lhs is a CallExpr `reinit(x, e)` and
  // rhs null.
};

// ---------------------------------------------------------------------------------------------
// The mechanics section (spec §5)
// ---------------------------------------------------------------------------------------------

enum class MechanicsKind { Kinetic, Potential, Dissipation, Force, Constraint, For, Gravity, Torque };

struct MechanicsStmt {
  MechanicsKind kind;
  SourceRange range;
  SourceRange keywordRange;
  ExprPtr target;  ///< Force/Torque: the coordinate or body (NameExpr or IndexExpr) inside `force(...)`
  ExprPtr value;   ///< Kinetic/Potential/Dissipation/Force/Gravity/Torque: the rhs; Constraint: lhs
  ExprPtr at;      ///< Force on a body: `force(b, at = {…})`, the point in body axes (null: the centre of mass)
  bool world = false;  ///< Torque: `torque(b, world) = …` (world axes; else body axes)
  ExprPtr rhs;     ///< Constraint: rhs
  std::vector<Iterator> iterators;  ///< For
  std::vector<MechanicsStmt> body;  ///< For
};

// ---------------------------------------------------------------------------------------------
// Classes and files
// ---------------------------------------------------------------------------------------------

enum class ClassKind { Model, Connector, Package, Record, Block, Function, Type };

struct ClassDef {
  ClassKind kind = ClassKind::Model;
  std::string name;
  SourceRange nameRange;
  SourceRange range;
  std::string description;
  std::vector<Declaration> declarations;
  std::vector<ExtendsClause> extends;
  std::vector<ImportClause> imports;
  std::vector<std::unique_ptr<ClassDef>> classes;  ///< nested (packages)
  std::vector<Equation> equations;
  std::vector<Equation> initialEquations;
  std::vector<MechanicsStmt> mechanics;
  std::vector<Annotation> annotations;  ///< class-level annotation(...) statements, any section
};

/// One parsed file: `within` path (optional), imports at its top (for all its classes) and its
/// top-level classes.
struct StoredDefinition {
  uint32_t file = 0;
  std::vector<std::string> within;
  std::vector<ImportClause> imports;
  std::vector<std::unique_ptr<ClassDef>> classes;
};

}  // namespace qdot::ast
