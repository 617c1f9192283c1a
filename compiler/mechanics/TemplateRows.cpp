// Template Euler–Lagrange rows per region of a coordinate array (see TemplateRows.h).
#include "mechanics/TemplateRows.h"

#include <algorithm>
#include <optional>
#include <unordered_map>

namespace qdot::mech {
namespace {

using flat::ElementPatterns;
using flat::IndexedSum;
using flat::RelativeElement;
using flat::VarRole;
using sym::Expr;

using flat::Box;

class TemplateDeriver {
 public:
  TemplateDeriver(const flat::FlatModel& m, sym::Context& ctx, const std::vector<char>& peeled,
                  sym::SimplifyLevel level)
      : m_(m), ctx_(ctx), patterns_(*m.patterns), peeled_(peeled), simplify_(ctx, level) {}

  TemplateDerivation run(bool rows = true) {
    for (int s = 0; s < static_cast<int>(m_.indexedSums.size()); ++s)
      if (!contribute(m_.indexedSums[s])) out_.scalarSums.push_back(s);
    for (int f = 0; f < static_cast<int>(m_.indexedForces.size()); ++f)
      if (!contributeForce(m_.indexedForces[f])) out_.scalarForces.push_back(f);
    if (!rows) return std::move(out_);
    std::vector<int> arrays;
    for (const Contribution& c : contributions_) arrays.push_back(c.array);
    std::sort(arrays.begin(), arrays.end());
    arrays.erase(std::unique(arrays.begin(), arrays.end()), arrays.end());
    for (int a : arrays) rowsOf(a);
    out_.contributions = std::move(contributions_);
    return std::move(out_);
  }

 private:
  const flat::FlatModel& m_;
  sym::Context& ctx_;
  ElementPatterns& patterns_;  // adds the shifted and differentiated patterns it derives
  const std::vector<char>& peeled_;
  sym::Simplifier simplify_;
  std::vector<Contribution> contributions_;
  TemplateDerivation out_;

  VarRole roleOf(Expr e) const {
    int var = m_.variableOf(e);
    return var >= 0 ? m_.variables[var].role : VarRole::Parameter;
  }
  // The array of coordinates whose velocities `array` is, or -1.
  int coordinatesOfVelocities(int array) const {
    for (int a = 0; a < static_cast<int>(patterns_.arrays.size()); ++a)
      if (patterns_.arrays[a].derivative == array) return a;
    return -1;
  }
  bool moving(int array) const {
    VarRole r = roleOf(patterns_.arrays[array].elements[0]);
    return r == VarRole::Coordinate || r == VarRole::Velocity;
  }

  // Records the sum's contributions; false if it cannot give template rows.
  bool contribute(const IndexedSum& sum) {
    std::vector<Contribution> found;
    for (Expr s : ctx_.freeSymbols(sum.body)) {
      const RelativeElement* rel = patterns_.find(s);
      if (!rel) {
        VarRole r = roleOf(s);
        if (r == VarRole::Coordinate || r == VarRole::Velocity) return false;  // ∂/∂(scalar) would be a reduction
        continue;
      }
      if (!moving(rel->array)) continue;
      if (rel->dims.size() != sum.box.size()) return false;
      for (size_t d = 0; d < rel->dims.size(); ++d)
        if (rel->dims[d].iterator != static_cast<int>(d)) return false;
      bool velocity = roleOf(patterns_.arrays[rel->array].elements[0]) == VarRole::Velocity;
      int coords = velocity ? coordinatesOfVelocities(rel->array) : rel->array;
      if (coords < 0) return false;
      Contribution c;
      c.array = coords;
      std::vector<long> offset;
      for (size_t d = 0; d < rel->dims.size(); ++d) {
        offset.push_back(rel->dims[d].offset);
        c.box.push_back({sum.box[d].first + offset[d], sum.box[d].second + offset[d]});
      }
      c.part = sum.energy == IndexedSum::Energy::Dissipation ? Contribution::Part::Dissipation
               : velocity                                    ? Contribution::Part::Momentum
                                                             : Contribution::Part::Position;
      if (sum.energy == IndexedSum::Energy::Dissipation && !velocity) return false;  // D(q̇) only
      Expr d = ctx_.diff(sum.body, s);
      if (sum.energy == IndexedSum::Energy::Potential) d = ctx_.neg(d);  // L = T − V
      c.value = shift(d, offset);
      found.push_back(std::move(c));
    }
    contributions_.insert(contributions_.end(), found.begin(), found.end());
    return true;
  }

  // Records a force template's contribution; false if its body reads a scalar coordinate or
  // velocity (the rows would need ∂/∂ of it across the loop) or an array of coordinates, velocities
  // or accelerations across its iterators.
  bool contributeForce(const flat::IndexedForce& f) {
    for (Expr s : ctx_.freeSymbols(f.body)) {
      const RelativeElement* rel = patterns_.find(s);
      if (!rel) {
        VarRole r = roleOf(s);
        if (r != VarRole::Parameter && r != VarRole::Time) return false;
        continue;
      }
      if (roleOf(patterns_.arrays[rel->array].elements[0]) == VarRole::Parameter) continue;
      if (rel->dims.size() != f.box.size()) return false;
      for (size_t d = 0; d < rel->dims.size(); ++d)
        if (rel->dims[d].iterator != static_cast<int>(d)) return false;
    }
    const RelativeElement& target = *patterns_.find(f.target);
    Contribution c;
    c.array = target.array;
    c.part = Contribution::Part::Force;
    std::vector<long> offset;
    for (size_t d = 0; d < target.dims.size(); ++d) {
      offset.push_back(target.dims[d].offset);
      c.box.push_back({f.box[d].first + offset[d], f.box[d].second + offset[d]});
    }
    c.value = shift(f.body, offset);
    contributions_.push_back(std::move(c));
    return true;
  }

  // Every relative symbol with its iterator offsets decreased by `by` (indexed by iterator), and
  // every iterator's value %k by by[k] (%k then is the row's subscript: the iterator is %k − by[k]).
  Expr shift(Expr e, const std::vector<long>& by) {
    std::unordered_map<Expr, Expr> map;
    for (Expr s : ctx_.freeSymbols(e)) {
      if (int k = patterns_.iteratorOf(s); k >= 0 && by[k] != 0) {
        map.emplace(s, ctx_.add(s, ctx_.constant(-static_cast<double>(by[k]))));
        continue;
      }
      const RelativeElement* rel = patterns_.find(s);
      if (!rel) continue;
      RelativeElement moved = *rel;
      for (auto& dim : moved.dims)
        if (dim.iterator >= 0) dim.offset -= static_cast<int>(by[dim.iterator]);
      map.emplace(s, patterns_.symbol(ctx_, moved));
    }
    return map.empty() ? e : ctx_.substitute(e, map);
  }

  // The derivative array of `array` (velocities of coordinates, accelerations of velocities).
  int derivativeArray(int array) {
    if (patterns_.arrays[array].derivative >= 0) return patterns_.arrays[array].derivative;
    flat::ArrayVariable d{"der(" + patterns_.arrays[array].name + ")", patterns_.arrays[array].shape, {}};
    d.elements.reserve(patterns_.arrays[array].elements.size());
    for (Expr e : patterns_.arrays[array].elements) d.elements.push_back(m_.variables[m_.variables[m_.variableOf(e)].derivative].symbol);
    patterns_.arrays.push_back(std::move(d));
    patterns_.arrays[array].derivative = static_cast<int>(patterns_.arrays.size()) - 1;
    return patterns_.arrays[array].derivative;
  }

  // d/dt of a template: x[%+o] → der(x)[%+o] → der(der(x))[%+o]; time → 1; parameters constant.
  Expr timeDerivative(Expr e) {
    sym::DirectionalDerivative d(ctx_);
    for (Expr s : ctx_.freeSymbols(e)) {
      if (s == m_.time()) {
        d.setRate(s, ctx_.one());
      } else if (const RelativeElement* rel = patterns_.find(s); rel && moving(rel->array)) {
        RelativeElement rate = *rel;
        rate.array = derivativeArray(rel->array);
        d.setRate(s, patterns_.symbol(ctx_, rate));
      }
    }
    return d(e);
  }

  // The regions of array `a`: each dimension split where a contribution's box begins or ends and
  // around every peeled element.
  void rowsOf(int a) {
    const flat::ArrayVariable& arr = patterns_.arrays[a];
    size_t rank = arr.shape.size();
    std::vector<std::vector<long>> cuts(rank);
    for (size_t d = 0; d < rank; ++d) cuts[d] = {1, static_cast<long>(arr.shape[d]) + 1};
    for (const Contribution& c : contributions_)
      if (c.array == a)
        for (size_t d = 0; d < rank; ++d) cuts[d].insert(cuts[d].end(), {c.box[d].first, c.box[d].second + 1});
    for (size_t k = 0; k < arr.elements.size(); ++k) {
      int var = m_.variableOf(arr.elements[k]);
      if (var < 0 || !peeled_[var]) continue;
      size_t rest = k;
      for (size_t d = rank; d-- > 0;) {
        long sub = static_cast<long>(rest % arr.shape[d]) + 1;
        rest /= arr.shape[d];
        cuts[d].insert(cuts[d].end(), {sub, sub + 1});
      }
    }
    for (auto& c : cuts) {
      std::sort(c.begin(), c.end());
      c.erase(std::unique(c.begin(), c.end()), c.end());
      c.erase(std::remove_if(c.begin(), c.end(), [&](long v) { return v < 1; }), c.end());
    }
    Box region(rank);
    regions(a, cuts, 0, region);
  }

  void regions(int a, const std::vector<std::vector<long>>& cuts, size_t d, Box& region) {
    if (d == cuts.size()) return rowOn(a, region);
    const auto& c = cuts[d];
    long size = patterns_.arrays[a].shape[d];
    for (size_t k = 0; k + 1 < c.size() && c[k] <= size; ++k) {
      region[d] = {c[k], std::min(c[k + 1] - 1, size)};
      regions(a, cuts, d + 1, region);
    }
  }

  void rowOn(int a, const Box& region) {
    TemplateRow row{a, region, nullptr, nullptr};
    if (flat::pointCount(row.region) < 2) return;  // one element: a scalar row
    std::vector<Expr> momentum, position, dissipation, force;
    for (const Contribution& c : contributions_) {
      if (c.array != a || !contains(c.box, region)) continue;
      auto& into = c.part == Contribution::Part::Momentum   ? momentum
                   : c.part == Contribution::Part::Position ? position
                   : c.part == Contribution::Part::Force    ? force
                                                            : dissipation;
      into.push_back(c.value);
    }
    if (momentum.empty() && position.empty() && dissipation.empty()) return;  // forces alone: no inertia
    row.momentum = simplify_(ctx_.add(momentum));
    std::vector<Expr> parts{timeDerivative(row.momentum), ctx_.neg(ctx_.add(position)), ctx_.add(dissipation),
                            ctx_.neg(ctx_.add(force))};
    Expr residual = ctx_.add(parts);
    row.residual = simplify_(residual);
    if (!ctx_.dependsOn(row.residual, ownAcceleration(a))) return;  // no inertia of its own: scalar rows
    out_.rows.push_back(std::move(row));
  }

  // der(der(x))[%1, …, %rank]: a row that contains it determines its element's acceleration.
  Expr ownAcceleration(int a) {
    RelativeElement rel{derivativeArray(derivativeArray(a)), {}};
    for (size_t d = 0; d < patterns_.arrays[a].shape.size(); ++d) rel.dims.push_back({static_cast<int>(d), 0});
    return patterns_.symbol(ctx_, rel);
  }

  static bool contains(const Box& outer, const Box& inner) {
    for (size_t d = 0; d < outer.size(); ++d)
      if (inner[d].first < outer[d].first || inner[d].second > outer[d].second) return false;
    return true;
  }
};

}  // namespace

TemplateDerivation templatesWithoutRows(const flat::FlatModel& model, sym::Context& ctx) {
  std::vector<char> none(model.variables.size(), 0);
  return TemplateDeriver(model, ctx, none, sym::SimplifyLevel::None).run(false);
}

TemplateDerivation deriveTemplateRows(const flat::FlatModel& model, sym::Context& ctx, const std::vector<char>& peeled,
                                      sym::SimplifyLevel level) {
  return TemplateDeriver(model, ctx, peeled, level).run();
}

}  // namespace qdot::mech
