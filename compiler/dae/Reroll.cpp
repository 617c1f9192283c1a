// Rerolling (Reroll.h): each row's residual is read with its symbols replaced by their places
// (slots, taken in symbol order), so that rows which are one expression over other symbols have one
// signature (a structural hash over kinds, numbers and slots), confirmed by walking the two
// expressions side by side. Rows with one signature, in row order, form runs where every slot
// stands for the same symbol in each row (a parameter, the time) or moves by a constant stride: +1
// along the unknowns, any stride along the parameters. A long enough run becomes a TemplateBlock
// whose relative symbols index arrays made of the symbols the slots stood for, row by row. (Nothing
// is built per row: a model of 10⁵ elements has 6·10⁵ rows and outputs to look at.)
#include "dae/Reroll.h"

#include <algorithm>
#include <climits>
#include <cstring>
#include <map>
#include <tuple>
#include <optional>
#include <unordered_map>

namespace qdot::dae {
namespace {

using sym::Expr;

enum class Space : uint8_t { Unknown, Rate, Parameter, Other };

// What a slot of a row stands for: an unknown's y or y' (by variable), a parameter, or
// another symbol (the time), which must then be the same in every row of a run.
struct Slot {
  Space space = Space::Other;
  long index = -1;
  Expr symbol = nullptr;
};

struct RowShape {
  Expr value = nullptr;     ///< null: not looked at
  uint64_t signature = 0;  ///< equal for rows that are one expression over their slots
  std::vector<Slot> slots;
};

struct Run {
  std::vector<int> rows;      ///< in row order
  std::vector<long> strides;  ///< per slot: how far its index moves from row to row
};

class Reroller {
 public:
  Reroller(Dae& d, sym::Context& ctx, size_t minimumRun) : d_(d), ctx_(ctx), minimum_(std::max<size_t>(2, minimumRun)) {}

  RerollResult run() {
    RerollResult result;
    // Initial equations may become rows used at t0 whose plan (dae::planInitialization) reads every
    // row's residual: such a model keeps its rows.
    if (d_.templated() || !d_.differentiatedRows.empty() || !d_.initialEquations.empty()) return result;
    indexSymbols();
    rerollRowRuns(result);
    rerollOutputRuns(result);
    return result;
  }

 private:
  void rerollRowRuns(RerollResult& result) {
    if (d_.equations.size() < minimum_) return;
    shapes_.resize(d_.equations.size());
    for (int r : candidateRows()) shapes_[r] = shapeOf(d_.equations[r].residual);
    std::vector<Run> runs = findRuns();
    // Kinematic rows (q' = der(q): one subtraction each) are not worth loops on their own: the
    // N-link pendulum's would only make its kernel a little slower to build.
    if (std::all_of(runs.begin(), runs.end(), [&](const Run& r) { return kindOf(r) == flat::OriginKind::Kinematic; })) return;
    // The Euler–Lagrange rows are the first rowCoordinates.size() rows and stay so: a run on both
    // sides of that line (there is none in a DAE as built) is left as rows.
    auto m = static_cast<int>(d_.rowCoordinates.size());
    std::erase_if(runs, [&](const Run& r) { return (r.rows.front() < m) != (r.rows.back() < m); });
    makeParametersConsecutive(runs);
    if (runs.empty()) return;
    moveRowsTogether(runs);
    for (const Run& r : runs) makeBlock(r), ++result.blocks, result.rows += r.rows.size();
  }

  // Outputs keep their order (it is the result columns'): runs of consecutive outputs of one
  // signature and kind, along the unknowns and along parameters already consecutive, become
  // OutputBlocks (a component array's flows, which the DAE solved out of the system).
  void rerollOutputRuns(RerollResult& result) {
    if (d_.outputs.size() < minimum_) return;
    indexParameters();  // (the rows' runs may have moved them)
    std::vector<RowShape> shapes(d_.outputs.size());
    for (size_t i = 0; i < d_.outputs.size(); ++i)
      if (d_.outputs[i].value && d_.outputs[i].sums.empty()) shapes[i] = shapeOf(d_.outputs[i].value);
    auto follows = [&](size_t a, size_t b) -> std::optional<std::vector<long>> {
      if (!shapes[a].value || shapes[a].signature != shapes[b].signature || d_.outputs[a].kind != d_.outputs[b].kind)
        return std::nullopt;
      return strides(shapes[a], shapes[b], 1);
    };
    for (size_t i = 0; i + 1 < shapes.size();) {
      std::optional<std::vector<long>> step = follows(i, i + 1);
      if (!step) {
        ++i;
        continue;
      }
      size_t j = i + 2;
      while (j < shapes.size() && follows(j - 1, j) == step) ++j;
      if (j - i < minimum_) {
        i = j - 1;
        continue;
      }
      std::vector<int> members;
      for (size_t k = i; k < j; ++k) members.push_back(static_cast<int>(k));
      makeOutputBlock(shapes, members, *step);
      ++result.outputBlocks, result.outputs += members.size();
      i = j;
    }
  }

  void indexSymbols() {
    for (size_t j = 0; j < d_.variables.size(); ++j) {
      place(d_.variables[j].y, Space::Unknown, j);
      if (d_.variables[j].yp) place(d_.variables[j].yp, Space::Rate, j);
    }
    indexParameters();
  }
  void indexParameters() {
    for (size_t k = 0; k < d_.parameters.size(); ++k) place(d_.parameters[k].symbol, Space::Parameter, k);
  }
  void place(Expr symbol, Space space, size_t index) {
    if (where_.size() <= symbol->symbolId) where_.resize(symbol->symbolId + 1, {Space::Other, -1});
    where_[symbol->symbolId] = {space, static_cast<long>(index)};
  }

  // The rows worth a signature: those among at least `minimum_` rows of one origin whose residuals
  // agree in what a node tells at once (kind, operand count, depth). Cheap, so that a model with
  // nothing repeated (the N-link pendulum's dense rows) pays next to nothing.
  std::vector<int> candidateRows() const {
    std::map<std::tuple<int, int, size_t, uint32_t>, std::vector<int>> groups;
    for (size_t r = 0; r < d_.equations.size(); ++r)
      if (Expr e = d_.equations[r].residual)
        groups[{static_cast<int>(d_.equations[r].origin.kind), static_cast<int>(e->kind), e->args.size(), e->depth}].push_back(
            static_cast<int>(r));
    std::vector<int> rows;
    for (const auto& [key, members] : groups)
      if (members.size() >= minimum_) rows.insert(rows.end(), members.begin(), members.end());
    return rows;
  }

  flat::OriginKind kindOf(const Run& r) const { return d_.equations[r.rows[0]].origin.kind; }


  RowShape shapeOf(Expr value) {
    RowShape s;
    if (!value) return s;
    s.value = value;
    std::vector<Expr> symbols = ctx_.freeSymbols(value);
    std::sort(symbols.begin(), symbols.end(), [](Expr a, Expr b) { return a->symbolId < b->symbolId; });
    for (size_t k = 0; k < symbols.size(); ++k) {
      uint32_t id = symbols[k]->symbolId;
      Slot slot = id < where_.size() ? Slot{where_[id].first, where_[id].second} : Slot{};
      slot.symbol = symbols[k];
      s.slots.push_back(slot);
    }
    s.signature = signatureOf(s);
    return s;
  }

  // Slot numbers of a shape's symbols, by symbol id, in one of two scratch tables (set, used, reset).
  void setSlots(std::vector<int32_t>& table, const RowShape& s) {
    for (size_t k = 0; k < s.slots.size(); ++k) {
      uint32_t id = s.slots[k].symbol->symbolId;
      if (table.size() <= id) table.resize(id + 1, -1);
      table[id] = static_cast<int32_t>(k);
    }
  }
  static void resetSlots(std::vector<int32_t>& table, const RowShape& s) {
    for (const Slot& slot : s.slots) table[slot.symbol->symbolId] = -1;
  }

  static uint64_t mix(uint64_t h, uint64_t v) { return (h ^ (v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2))) * 0x100000001b3ull; }
  static uint64_t bits(double v) {
    uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  }

  // A hash of the expression with each symbol read as its slot: the DAG walked once (children
  // before parents, each node once).
  uint64_t signatureOf(const RowShape& s) {
    setSlots(slotA_, s);
    hashes_.clear();
    std::vector<std::pair<Expr, size_t>> stack{{s.value, 0}};
    while (!stack.empty()) {
      auto& [n, next] = stack.back();
      size_t kids = n->args.size() + n->exps().size();
      if (next < kids) {
        Expr c = next < n->args.size() ? n->args[next] : n->exps()[next - n->args.size()];
        ++next;
        if (!hashes_.count(c)) stack.push_back({c, 0});
        continue;
      }
      uint64_t h = mix(static_cast<uint64_t>(n->kind), bits(n->value));
      if (n->isSymbol()) h = mix(h, static_cast<uint64_t>(slotA_[n->symbolId]) + 1);
      for (double c : n->coefs()) h = mix(h, bits(c));
      for (Expr c : n->args) h = mix(h, hashes_.at(c));
      for (Expr c : n->exps()) h = mix(h, hashes_.at(c));
      hashes_.emplace(n, h);
      stack.pop_back();
    }
    resetSlots(slotA_, s);
    return hashes_.at(s.value);
  }

  // Whether two shapes with one signature are one expression over their slots: walked side by side.
  bool sameExpression(const RowShape& x, const RowShape& y) {
    if (x.slots.size() != y.slots.size()) return false;
    setSlots(slotA_, x);
    setSlots(slotB_, y);
    pairs_.clear();
    std::vector<std::pair<Expr, Expr>> stack{{x.value, y.value}};
    bool same = true;
    while (same && !stack.empty()) {
      auto [a, b] = stack.back();
      stack.pop_back();
      auto [at, fresh] = pairs_.try_emplace(a, b);
      if (!fresh) {
        same = at->second == b;
        continue;
      }
      same = a->kind == b->kind && bits(a->value) == bits(b->value) && a->args.size() == b->args.size() &&
             a->exps().size() == b->exps().size() && a->coefs().size() == b->coefs().size() &&
             std::equal(a->coefs().begin(), a->coefs().end(), b->coefs().begin(), [](double u, double v) { return bits(u) == bits(v); }) &&
             (!a->isSymbol() || slotA_[a->symbolId] == slotB_[b->symbolId]);
      for (size_t k = 0; same && k < a->args.size(); ++k) stack.push_back({a->args[k], b->args[k]});
      for (size_t k = 0; same && k < a->exps().size(); ++k) stack.push_back({a->exps()[k], b->exps()[k]});
    }
    resetSlots(slotA_, x);
    resetSlots(slotB_, y);
    return same;
  }

  // How each slot moves from row a to row b, if b may follow a in a run: the same symbol, or for an
  // unknown the next one, for a parameter one at any distance after it.
  std::optional<std::vector<long>> strides(int a, int b) {
    if (d_.equations[a].origin.kind != d_.equations[b].origin.kind) return std::nullopt;
    return strides(shapes_[a], shapes_[b]);
  }
  std::optional<std::vector<long>> strides(const RowShape& x, const RowShape& y, long parameterStride = LONG_MAX) {
    if (x.signature != y.signature || !sameExpression(x, y)) return std::nullopt;
    std::vector<long> out(x.slots.size());
    bool moves = false;
    for (size_t k = 0; k < x.slots.size(); ++k) {
      const Slot &s = x.slots[k], &t = y.slots[k];
      if (s.space != t.space) return std::nullopt;
      long step = t.index - s.index;
      switch (s.space) {
        case Space::Other:
          if (s.symbol != t.symbol) return std::nullopt;
          step = 0;
          break;
        case Space::Unknown:
        case Space::Rate:
          if (step != 0 && step != 1) return std::nullopt;
          break;
        case Space::Parameter:
          if (step < 0 || step > parameterStride) return std::nullopt;
          break;
      }
      out[k] = step;
      moves = moves || step != 0;
    }
    if (!moves) return std::nullopt;
    return out;
  }

  std::vector<Run> findRuns() {
    std::unordered_map<uint64_t, std::vector<int>> bySignature;
    std::vector<uint64_t> order;  // signatures by first row: runs come out in row order
    for (size_t r = 0; r < shapes_.size(); ++r) {
      if (!shapes_[r].value) continue;
      auto [at, fresh] = bySignature.try_emplace(shapes_[r].signature);
      if (fresh) order.push_back(shapes_[r].signature);
      at->second.push_back(static_cast<int>(r));
    }
    std::vector<Run> runs;
    for (uint64_t signature : order) {
      const std::vector<int>& rows = bySignature[signature];
      for (size_t i = 0; i + 1 < rows.size();) {
        std::optional<std::vector<long>> step = strides(rows[i], rows[i + 1]);
        if (!step) {
          ++i;
          continue;
        }
        Run run{{rows[i], rows[i + 1]}, *step};
        size_t j = i + 2;
        for (; j < rows.size() && strides(rows[j - 1], rows[j]) == run.strides; ++j) run.rows.push_back(rows[j]);
        // A run kept owns its rows; a short one's last row may still start the next run.
        bool kept = run.rows.size() >= minimum_ && commonUnknownsApart(run);
        if (kept) runs.push_back(std::move(run));
        i = kept ? j : j - 1;
      }
    }
    return runs;
  }

  // An unknown every row of a run reads (a common frame) is a Jacobian column of its own in each
  // row: it must not be one the arrays of the run reach (that row would have the column twice).
  bool commonUnknownsApart(const Run& r) const {
    const std::vector<Slot>& first = shapes_[r.rows[0]].slots;
    auto n = static_cast<long>(r.rows.size());
    for (size_t k = 0; k < first.size(); ++k) {
      bool unknown = first[k].space == Space::Unknown || first[k].space == Space::Rate;
      if (!unknown || r.strides[k] != 0) continue;
      for (size_t m = 0; m < first.size(); ++m) {
        bool moving = (first[m].space == Space::Unknown || first[m].space == Space::Rate) && r.strides[m] != 0;
        if (moving && first[k].index >= first[m].index && first[k].index < first[m].index + n) return false;
      }
    }
    return true;
  }

  // A loop reads a parameter array as p[first + i]: the parameters a run reads at a stride of more
  // than one (a parameter of each component of an array: links[i].k, links[i].c, …) are moved next
  // to each other, the others keep their order. Runs whose parameters still are not consecutive
  // (two runs wanting them in different orders) stay scalar rows.
  void makeParametersConsecutive(std::vector<Run>& runs) {
    struct Column {
      long first, stride, last;
    };
    std::vector<Column> columns;
    for (const Run& r : runs)
      for (size_t k = 0; k < r.strides.size(); ++k) {
        const Slot& s = shapes_[r.rows[0]].slots[k];
        if (s.space != Space::Parameter || r.strides[k] < 2) continue;
        Column c{s.index, r.strides[k], s.index + r.strides[k] * static_cast<long>(r.rows.size() - 1)};
        auto same = std::find_if(columns.begin(), columns.end(), [&](const Column& o) {
          return o.stride == c.stride && o.first % o.stride == c.first % c.stride && c.first <= o.last + o.stride &&
                 o.first <= c.last + c.stride;
        });
        if (same != columns.end()) same->first = std::min(same->first, c.first), same->last = std::max(same->last, c.last);
        else columns.push_back(c);
      }
    if (!columns.empty()) {
      std::vector<int> columnOf(d_.parameters.size(), -1);
      for (size_t c = 0; c < columns.size(); ++c)
        for (long p = columns[c].first; p <= columns[c].last; p += columns[c].stride)
          if (columnOf[p] < 0) columnOf[p] = static_cast<int>(c);
      std::vector<long> newIndex(d_.parameters.size(), -1);
      std::vector<Parameter> permuted;
      permuted.reserve(d_.parameters.size());
      auto emit = [&](long p) {
        if (newIndex[p] >= 0) return;
        newIndex[p] = static_cast<long>(permuted.size());
        permuted.push_back(std::move(d_.parameters[p]));
      };
      std::vector<char> placed(columns.size(), 0);
      for (long p = 0; p < static_cast<long>(d_.parameters.size()); ++p) {
        if (int c = columnOf[p]; c >= 0 && !placed[c]) {  // the whole column where its first member was
          placed[c] = 1;
          for (long q = columns[c].first; q <= columns[c].last; q += columns[c].stride)
            if (columnOf[q] == c) emit(q);
        }
        emit(p);
      }
      d_.parameters = std::move(permuted);
      for (RowShape& s : shapes_)
        for (Slot& slot : s.slots)
          if (slot.space == Space::Parameter) slot.index = newIndex[slot.index];
    }
    std::erase_if(runs, [&](const Run& r) { return !parametersConsecutive(r); });
  }

  bool parametersConsecutive(const Run& r) const {
    for (size_t k = 0; k < r.strides.size(); ++k) {
      if (shapes_[r.rows[0]].slots[k].space != Space::Parameter || r.strides[k] == 0) continue;
      for (size_t j = 1; j < r.rows.size(); ++j)
        if (shapes_[r.rows[j]].slots[k].index != shapes_[r.rows[j - 1]].slots[k].index + 1) return false;
    }
    return true;
  }

  // Each run's rows next to each other, where its first row was; the derivative links and the
  // Euler–Lagrange rows' coordinates follow their rows. (A run holds rows of one origin, so the
  // Euler–Lagrange rows stay first.)
  void moveRowsTogether(std::vector<Run>& runs) {
    std::vector<int> runOf(d_.equations.size(), -1);
    for (size_t k = 0; k < runs.size(); ++k)
      for (int r : runs[k].rows) runOf[r] = static_cast<int>(k);
    std::vector<int> newRow(d_.equations.size(), -1), order;
    order.reserve(d_.equations.size());
    for (size_t r = 0; r < d_.equations.size(); ++r) {
      if (newRow[r] >= 0) continue;
      if (runOf[r] < 0) {
        newRow[r] = static_cast<int>(order.size()), order.push_back(static_cast<int>(r));
        continue;
      }
      for (int q : runs[runOf[r]].rows) newRow[q] = static_cast<int>(order.size()), order.push_back(q);
    }
    std::vector<Equation> equations;
    std::vector<RowShape> shapes;
    equations.reserve(order.size());
    shapes.reserve(order.size());
    for (int r : order) equations.push_back(std::move(d_.equations[r])), shapes.push_back(std::move(shapes_[r]));
    d_.equations = std::move(equations);
    shapes_ = std::move(shapes);
    std::vector<std::string> coordinates(d_.rowCoordinates.size());
    for (size_t r = 0; r < d_.rowCoordinates.size(); ++r) coordinates[newRow[r]] = std::move(d_.rowCoordinates[r]);
    d_.rowCoordinates = std::move(coordinates);
    for (DerivativeLink& l : d_.links) l.row = newRow[l.row];
    for (Run& run : runs)
      for (int& r : run.rows) r = newRow[r];
  }

  // The array of the symbols slot k stands for, member by member (one array per distinct sequence).
  Expr relativeSymbol(const std::vector<RowShape>& shapes, const std::vector<int>& members, size_t k) {
    if (!d_.patterns) d_.patterns = std::make_shared<flat::ElementPatterns>();
    std::vector<Expr> elements;
    elements.reserve(members.size());
    for (int m : members) elements.push_back(shapes[m].slots[k].symbol);
    std::string name = "{" + std::string(ctx_.symbolName(elements.front())) + "…" + std::string(ctx_.symbolName(elements.back())) + "}";
    auto [at, fresh] = arrays_.try_emplace(name, 0);
    if (fresh) {
      at->second = static_cast<int>(d_.patterns->arrays.size());
      d_.patterns->arrays.push_back({name, {static_cast<int>(elements.size())}, std::move(elements), -1});
    }
    return d_.patterns->symbol(ctx_, {at->second, {{0, 0}}});
  }

  // The first member's value with each moving symbol replaced by its array's relative symbol.
  Expr templateOf(const std::vector<RowShape>& shapes, const std::vector<int>& members, const std::vector<long>& strides,
                  Expr value) {
    std::unordered_map<Expr, Expr> map;
    for (size_t k = 0; k < strides.size(); ++k)
      if (strides[k] != 0) map.emplace(shapes[members[0]].slots[k].symbol, relativeSymbol(shapes, members, k));
    return ctx_.substitute(value, map);
  }

  void makeOutputBlock(const std::vector<RowShape>& shapes, const std::vector<int>& members, const std::vector<long>& strides) {
    flat::Output& first = d_.outputs[members[0]];
    Expr value = templateOf(shapes, members, strides, first.value);
    d_.outputBlocks.push_back({members[0], static_cast<int>(members.size()), value, first.range});
    for (int m : members) d_.outputs[m].value = nullptr;
  }

  void makeBlock(const Run& r) {
    Equation& e = d_.equations[r.rows[0]];
    Expr residual = templateOf(shapes_, r.rows, r.strides, e.residual);
    auto n = static_cast<long>(r.rows.size());
    d_.templateBlocks.push_back({r.rows[0], {static_cast<int>(n)}, {{1, n}}, residual, e.origin.kind, e.origin.range});
    for (int row : r.rows) d_.equations[row].residual = nullptr;
  }

  Dae& d_;
  sym::Context& ctx_;
  size_t minimum_;
  std::vector<std::pair<Space, long>> where_;  ///< by symbolId: what each symbol of the DAE is
  std::vector<RowShape> shapes_;
  std::vector<int32_t> slotA_, slotB_;          ///< by symbol id: its slot in the shapes looked at (-1: none)
  std::unordered_map<Expr, uint64_t> hashes_;   ///< signatureOf's, kept to spare an allocation per row
  std::unordered_map<Expr, Expr> pairs_;        ///< sameExpression's
  std::unordered_map<std::string, int> arrays_;
};

}  // namespace

RerollResult rerollRows(Dae& dae, sym::Context& ctx, size_t minimumRun) { return Reroller(dae, ctx, minimumRun).run(); }

}  // namespace qdot::dae
