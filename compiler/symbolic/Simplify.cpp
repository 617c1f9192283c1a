// The simplifier: expression -> polynomial over atoms (functions, symbols, non-integer powers) with
// numeric coefficients -> Pythagorean and angle-sum rewrites -> expression, kept only if shorter.
// Function arguments are simplified first (memoised per node) and given a canonical sign
// (sin(−u) = −sin u, cos(−u) = cos u), so sin(a − b) and sin(b − a) meet as one atom.
// Determinism: monomials are sorted by structuralCompare and terms stay in the order the expansion
// produced them (which follows the canonical order of the input), so every greedy choice is
// independent of addresses; pointer hashing only finds equal monomials.
#include "symbolic/Simplify.h"

#include <algorithm>
#include <set>
#include <unordered_map>
#include <vector>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {
namespace {

struct Factor {
  Expr atom;
  int exp;
  bool operator==(const Factor&) const = default;
};
using Mono = std::vector<Factor>;  // sorted by atom (structuralCompare), exponents non-zero

struct MonoHash {
  size_t operator()(const Mono& m) const {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const Factor& f : m) h = (h ^ f.atom->hash ^ (uint64_t(uint32_t(f.exp)) << 17)) * 0x100000001b3ull;
    return h;
  }
};

bool atomLess(Expr a, Expr b) { return a != b && structuralCompare(a, b) < 0; }

Mono multiplyMonos(const Mono& a, const Mono& b) {
  Mono out;
  out.reserve(a.size() + b.size());
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && atomLess(a[i].atom, b[j].atom))) out.push_back(a[i++]);
    else if (i == a.size() || a[i].atom != b[j].atom) out.push_back(b[j++]);
    else {
      int e = a[i].exp + b[j].exp;
      if (e != 0) out.push_back({a[i].atom, e});
      ++i, ++j;
    }
  }
  return out;
}

struct OverBudget {};

// Monomials a fast call may create besides 8 per input node: the 32-link pendulum's kinetic energy
// (2·Σ i² ≈ 23 000 products of the velocities' terms) fits, the 64-link's (175 000) does not.
constexpr size_t kFastBudget = 40000;

}  // namespace

/// A sum of coefficient·monomial with an index of the monomials (terms keep their insertion order).
/// The index maps a monomial's hash to the first term with it, terms with equal hashes are chained:
/// a monomial is stored once, and adding to an existing term allocates nothing.
struct Poly {
  static constexpr uint32_t kEnd = UINT32_MAX;
  struct Term {
    Mono mono;
    double coef;
    uint32_t next = kEnd;  ///< next term with the same hash
  };
  std::vector<Term> terms;
  std::unordered_map<size_t, uint32_t> index;

  Term* find(const Mono& m, size_t h) {
    auto it = index.find(h);
    for (uint32_t i = it == index.end() ? kEnd : it->second; i != kEnd; i = terms[i].next)
      if (terms[i].mono == m) return &terms[i];
    return nullptr;
  }
  Term* find(const Mono& m) { return find(m, MonoHash{}(m)); }
  template <class M = Mono>
  void add(M&& m, double c) {
    if (c == 0.0) return;
    size_t h = MonoHash{}(m);
    if (Term* t = find(m, h)) {
      t->coef += c;
      return;
    }
    auto [it, fresh] = index.try_emplace(h, static_cast<uint32_t>(terms.size()));
    uint32_t next = fresh ? kEnd : it->second;
    if (!fresh) it->second = static_cast<uint32_t>(terms.size());
    terms.push_back({Mono(std::forward<M>(m)), c, next});
  }
  /// Drops terms whose coefficients cancelled.
  void compact() {
    Poly out;
    out.terms.reserve(terms.size());
    for (Term& t : terms)
      if (t.coef != 0.0) out.add(std::move(t.mono), t.coef);
    *this = std::move(out);
  }
  static Poly constant(double c) {
    Poly p;
    p.add({}, c);
    return p;
  }
  static Poly atom(Expr a, int exp = 1) {
    Poly p;
    p.add({{a, exp}}, 1.0);
    return p;
  }
};

struct Simplifier::Impl {
  Impl(Context& c, SimplifyLevel l) : ctx(c), level(l) {}

  Context& ctx;
  SimplifyLevel level;
  size_t work = 0, budget = 0;
  bool gaveUp = false;  ///< the last call ran out of budget
  NodeMap<Expr> memo;       ///< node -> simplifyExpr's result (subexpressions, function arguments)
  NodeMap<Expr> functions;  ///< function node -> its canonical form as an atom of a polynomial

  static constexpr uint32_t kMaxDepth = 200;  // deeper inputs are left alone (no deep recursion)

  void spend(size_t n) {
    work += n;
    if (work > budget) throw OverBudget{};
  }

  // --- polynomial arithmetic ---------------------------------------------------------------------
  void addScaled(Poly& dst, const Poly& src, double k) {
    spend(src.terms.size());
    for (const auto& t : src.terms) dst.add(t.mono, k * t.coef);
  }
  Poly multiply(const Poly& a, const Poly& b) {
    spend(a.terms.size() * b.terms.size());
    Poly out;
    for (const auto& x : a.terms)
      for (const auto& y : b.terms) out.add(multiplyMonos(x.mono, y.mono), x.coef * y.coef);
    return out;
  }
  Poly power(const Poly& p, int n) {
    Poly r = p;
    for (int i = 1; i < n; ++i) r = multiply(r, p);
    return r;
  }

  // --- expression -> polynomial ----------------------------------------------------------------------
  Poly expand(Expr e) {
    switch (e->kind) {
      case Kind::Constant: return Poly::constant(e->value);
      case Kind::Symbol: return Poly::atom(e);
      case Kind::Add: {
        Poly p = Poly::constant(e->value);
        for (size_t i = 0; i < e->args.size(); ++i) addScaled(p, expand(e->args[i]), e->coefs()[i]);
        return p;
      }
      case Kind::Mul: {
        Poly p = Poly::constant(e->value);
        for (size_t i = 0; i < e->args.size(); ++i) p = multiply(p, expandPower(e->args[i], e->exps()[i]));
        return p;
      }
      case Kind::Pow: return expandPower(e->args[0], e->args[1]);
      default: return expand(simplifyFunction(e), e);
    }
  }
  // A simplified function node (an atom) or what it simplified to.
  Poly expand(Expr simplified, Expr original) {
    if (simplified == original || isAtom(simplified)) return Poly::atom(simplified);
    return expand(simplified);
  }
  static bool isAtom(Expr e) {
    return e->kind != Kind::Constant && e->kind != Kind::Add && e->kind != Kind::Mul && e->kind != Kind::Pow;
  }

  Poly expandPower(Expr base, Expr exponent) {
    bool integer = exponent->isConstant() && isIntegerValue(exponent->value) && std::abs(exponent->value) < 64;
    if (!integer) return Poly::atom(simplifyPower(base, exponent));
    int n = static_cast<int>(exponent->value);
    Poly b = expand(base);
    if (n > 0) return power(b, n);
    if (b.terms.size() == 1) {  // a monomial: invert it
      Poly::Term t = b.terms[0];
      for (Factor& f : t.mono) f.exp *= n;
      Poly p;
      p.add(std::move(t.mono), powValue(t.coef, n));
      return p;
    }
    return Poly::atom(toExpr(b), n);  // 1/(sum) stays a power of the simplified sum
  }

  // sqrt(u²) = |u|; other non-integer powers over simplified operands.
  Expr simplifyPower(Expr base, Expr exponent) {
    Expr b = simplifyExpr(base), x = simplifyExpr(exponent);
    if (x->isConstant() && x->value == 0.5 && b->kind == Kind::Pow && b->args[1]->isConstant() && b->args[1]->value == 2.0)
      return ctx.unary(Kind::Abs, b->args[0]);
    return ctx.pow(b, x);
  }

  // --- functions: simplified arguments, canonical sign, inverse pairs ---------------------------
  static bool isOdd(Kind k) {
    return k == Kind::Sin || k == Kind::Tan || k == Kind::Asin || k == Kind::Atan || k == Kind::Sinh || k == Kind::Tanh;
  }
  static bool isEven(Kind k) { return k == Kind::Cos || k == Kind::Cosh || k == Kind::Abs; }
  // Of u and −u exactly one is "negative": the one whose first term (or coefficient) is negative.
  static bool negative(Expr u) {
    if (u->kind == Kind::Mul) return u->value < 0;
    if (u->kind == Kind::Add) return u->coefs()[0] < 0;
    return false;
  }
  Expr negate(Expr u) {
    AddBuilder s(ctx);
    s.add(-1.0, u);
    return s.build();
  }

  Expr simplifyFunction(Expr f) {
    if (Expr* known = functions.find(f)) return *known;
    Expr r = rewriteFunction(f);
    functions.insert(f, r);
    if (r != f && isAtom(r) && !functions.find(r)) functions.insert(r, r);
    return r;
  }
  Expr rewriteFunction(Expr f) {
    Kind k = f->kind;
    if (kindArity(k) != 1) {
      SmallVec<Expr, 4> kids;
      for (Expr c : children(f)) kids.push_back(simplifyExpr(c));
      return ctx.impl().rebuild(f, std::span<const Expr>(kids.data(), kids.size()));
    }
    Expr u = simplifyExpr(f->args[0]);
    if (k == Kind::Exp && u->kind == Kind::Log) return u->args[0];  // exp(log u) = u where log u is defined
    if (k == Kind::Log && u->kind == Kind::Exp) return u->args[0];
    if ((isOdd(k) || isEven(k)) && negative(u)) {
      Expr g = ctx.unary(k, negate(u));
      return isOdd(k) ? ctx.neg(g) : g;
    }
    return ctx.unary(k, u);
  }

  // --- polynomial -> expression ------------------------------------------------------------------
  Expr monoExpr(const Mono& m, double coef) {
    MulBuilder b(ctx, coef);
    for (const Factor& f : m) b.power(f.atom, ctx.constant(f.exp));
    return b.build();
  }
  Expr toExpr(const Poly& p) {
    AddBuilder s(ctx);
    for (const auto& t : p.terms)
      if (t.coef != 0.0) s.add(1.0, monoExpr(t.mono, t.coef));
    return s.build();
  }
  // The factors every term has (positive powers only, the least exponent), taken out of the sum.
  Expr factoredExpr(const Poly& p) {
    if (p.terms.size() < 2) return nullptr;
    Mono common = p.terms[0].mono;
    for (const auto& t : p.terms) {
      Mono kept;
      for (const Factor& c : common) {
        auto at = std::find_if(t.mono.begin(), t.mono.end(), [&](const Factor& f) { return f.atom == c.atom; });
        if (at != t.mono.end() && at->exp > 0 && c.exp > 0) kept.push_back({c.atom, std::min(c.exp, at->exp)});
      }
      common = std::move(kept);
      if (common.empty()) return nullptr;
    }
    Mono inverse = common;
    for (Factor& f : inverse) f.exp = -f.exp;
    AddBuilder s(ctx);
    for (const auto& t : p.terms) s.add(1.0, monoExpr(multiplyMonos(t.mono, inverse), t.coef));
    return ctx.mul(monoExpr(common, 1.0), s.build());
  }

  // --- the trigonometric rewrites --------------------------------------------------------------------
  // For each argument u of a squared sin/cos (sinh/cosh), the cheapest of: as is, cos² → 1 − sin²,
  // sin² → 1 − cos² (cosh² → 1 + sinh², sinh² → cosh² − 1). Never raises the cost (termCost summed).
  // A rewrite touches only the terms with the square and the terms its products fall on, so it is
  // weighed and made on those (TermList) rather than by building the polynomial again: with n
  // arguments (n coupled pendulums) that was O(n²) — 88 s at n = 4 000. The terms, their order and
  // their coefficients (summed in the same order) are those that rebuilding gave.
  Poly pythagorean(Poly p) {
    std::vector<Expr> squared;  // Sin/Cos/Sinh/Cosh atoms with exponent >= 2, by first appearance
    for (const auto& t : p.terms)
      for (const Factor& f : t.mono)
        if (f.exp >= 2 && isCircularOrHyperbolic(f.atom->kind)) squared.push_back(f.atom);
    if (squared.empty()) return p;
    TermList list(p);
    std::set<std::pair<Expr, bool>> done;  // (argument, hyperbolic)
    for (Expr a : squared) {
      bool hyperbolic = a->kind == Kind::Sinh || a->kind == Kind::Cosh;
      if (!done.insert({a->args[0], hyperbolic}).second) continue;
      Expr u = a->args[0];
      Expr s = ctx.unary(hyperbolic ? Kind::Sinh : Kind::Sin, u), c = ctx.unary(hyperbolic ? Kind::Cosh : Kind::Cos, u);
      // c² = 1 − s² (circular) or 1 + s² (hyperbolic); s² = 1 − c² or c² − 1.
      Rewrite viaSin = weighSquare(list, c, s, 1.0, hyperbolic ? 1.0 : -1.0);
      Rewrite viaCos = weighSquare(list, s, c, hyperbolic ? -1.0 : 1.0, hyperbolic ? 1.0 : -1.0);
      size_t now = list.cost, a1 = viaSin.cost, a2 = viaCos.cost;
      if (a1 < now && a1 <= a2) list.apply(viaSin);
      else if (a2 < now) list.apply(viaCos);
    }
    return list.changed ? list.materialize() : std::move(p);
  }
  static bool isCircularOrHyperbolic(Kind k) { return k == Kind::Sin || k == Kind::Cos || k == Kind::Sinh || k == Kind::Cosh; }
  static size_t termCost(const Mono& m, double coef) {
    if (coef == 0.0) return 0;
    size_t c = 1 + (std::abs(coef) != 1.0);
    for (const Factor& f : m) c += 1 + (f.exp != 1);
    return c;
  }
  static int exponentOf(const Mono& m, Expr atom) {
    for (const Factor& f : m)
      if (f.atom == atom) return f.exp;
    return 0;
  }

  // One rewrite from^k → from^(k mod 2) · (constant + sign·to²)^(k/2), weighed but not yet made: the
  // terms it replaces (`affected`, in term order), each monomial its products fall on (`touched`,
  // by first appearance) with its coefficient after the rewrite, and the polynomial's cost after it.
  struct Rewrite {
    struct Touch {
      Mono mono;
      uint32_t existing = Poly::kEnd;  ///< the live term with this monomial, if any
      double coef = 0.0;               ///< after the rewrite
    };
    std::vector<uint32_t> affected;
    std::vector<std::vector<uint32_t>> products;  ///< per affected term: its touches, in its product's order
    std::vector<Touch> touched;
    size_t cost = 0;
  };

  // The polynomial as a doubly linked list in term order. Ranks (with gaps, renumbered when a gap
  // closes) compare positions; `squares` finds the terms holding an atom squared.
  struct TermList {
    explicit TermList(Poly& poly) : p(poly) {
      size_t n = p.terms.size();
      prev.resize(n), next.resize(n), rank.resize(n);
      for (uint32_t i = 0; i < n; ++i) {
        prev[i] = i == 0 ? Poly::kEnd : i - 1;
        next[i] = i + 1 == n ? Poly::kEnd : i + 1;
        rank[i] = uint64_t{i + 1} << kGapBits;
        cost += termCost(p.terms[i].mono, p.terms[i].coef);
        enter(i);
      }
      head = n == 0 ? Poly::kEnd : 0;
    }
    static constexpr int kGapBits = 20;
    Poly& p;
    std::vector<uint32_t> prev, next;
    std::vector<uint64_t> rank;
    uint32_t head = Poly::kEnd;
    std::unordered_map<Expr, std::vector<uint32_t>> squares;
    std::vector<bool> entered;
    size_t cost = 0;
    bool changed = false;

    bool live(uint32_t t) const { return p.terms[t].coef != 0.0; }
    void enter(uint32_t t) {  // into `squares`, once per term (a revived term is already there)
      if (entered.size() <= t) entered.resize(t + 1, false);
      if (entered[t]) return;
      entered[t] = true;
      for (const Factor& f : p.terms[t].mono)
        if (f.exp >= 2 && isCircularOrHyperbolic(f.atom->kind)) squares[f.atom].push_back(t);
    }
    void unlink(uint32_t t) {
      (prev[t] == Poly::kEnd ? head : next[prev[t]]) = next[t];
      if (next[t] != Poly::kEnd) prev[next[t]] = prev[t];
    }
    void renumber() {
      uint64_t r = 0;
      for (uint32_t t = head; t != Poly::kEnd; t = next[t]) rank[t] = (r += uint64_t{1} << kGapBits);
    }
    void insertAfter(uint32_t at, uint32_t t) {
      auto gap = [&] { return next[at] == Poly::kEnd ? uint64_t{2} << kGapBits : rank[next[at]] - rank[at]; };
      if (gap() < 2) renumber();
      rank[t] = rank[at] + gap() / 2;
      prev[t] = at, next[t] = next[at];
      if (next[at] != Poly::kEnd) prev[next[at]] = t;
      next[at] = t;
    }
    // Each touched monomial takes its place where it first appeared (an existing term after that
    // moves up to it), the affected terms leave, and what cancelled to zero goes.
    void apply(const Rewrite& w) {
      changed = true;
      std::vector<bool> placed(w.touched.size(), false);
      for (size_t i = 0; i < w.affected.size(); ++i) {
        uint32_t cursor = w.affected[i];
        for (uint32_t k : w.products[i]) {
          const Rewrite::Touch& touch = w.touched[k];
          if (placed[k]) continue;
          placed[k] = true;
          if (touch.coef == 0.0) continue;
          uint32_t t = touch.existing;
          if (t != Poly::kEnd && rank[t] < rank[w.affected[i]]) continue;  // stays where it is
          if (t == Poly::kEnd) t = add(touch.mono);
          else unlink(t);
          insertAfter(cursor, t);
          cursor = t;
        }
        unlink(w.affected[i]);
        p.terms[w.affected[i]].coef = 0.0;
      }
      for (const Rewrite::Touch& touch : w.touched) {
        if (touch.existing != Poly::kEnd && touch.coef == 0.0) unlink(touch.existing);
        Poly::Term* t = p.find(touch.mono);
        if (t) t->coef = touch.coef;
      }
      cost = w.cost;
    }
    uint32_t add(const Mono& m) {  // a new term (or a dead one revived) with coefficient 0 for now
      Poly::Term* t = p.find(m);
      if (!t) {
        p.add(m, 1.0);
        t = p.find(m);
      }
      uint32_t id = static_cast<uint32_t>(t - p.terms.data());
      if (prev.size() <= id) prev.resize(id + 1), next.resize(id + 1), rank.resize(id + 1);
      enter(id);
      return id;
    }
    Poly materialize() {
      Poly out;
      for (uint32_t t = head; t != Poly::kEnd; t = next[t]) out.add(std::move(p.terms[t].mono), p.terms[t].coef);
      return out;
    }
  };

  // Weighs rewriting every from^k (k >= 2) as from^(k mod 2) · (constant + sign·to²)^(k/2): the
  // products of the affected terms in term order, each product's terms in its order, added to what
  // is there in the order a rebuild would have added them (an existing term at its own place).
  Rewrite weighSquare(TermList& list, Expr from, Expr to, double constant, double sign) {
    Rewrite w;
    w.cost = list.cost;
    if (auto it = list.squares.find(from); it != list.squares.end())
      for (uint32_t t : it->second)
        if (list.live(t) && exponentOf(list.p.terms[t].mono, from) >= 2) w.affected.push_back(t);
    if (w.affected.empty()) return w;
    std::sort(w.affected.begin(), w.affected.end(), [&](uint32_t a, uint32_t b) { return list.rank[a] < list.rank[b]; });
    Poly square;
    square.add({}, constant);
    square.add({{to, 2}}, sign);
    struct Part {
      uint64_t rank;
      double coef;
    };
    std::vector<std::vector<Part>> parts;
    std::unordered_map<Mono, uint32_t, MonoHash> touchOf;
    for (uint32_t a : w.affected) {
      const Poly::Term& t = list.p.terms[a];
      w.cost -= termCost(t.mono, t.coef);
      int k = exponentOf(t.mono, from);
      Mono rest;
      for (const Factor& f : t.mono)
        if (f.atom != from) rest.push_back(f);
      if (k % 2) rest = multiplyMonos(rest, {{from, 1}});
      Poly term;
      term.add(std::move(rest), t.coef);
      Poly product = multiply(term, power(square, k / 2));
      spend(product.terms.size());
      auto& mine = w.products.emplace_back();
      for (const auto& r : product.terms) {
        if (1.0 * r.coef == 0.0) continue;
        auto [at, fresh] = touchOf.try_emplace(r.mono, static_cast<uint32_t>(w.touched.size()));
        if (fresh) {
          w.touched.push_back({r.mono});
          parts.emplace_back();
        }
        parts[at->second].push_back({list.rank[a], 1.0 * r.coef});
        mine.push_back(at->second);
      }
    }
    for (size_t k = 0; k < w.touched.size(); ++k) {
      Rewrite::Touch& touch = w.touched[k];
      const Poly::Term* old = list.p.find(touch.mono);
      if (old && old->coef != 0.0) touch.existing = static_cast<uint32_t>(old - list.p.terms.data());
      uint64_t own = touch.existing == Poly::kEnd ? UINT64_MAX : list.rank[touch.existing];
      bool first = true, ownAdded = touch.existing == Poly::kEnd;
      auto addPart = [&](double c) {
        touch.coef = first ? c : touch.coef + c;
        first = false;
      };
      for (const Part& part : parts[k]) {
        if (!ownAdded && own < part.rank) addPart(old->coef), ownAdded = true;
        addPart(part.coef);
      }
      if (!ownAdded) addPart(old->coef);
      if (touch.existing != Poly::kEnd) w.cost -= termCost(old->mono, old->coef);
      w.cost += termCost(touch.mono, touch.coef);
    }
    return w;
  }


  // sin a cos b ± cos a sin b = sin(a ± b), cos a cos b ∓ sin a sin b = cos(a ± b): pairs of terms
  // with the same rest and coefficients equal up to sign become one term.
  Poly contractAngles(Poly p) {
    std::vector<Expr> replacements;
    for (size_t ti = 0; ti < p.terms.size(); ++ti) {
      const Mono& m = p.terms[ti].mono;
      for (size_t i = 0; i < m.size() && p.terms[ti].coef != 0.0; ++i)
        for (size_t j = i + 1; j < m.size() && p.terms[ti].coef != 0.0; ++j)
          if (Expr r = contractPair(p, ti, i, j)) replacements.push_back(r);
    }
    if (replacements.empty()) return p;
    for (Expr r : replacements) addScaled(p, expand(r), 1.0);
    p.compact();
    return p;
  }
  static bool isSinCos(const Factor& f) { return f.exp == 1 && (f.atom->kind == Kind::Sin || f.atom->kind == Kind::Cos); }
  static Kind other(Kind k) { return k == Kind::Sin ? Kind::Cos : Kind::Sin; }

  Expr contractPair(Poly& p, size_t ti, size_t i, size_t j) {
    const Mono& m = p.terms[ti].mono;
    if (!isSinCos(m[i]) || !isSinCos(m[j]) || m[i].atom->args[0] == m[j].atom->args[0]) return nullptr;
    Kind ki = m[i].atom->kind, kj = m[j].atom->kind;
    Expr a = m[i].atom->args[0], b = m[j].atom->args[0];
    Mono rest;
    for (size_t k = 0; k < m.size(); ++k)
      if (k != i && k != j) rest.push_back(m[k]);
    Mono partnerMono = multiplyMonos(rest, sortedPair(ctx.unary(other(ki), a), ctx.unary(other(kj), b)));
    Poly::Term* found = p.find(partnerMono);
    if (!found) return nullptr;
    Poly::Term& partner = *found;
    double c = p.terms[ti].coef, d = partner.coef;
    if (d != c && d != -c) return nullptr;
    bool same = d == c;
    Expr angle;
    double k = c;
    Kind result;
    if (ki == Kind::Cos && kj == Kind::Cos) result = Kind::Cos, angle = same ? ctx.sub(a, b) : ctx.add(a, b);
    else if (ki == Kind::Sin && kj == Kind::Sin) result = Kind::Cos, angle = same ? ctx.sub(a, b) : ctx.add(a, b), k = d;
    else if (ki == Kind::Sin) result = Kind::Sin, angle = same ? ctx.add(a, b) : ctx.sub(a, b);
    else result = Kind::Sin, angle = same ? ctx.add(a, b) : ctx.sub(b, a);
    Expr r = ctx.mul(monoExpr(rest, k), ctx.unary(result, angle));
    p.terms[ti].coef = 0.0;
    partner.coef = 0.0;
    return r;
  }
  static Mono sortedPair(Expr x, Expr y) {
    return atomLess(x, y) ? Mono{{x, 1}, {y, 1}} : Mono{{y, 1}, {x, 1}};
  }

  // --- one expression ------------------------------------------------------------------------------
  Expr simplifyExpr(Expr e) {
    if (e->kind == Kind::Constant || e->kind == Kind::Symbol) return e;
    if (Expr* known = memo.find(e)) return *known;
    if (e->depth > kMaxDepth) return e;
    Expr r;
    if (isAtom(e)) {
      r = simplifyFunction(e);
      if (expressionCost(r) > expressionCost(e)) r = e;  // −sin(u) for sin(−u) is no shorter
    } else {
      Poly p = expand(e);
      p.compact();
      p = contractAngles(pythagorean(std::move(p)));
      r = toExpr(p);
      size_t cost = expressionCost(r);
      if (Expr f = factoredExpr(p)) {
        size_t factored = expressionCost(f);
        if (factored < cost) r = f, cost = factored;
      }
      if (cost >= expressionCost(e)) r = e;
    }
    memo.insert(e, r);
    return r;
  }
};

bool parseSimplifyLevel(std::string_view text, SimplifyLevel& level) {
  if (text == "none") level = SimplifyLevel::None;
  else if (text == "fast") level = SimplifyLevel::Fast;
  else if (text == "full") level = SimplifyLevel::Full;
  else return false;
  return true;
}

Simplifier::Simplifier(Context& ctx, SimplifyLevel level) : impl_(std::make_unique<Impl>(ctx, level)) {}
Simplifier::~Simplifier() = default;
size_t Simplifier::work() const { return impl_->work; }
bool Simplifier::gaveUp() const { return impl_->gaveUp; }

Expr Simplifier::operator()(Expr e) {
  Impl& s = *impl_;
  if (s.level == SimplifyLevel::None || e->kind == Kind::Constant || e->kind == Kind::Symbol) return e;
  size_t size = s.ctx.dagSize({&e, 1});
  s.budget = s.work + (s.level == SimplifyLevel::Full ? 1000000 + 64 * size : kFastBudget + 8 * size);
  s.gaveUp = false;
  try {
    return s.simplifyExpr(e);
  } catch (const OverBudget&) {
    s.gaveUp = true;
    return e;
  }
}

Expr simplify(Context& ctx, Expr e, SimplifyLevel level) { return Simplifier(ctx, level)(e); }

namespace {

// Whether u is a ± b of two symbols (coefficients ±1, no constant).
bool isSymbolPair(Expr u) {
  return u->kind == Kind::Add && u->value == 0.0 && u->args.size() == 2 && u->args[0]->isSymbol() &&
         u->args[1]->isSymbol() && std::abs(u->coefs()[0]) == 1.0 && std::abs(u->coefs()[1]) == 1.0;
}

// sin/cos(k0 a + k1 b) with k = ±1, from sin(k a) = k sin a and cos(k a) = cos a.
Expr expandedAngle(Context& ctx, Expr f) {
  Expr u = f->args[0], a = u->args[0], b = u->args[1];
  double ka = u->coefs()[0], kb = u->coefs()[1];
  Expr sa = ctx.scale(ka, ctx.unary(Kind::Sin, a)), ca = ctx.unary(Kind::Cos, a);
  Expr sb = ctx.scale(kb, ctx.unary(Kind::Sin, b)), cb = ctx.unary(Kind::Cos, b);
  if (f->kind == Kind::Sin) return ctx.add(ctx.mul(sa, cb), ctx.mul(ca, sb));
  return ctx.sub(ctx.mul(ca, cb), ctx.mul(sa, sb));
}

}  // namespace

std::vector<Expr> expandAngleDifferences(Context& ctx, std::span<const Expr> roots) {
  std::unordered_map<Expr, Expr> map;
  PostOrder po = postOrder(roots);
  for (Expr n : po.order)
    if ((n->kind == Kind::Sin || n->kind == Kind::Cos) && isSymbolPair(n->args[0])) map.emplace(n, expandedAngle(ctx, n));
  std::vector<Expr> out(roots.begin(), roots.end());
  if (map.empty()) return out;
  uint64_t mask = Context::keyMaskOf(map);
  for (Expr& e : out) e = ctx.substitute(e, map, mask);
  return out;
}

bool worthSimplifying(Expr e, SimplifyLevel level) {
  if (level != SimplifyLevel::Fast) return level == SimplifyLevel::Full;
  NodeSet seen;
  SmallVec<Expr, 32> stack;
  stack.push_back(e);
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    if (!n->symbolMask || !seen.insert(n)) continue;
    switch (n->kind) {
      case Kind::Sin: case Kind::Cos: case Kind::Tan: case Kind::Sinh: case Kind::Cosh: case Kind::Tanh:
      case Kind::Exp: case Kind::Log: return true;
      case Kind::Pow:
        if (!n->args[1]->isConstant() || !isIntegerValue(n->args[1]->value)) return true;
        break;
      case Kind::Mul:
        for (Expr x : n->exps())
          if (!x->isConstant() || !isIntegerValue(x->value)) return true;
        break;
      default: break;
    }
    for (Expr c : children(n)) stack.push_back(c);
  }
  return false;
}

size_t expressionCost(Expr e) {
  NodeMap<size_t> cost;
  constexpr size_t kCap = size_t{1} << 40;
  PostOrder po = postOrder({&e, 1});
  for (Expr n : po.order) {
    size_t c = 1;
    for (Expr k : children(n)) c += *cost.find(k);
    if (n->kind == Kind::Add) c += n->value != 0.0;
    if (n->kind == Kind::Add)
      for (double k : n->coefs()) c += std::abs(k) != 1.0;
    if (n->kind == Kind::Mul) {
      c += std::abs(n->value) != 1.0;
      for (Expr x : n->exps()) c -= x->isOne();  // x^1 prints as x
    }
    cost.insert(n, std::min(c, kCap));
  }
  return *cost.find(e);
}

}  // namespace qdot::sym
