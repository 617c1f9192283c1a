// Energy terms that repeat along arrays of components made sums again (issue 15, docs/loops.md
// "Arrays of components"). An array of components is flattened instance by instance: `Mass
// ms[n]` gives n kinetic terms `0.5*ms[i].m*der(ms[i].s)^2`, one per instance, in instance order.
// Variables named alike but for one subscript (`ms[1].s`, `ms[2].s`, …, numbered 1..N) form a
// family, which becomes an array (`ms.s`); a run of consecutive terms of one statement that are the
// same expression but for every family member's subscript, shifted by one from term to term, becomes
// one IndexedSum over its relative symbols (`0.5*ms.m[%1]*der(ms.s)[%1]^2` for %1 in 1..n) — what
// `sum(… for i in 1:n)` over declared arrays gives, so the stages after flattening keep it as a
// template. Parameter families a sum reads are renumbered to consecutive variables (the loops read
// them as p[first + i]).
#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "flatten/Flatten.h"

namespace qdot::flat {

using sym::Expr;

namespace {

/// A name with exactly one subscript that is a number (`ms[12].s`, `der(x[3])`, `links[2].s0`): the
/// name without it (`ms.s`, `der(x)`, `links.s0`) — the family — and the number.
std::optional<std::pair<std::string, long>> familyOf(std::string_view name) {
  std::optional<std::pair<size_t, size_t>> subscript;  // [open, close]
  for (size_t open = name.find('['); open != std::string_view::npos; open = name.find('[', open + 1)) {
    size_t close = name.find_first_not_of("0123456789", open + 1);
    if (close == std::string_view::npos || close == open + 1 || name[close] != ']') continue;
    if (subscript || close - open > 10) return std::nullopt;
    subscript = {open, close};
  }
  if (!subscript) return std::nullopt;
  long number = 0;
  for (size_t k = subscript->first + 1; k < subscript->second; ++k) number = number * 10 + (name[k] - '0');
  std::string family(name.substr(0, subscript->first));
  family += name.substr(subscript->second + 1);
  return std::pair{std::move(family), number};
}

class Reroller {
 public:
  Reroller(FlatModel& m, sym::Context& ctx, size_t minimumRun) : m_(m), ctx_(ctx), minimumRun_(std::max<size_t>(minimumRun, 2)) {}

  size_t run() {
    findFamilies();
    if (families_.empty()) return 0;
    size_t made = 0;
    made += reroll(m_.kinetic, IndexedSum::Energy::Kinetic);
    made += reroll(m_.potential, IndexedSum::Energy::Potential);
    made += reroll(m_.dissipation, IndexedSum::Energy::Dissipation);
    if (made) groupParameters();
    return made;
  }

 private:
  struct Family {
    std::string name;
    std::vector<int> members;  ///< by number - 1: the variable
    int array = -1;            ///< in m_.patterns->arrays, once a sum reads it
  };
  struct Member {
    int family = -1;
    long number = 0;
  };

  FlatModel& m_;
  sym::Context& ctx_;
  size_t minimumRun_;
  std::vector<Family> families_;
  std::vector<Member> memberOf_;  // by variable

  // Families numbered 1..N without a gap or a repeat; the others are not arrays.
  void findFamilies() {
    std::unordered_map<std::string, int> byName;
    std::vector<std::vector<std::pair<long, int>>> numbers;
    memberOf_.assign(m_.variables.size(), {});
    for (size_t v = 1; v < m_.variables.size(); ++v) {
      auto f = familyOf(m_.variables[v].name);
      if (!f) continue;
      auto [it, fresh] = byName.try_emplace(f->first, static_cast<int>(families_.size()));
      if (fresh) families_.push_back({f->first, {}}), numbers.emplace_back();
      numbers[it->second].push_back({f->second, static_cast<int>(v)});
    }
    for (size_t f = 0; f < families_.size(); ++f) {
      auto& list = numbers[f];
      std::sort(list.begin(), list.end());
      bool dense = true;
      for (size_t k = 0; k < list.size(); ++k) dense = dense && list[k].first == static_cast<long>(k) + 1;
      if (!dense || list.size() < minimumRun_) continue;
      for (auto [number, v] : list) families_[f].members.push_back(v), memberOf_[v] = {static_cast<int>(f), number};
    }
  }

  const Member* member(Expr s) const {
    int v = m_.variableOf(s);
    return v >= 0 && memberOf_[v].family >= 0 && !families_[memberOf_[v].family].members.empty() ? &memberOf_[v] : nullptr;
  }

  // The number of the first family member in e (depth first), or 0: where the term is.
  long anchorOf(Expr e) const {
    if (e->isSymbol()) return member(e) ? member(e)->number : 0;
    for (Expr a : e->args)
      if (long n = anchorOf(a)) return n;
    for (Expr a : e->exps())
      if (long n = anchorOf(a)) return n;
    return 0;
  }

  // Whether a at anchor p is b at anchor q: the same expression but for every family member's
  // number, which differs by q - p.
  bool sameShape(Expr a, long p, Expr b, long q) const {
    if (a == b && p == q) return true;
    if (a->kind != b->kind || a->value != b->value || a->args.size() != b->args.size() || a->exps().size() != b->exps().size())
      return false;
    if (a->isSymbol()) {
      const Member* ma = member(a);
      const Member* mb = member(b);
      if (!ma || !mb) return a == b;
      return ma->family == mb->family && ma->number - p == mb->number - q;
    }
    if (a->isConstant()) return true;
    if (!std::equal(a->coefs().begin(), a->coefs().end(), b->coefs().begin(), b->coefs().end())) return false;
    for (size_t k = 0; k < a->args.size(); ++k)
      if (!sameShape(a->args[k], p, b->args[k], q)) return false;
    for (size_t k = 0; k < a->exps().size(); ++k)
      if (!sameShape(a->exps()[k], p, b->exps()[k], q)) return false;
    return true;
  }

  // Terms of one statement, consecutive, each the one before shifted by one: runs of at least
  // minimumRun_ become sums, the other terms stay.
  size_t reroll(std::vector<Term>& terms, IndexedSum::Energy energy) {
    constexpr uint32_t kDeepest = 256;  // deeper terms stay as they are (no recursion that deep)
    std::vector<Term> out;
    size_t made = 0;
    for (size_t k = 0; k < terms.size();) {
      long anchor = terms[k].value->depth <= kDeepest ? anchorOf(terms[k].value) : 0;
      size_t end = k + 1;
      while (anchor && end < terms.size() && terms[end].range == terms[k].range && terms[end].value->depth <= kDeepest &&
             anchorOf(terms[end].value) == anchor + static_cast<long>(end - k) &&
             sameShape(terms[k].value, anchor, terms[end].value, anchor + static_cast<long>(end - k)))
        ++end;
      if (end - k < minimumRun_) {
        out.push_back(terms[k++]);
        continue;
      }
      IndexedSum sum{energy, static_cast<int>(out.size()), {{anchor, anchor + static_cast<long>(end - k) - 1}},
                     template_(terms[k].value, anchor), terms[k].range};
      out.push_back({ctx_.zero(), terms[k].range});
      m_.indexedSums.push_back(std::move(sum));
      ++made;
      k = end;
    }
    terms = std::move(out);
    return made;
  }

  // The term at `anchor` with every family member an element of its family's array, subscripted
  // by the iterator plus the member's offset from the anchor.
  Expr template_(Expr term, long anchor) {
    std::unordered_map<Expr, Expr> map;
    for (Expr s : ctx_.freeSymbols(term))
      if (const Member* mb = member(s)) {
        RelativeElement rel{arrayOf(mb->family), {{0, static_cast<int>(mb->number - anchor)}}};
        map.emplace(s, m_.patterns->symbol(ctx_, rel));
      }
    return ctx_.substitute(term, map);
  }

  // The array of a family, made on first use. A family of velocities is its coordinates' family's
  // derivative array (a template's rates are taken along it), and so on.
  int arrayOf(int family) {
    Family& f = families_[family];
    if (f.array >= 0) return f.array;
    ArrayVariable a{f.name, {static_cast<int>(f.members.size())}, {}};
    for (int v : f.members) a.elements.push_back(m_.variables[v].symbol);
    m_.patterns->arrays.push_back(std::move(a));
    f.array = static_cast<int>(m_.patterns->arrays.size()) - 1;
    int of = m_.variables[f.members[0]].derivativeOf;
    if (of >= 0 && memberOf_[of].family >= 0) {
      int base = arrayOf(memberOf_[of].family);
      const Family& g = families_[memberOf_[of].family];
      bool aligned = g.members.size() == f.members.size();
      for (size_t k = 0; aligned && k < f.members.size(); ++k) aligned = m_.variables[g.members[k]].derivative == f.members[k];
      if (aligned) m_.patterns->arrays[base].derivative = families_[family].array;
    }
    return families_[family].array;
  }

  // Every family of parameters a sum reads, as consecutive variables in the order of their numbers
  // (the first member's place), the other variables in their order.
  void groupParameters() {
    std::vector<int> order;
    order.reserve(m_.variables.size());
    std::vector<char> placed(m_.variables.size(), 0);
    for (size_t v = 0; v < m_.variables.size(); ++v) {
      if (placed[v]) continue;
      const Member& mb = memberOf_[v];
      bool grouped = mb.family >= 0 && families_[mb.family].array >= 0 && m_.variables[v].role == VarRole::Parameter;
      if (!grouped) {
        order.push_back(static_cast<int>(v)), placed[v] = 1;
        continue;
      }
      for (int w : families_[mb.family].members) order.push_back(w), placed[w] = 1;
    }
    std::vector<int> newIndex(order.size());
    for (size_t k = 0; k < order.size(); ++k) newIndex[order[k]] = static_cast<int>(k);
    renumberVariables(m_, newIndex);
  }
};

}  // namespace

size_t rerollTerms(FlatModel& model, sym::Context& ctx, size_t minimumRun) { return Reroller(model, ctx, minimumRun).run(); }

}  // namespace qdot::flat
