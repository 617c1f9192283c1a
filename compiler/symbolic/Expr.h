// The symbolic expression DAG used by every stage from flatten on.
//
// Nodes are immutable and hash-consed inside a Context: structurally equal expressions are the same
// node, so equality is pointer equality and `Expr` is a plain pointer. Constructors simplify to a
// canonical form as they build:
//   * Add:  constant + Σ coef_i * term_i. Terms are non-constant, not Add, not a Mul with a
//           numeric coefficient (that coefficient moves into coef_i), sorted by a stable order,
//           like terms collected, zero coefficients dropped. No Add with one term of coef 1 and
//           constant 0 survives (it is that term).
//   * Mul:  coef * Π base_i ^ exp_i. Bases are non-constant and not Mul; equal bases have their
//           exponents added; exponent-0 factors dropped; coef 0 gives 0. A Mul of a single factor
//           with coef 1 is that factor (or a Pow). Products of sums are NOT expanded; a numeric
//           coefficient times an Add is kept as a Mul (no distribution), so sizes stay linear.
//   * Pow:  base ^ exponent with both folded when constant; x^0 = 1, x^1 = x, (x^a)^b = x^(a*b)
//           for integer b. An integer power of a product distributes over its factors
//           ((2*x*y)^-1 = 0.5*x^-1*y^-1), so a/(b*c) and a*b^-1*c^-1 are one node.
//   * functions fold on constant arguments (sin(0) = 0, exp(0) = 1, ...); x - x = 0, x / x = 1.
//     min, max, ==, <>, and, or order their arguments (min(x, y) is min(y, x)); min(a, a) = a,
//     a < a = 0, a <= a = 1, x and 0 = 0, x or 1 = 1, if c then a else a = a.
//   * The sign of zero is not kept (-0 is 0, 0*x is 0), and NaN constants are one node.
// Subtraction a - b is a + (-1)*b; division a / b is a * b^-1; sqrt(x) is x^0.5.
//
// Costs the later stages rely on: building a node is O(arity) amortised (O(n log n) for an n-ary
// Add/Mul); diff(e, s) is memoised per (node, symbol) and returns zero in O(1) for a node whose
// symbol mask shows it cannot contain s, so differentiating a sum of N terms is O(N) and repeated
// derivatives share nodes. A DirectionalDerivative (d/dt) is one forward pass per new node, with
// its memo shared by all its calls.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace qdot::sym {

enum class Kind : uint8_t {
#define QDOT_EXPR_KIND(K, A, S) K,
#include "symbolic/ExprKinds.def"
};

/// Printable name of a kind ("sin", "+", ...).
const char* kindSpelling(Kind k);

struct Node;
using Expr = const Node*;

/// One immutable node. Fields used depend on the kind:
///  Constant: value.     Symbol: symbolId (dense, 0-based, in creation order).
///  Add: value = constant term; args = terms; coefs() = their numeric coefficients.
///  Mul: value = numeric coefficient; args = bases, exps() = exponents (Exprs, often constants).
///  every other kind: args in order (Select: cond, then, else).
/// The operands live in the Context's arena right behind the node — args, then a Mul's exponents
/// or an Add's coefficients, one per arg — for as long as the Context; nodes are trivially
/// destructible. 48 bytes: a large model has a few symbols per array element, and every stage
/// writes and reads its nodes (they were 80 bytes with a span each for coefs and exps).
struct Node {
  static constexpr uint32_t kMaxDepth = (1u << 24) - 1;
  Kind kind;
  uint32_t depth : 24 = 0;  ///< longest path to a leaf (leaves 0), saturating at kMaxDepth
  uint32_t symbolId = 0;
  uint64_t hash = 0;
  uint64_t symbolMask = 0;  ///< bit (id % 64) set for every symbol below; 0 => constant expression
  double value = 0;
  std::span<const Expr> args;

  /// Add only (else empty): the coefficient of each term.
  std::span<const double> coefs() const {
    if (kind != Kind::Add) return {};
    return {reinterpret_cast<const double*>(args.data() + args.size()), args.size()};
  }
  /// Mul only (else empty): the exponent of each base.
  std::span<const Expr> exps() const {
    if (kind != Kind::Mul) return {};
    return {args.data() + args.size(), args.size()};
  }

  bool isConstant() const { return kind == Kind::Constant; }
  bool isSymbol() const { return kind == Kind::Symbol; }
  bool isZero() const { return kind == Kind::Constant && value == 0.0; }
  bool isOne() const { return kind == Kind::Constant && value == 1.0; }
};

/// Owns every node, interns them, and remembers symbol names and derivative memos.
/// Not thread-safe. Nodes live as long as the Context.
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  /// Drops every node, symbol and memo: the Context is as new, and every Expr made before is
  /// invalid. For a driver that has lowered everything it needs out of the symbolic form.
  void clear();

  // --- leaves -----------------------------------------------------------------------------
  Expr constant(double v);
  /// constant(v) for each value, in order. For many values at once (a large array's start values):
  /// the intern table is read ahead, so the lookups' cache misses overlap.
  std::vector<Expr> constants(std::span<const double> values);
  Expr zero() const { return zero_; }
  Expr one() const { return one_; }
  /// A new symbol, or the existing one with this name (names are unique per Context).
  Expr symbol(std::string_view name);
  /// symbol(name) for each name, in order (new symbols get their ids in this order). For many names
  /// at once, a large array's: the name table is read ahead, so the lookups' cache misses overlap.
  std::vector<Expr> symbols(std::span<const std::string_view> names);
  /// Lookup without creating; nullptr if none.
  Expr findSymbol(std::string_view name) const;
  /// Room for `symbols` more symbols and `nodes` more other nodes: a caller about to make many (a
  /// large array's variables) spares the tables rehashing as they grow. Never changes any result.
  void reserve(size_t symbols, size_t nodes);
  /// An array's element symbols, `prefix[1]suffix`, `prefix[2]suffix`, … (row-major over shape,
  /// subscripts as `[i,j]`), with consecutive ids: the same symbols as symbols() of those names,
  /// made without the name table (a large array's are found by their family and subscripts). If a
  /// name of the family may exist already (or the suffix holds a bracket), made through symbols().
  std::vector<Expr> symbolArray(std::string_view prefix, std::span<const int> shape, std::string_view suffix = {});
  /// The array symbolArray made that s is an element of: its prefix, suffix and shape, and the
  /// first element's id (s is element s->symbolId - first, row-major); nullopt if none.
  struct SymbolArrayInfo {
    std::string_view prefix, suffix;
    std::span<const int> shape;
    uint32_t first = 0;
  };
  std::optional<SymbolArrayInfo> symbolArrayOf(Expr s) const;
  /// How many of `symbols`, from the first on, are one whole symbolArray in order (its first
  /// element first): the array's size, or 0 if they are not.
  size_t wholeSymbolArrayAt(std::span<const Expr> symbols) const;
  /// For the array whose first element is `first`: the array of the same shape named
  /// `before` + element's name + `after` (der(x[i]) for x[i]), made as one block too.
  std::vector<Expr> symbolArrayAround(Expr first, std::string_view before, std::string_view after);
  std::string_view symbolName(Expr s) const;
  size_t symbolCount() const;

  // --- arithmetic (all simplify to canonical form) -----------------------------------------
  Expr add(Expr a, Expr b);
  Expr add(std::span<const Expr> terms);
  Expr sub(Expr a, Expr b);
  Expr neg(Expr a);
  Expr mul(Expr a, Expr b);
  Expr mul(std::span<const Expr> factors);
  Expr div(Expr a, Expr b);
  Expr pow(Expr base, Expr exponent);
  Expr scale(double c, Expr a);  ///< c * a
  /// Σ coefs[i]·terms[i] built as one sum: add() of the scaled terms, without a product per term.
  Expr linearCombination(std::span<const Expr> terms, std::span<const double> coefs);

  // --- functions ---------------------------------------------------------------------------
  /// Any unary function kind (Sin … Sign, Not). sqrt is pow(x, 0.5); log10(x) is log(x)/log(10).
  Expr unary(Kind k, Expr x);
  /// Atan2, Min, Max, Lt, Le, Eq, Ne, And, Or. (a > b is Lt(b, a); a >= b is Le(b, a).)
  Expr binary(Kind k, Expr a, Expr b);
  Expr select(Expr cond, Expr ifTrue, Expr ifFalse);

  // --- calculus and rewriting ---------------------------------------------------------------
  /// ∂e/∂s for a symbol s. Memoised; derivative rules for every kind live in Derivative.cpp.
  /// abs, sign, min, max, comparisons and select differentiate piecewise (sign(x)*x' etc.).
  Expr diff(Expr e, Expr s);
  /// Replaces symbols by expressions (all at once, not recursively) and re-simplifies.
  /// A key may also be any other node, which is then replaced wherever it occurs as a node.
  Expr substitute(Expr e, const std::unordered_map<Expr, Expr>& map);
  /// The same with the keys' symbol mask given (keyMaskOf(map)): substituting one map into many
  /// expressions then costs nothing per key.
  Expr substitute(Expr e, const std::unordered_map<Expr, Expr>& map, uint64_t keyMask);
  static uint64_t keyMaskOf(const std::unordered_map<Expr, Expr>& map);
  /// The same for symbol keys given as a table by symbol id (null: kept), keyMask that of its
  /// keys: a lookup per node instead of a hash lookup, for a large map applied to many expressions
  /// (a model's aliases).
  Expr substitute(Expr e, std::span<const Expr> bySymbolId, uint64_t keyMask);

  /// True if symbol s occurs in e (exact; uses the mask to answer "no" fast).
  bool dependsOn(Expr e, Expr s) const;
  /// The distinct symbols in e, in order of first occurrence (depth-first, left to right).
  std::vector<Expr> freeSymbols(Expr e) const;
  /// Number of distinct nodes reachable from the roots (the DAG size).
  size_t dagSize(std::span<const Expr> roots) const;

  size_t nodeCount() const;

  // Implementation detail (Context.cpp); public only so the rule files can reach it.
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
  Expr zero_, one_;
};

// --- directional derivative --------------------------------------------------------------------

/// The derivative along a vector field, d/dt = Σ_s rate(s) · ∂/∂s (symbols without a rate have
/// rate 0), computed forward in one pass with the same per-kind rules as Context::diff (which is
/// the field {s -> 1}). The memo lives in the object, so subexpressions shared between calls are
/// differentiated once: a call costs O(nodes of e not yet differentiated), a repeated call O(1).
/// Subtrees whose symbol mask misses every rated symbol are zero in O(1).
class DirectionalDerivative {
 public:
  explicit DirectionalDerivative(Context& ctx);
  ~DirectionalDerivative();
  DirectionalDerivative(DirectionalDerivative&&) noexcept;
  DirectionalDerivative(const DirectionalDerivative&) = delete;
  DirectionalDerivative& operator=(const DirectionalDerivative&) = delete;

  /// Sets the rate of a symbol (any expression of the same Context). Best done before the first
  /// call: changing a rate that earlier results may depend on drops the memo.
  void setRate(Expr symbol, Expr rate);
  /// Rates for symbols without one, asked once per symbol when a derivative first reaches it; the
  /// answer is kept as its rate. Replacing the function keeps the rates (and memo) obtained so far,
  /// so it may capture per-call context such as a source location. If it throws, the symbol stays
  /// unrated and the call is abandoned with the memo still valid. With a function, no subtree can
  /// be skipped by mask, so each call visits every symbol-bearing node it has not seen before.
  void setRateFunction(std::function<Expr(Expr symbol)> rateOf);
  /// d e / dt along the field.
  Expr operator()(Expr e);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// --- partial derivatives for Jacobians -----------------------------------------------------------

/// ∂e/∂s for many expressions e and a fixed list of distinct symbols s (a Jacobian's unknowns), in
/// one sparse forward pass: every node gets, once, the list of listed symbols it contains and its
/// derivative with respect to each, from its children's. Gives the nodes Context::diff gives, but
/// costs O(Σ over nodes of the symbols they contain) instead of visiting, for every symbol, every
/// node that shares its mask bit (with more than 64 symbols the bits alias, and Context::diff then
/// revisits wide sums once per symbol). Keeps its results (not Context::diff's memo).
class PartialDerivatives {
 public:
  PartialDerivatives(Context& ctx, std::span<const Expr> symbols);
  ~PartialDerivatives();
  PartialDerivatives(const PartialDerivatives&) = delete;
  PartialDerivatives& operator=(const PartialDerivatives&) = delete;

  /// Positions (in `symbols`) of the symbols that occur in e, ascending.
  std::span<const uint32_t> symbolsIn(Expr e);
  /// ∂e/∂symbols[k] for every k in symbolsIn(e), in that order (some may be zero: sign(x)).
  /// Both spans stay valid until a call reaches nodes not seen before.
  std::span<const Expr> gradient(Expr e);
  /// ∂e/∂symbols[position] (zero if e does not contain it).
  Expr diff(Expr e, uint32_t position);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// --- evaluation --------------------------------------------------------------------------------

/// Evaluates e with symbol values indexed by symbolId (values.size() >= symbolCount(); precisely,
/// every symbol in e must be covered, else std::invalid_argument). Booleans are 1.0/0.0, any
/// non-zero value is true. Follows IEEE semantics (sqrt(-1) = NaN, log(0) = -inf); sign(0) = 0,
/// min/max are fmin/fmax. Iterative: cost is the DAG size, any depth is fine.
double evaluate(Expr e, std::span<const double> values);

/// base^exponent as constants are folded and expressions evaluated, with exact fast paths (x^1,
/// x^2, x^-1, x^0.5): for a caller that folds numbers itself and must agree bit for bit.
double powValue(double base, double exponent);

/// f(x) for a unary kind (Sin … Sign) as Context::unary folds a constant argument (before the
/// constant's own normalization: −0 → 0, one NaN): for callers that fold numbers themselves.
double unaryValue(Kind k, double x);

/// Evaluates many roots sharing one memo (each node computed once).
void evaluate(std::span<const Expr> roots, std::span<const double> values, std::span<double> out);

/// Compiles roots once into a flat post-order tape (each distinct node one slot) so they can be
/// evaluated repeatedly for different symbol values without re-traversing the DAG. Both branches of
/// a select are computed (IEEE arithmetic never traps, so this is only a cost, never an error).
class Evaluator {
 public:
  explicit Evaluator(std::span<const Expr> roots);
  /// Values indexed by symbolId (must cover every symbol in the roots); out.size() >= roots.size().
  void run(std::span<const double> values, std::span<double> out);
  /// Number of distinct nodes on the tape.
  size_t tapeSize() const { return nodes_.size(); }

 private:
  std::vector<Expr> nodes_;         // post-order
  std::vector<uint32_t> argStart_;  // nodes_.size() + 1 offsets into argSlots_
  std::vector<uint32_t> argSlots_;  // tape slots of each node's children (args then exps)
  std::vector<uint32_t> roots_;     // tape slot of each root
  std::vector<double> slots_;       // scratch values
  uint32_t minValues_ = 0;          // 1 + largest symbolId used
};

// --- ordering ----------------------------------------------------------------------------------

/// The deterministic structural total order used for canonical Add terms and Mul factors (and so
/// for printing): by kind (ExprKinds.def order), then constant value / symbolId (creation order),
/// then depth, then children lexicographically, then coefficients. Never uses pointers. To keep a
/// comparison O(1), nodes that still agree after 12 levels of descent are ordered by their
/// structural hash (a function of kinds, values and symbolIds only, so still run-independent).
/// Returns <0, 0 (same node), >0.
int structuralCompare(Expr a, Expr b);

// --- printing ----------------------------------------------------------------------------------

/// Infix text with minimal parentheses, Modelica-like: `rho*A*l*der(v) + 2*rho*A*g*x`,
/// `x^2`, `-a*b`, `-(a + b)`, `a/(b*c)`, `sqrt(x)`, `sin(th[1])`, `if c then a else b`,
/// comparisons as `<`, `<=`, `==`, `<>`. Numbers in shortest round-trip form. Terms of a sum print
/// in canonical order with a leading minus as ` - `, the constant term last (`x - 1`).
std::string toString(const Context& ctx, Expr e);

/// toString with the terms of the top-level sum (or of the one sum factor of a top-level product,
/// `m*l*(...)`) ordered by group(term), lowest first, canonical order within a group: the equations
/// of motion print mass-matrix terms, then velocity terms, then potential and forces.
std::string toStringGrouped(const Context& ctx, Expr e, const std::function<int(Expr term)>& group);

// --- common-subexpression elimination ----------------------------------------------------------

/// The result of CSE over a set of outputs: temporaries in evaluation order (each value uses only
/// symbols, earlier temporaries and constants) and the outputs rewritten in terms of them.
struct CseResult {
  std::vector<std::pair<Expr, Expr>> temporaries;  ///< (temporary symbol, value)
  std::vector<Expr> outputs;
};

/// A node becomes a temporary when it is non-leaf and used more than once across all outputs.
/// Temporary symbols are named `<prefix>0`, `<prefix>1`, ... in the same Context.
CseResult eliminateCommonSubexpressions(Context& ctx, std::span<const Expr> outputs,
                                        std::string_view prefix = "_t");

}  // namespace qdot::sym
