// The storage and fast paths behind the public API give the same answers as the plain algorithms:
// large sums built from ascending runs, reversed or shuffled operands are one node; the constant
// cache and the symbol-name table never confuse values or names; traversals agree below and above
// the size where their visited set leaves its inline buffer; operands of a Mul are contiguous.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

std::string numbered(const char* prefix, size_t i) {
  std::string name = prefix;
  name += std::to_string(i);
  return name;
}

// Mixed terms: symbols, products, powers and functions, with repeated (like) terms.
std::vector<Expr> mixedTerms(Context& ctx, size_t n) {
  std::vector<Expr> q, terms;
  for (size_t i = 0; i < n / 4 + 1; ++i) q.push_back(ctx.symbol(numbered("q", i)));
  for (size_t i = 0; i < n; ++i) {
    Expr a = q[i % q.size()], b = q[(7 * i + 3) % q.size()];
    switch (i % 4) {
      case 0: terms.push_back(ctx.scale(double(i % 5) + 1, a)); break;
      case 1: terms.push_back(ctx.mul(a, b)); break;
      case 2: terms.push_back(ctx.pow(a, ctx.constant(double(i % 3) + 2))); break;
      default: terms.push_back(ctx.unary(Kind::Sin, ctx.add(a, b))); break;
    }
  }
  return terms;
}

TEST(Storage, LargeSumsDoNotDependOnOperandOrder) {
  for (size_t n : {10u, 63u, 64u, 65u, 200u, 5000u}) {
    Context ctx;
    std::vector<Expr> terms = mixedTerms(ctx, n);
    Expr sum = ctx.add(terms);
    std::vector<Expr> reversed(terms.rbegin(), terms.rend());
    EXPECT_EQ(ctx.add(reversed), sum) << n;
    std::vector<Expr> shuffled = terms;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(static_cast<unsigned>(n)));
    EXPECT_EQ(ctx.add(shuffled), sum) << n;
    // Sorted runs: two canonical halves, and a canonical sum plus a few stray terms.
    size_t half = n / 2;
    Expr a = ctx.add(std::span<const Expr>(terms).first(half));
    Expr b = ctx.add(std::span<const Expr>(terms).subspan(half));
    EXPECT_EQ(ctx.add(a, b), sum) << n;
    Expr most = ctx.add(std::span<const Expr>(terms).first(n - 3));
    std::vector<Expr> parts = {terms[n - 1], most, terms[n - 3], terms[n - 2]};
    EXPECT_EQ(ctx.add(parts), sum) << n;
    if (sum->kind == Kind::Add) {
      for (size_t i = 1; i < sum->args.size(); ++i) EXPECT_LT(structuralCompare(sum->args[i - 1], sum->args[i]), 0);
    }
  }
}

TEST(Storage, ConstantsAreExactAndUnique) {
  Context ctx;
  std::mt19937_64 rng(7);
  std::vector<double> values = {0.0, 1.0, -1.0, 0.5, 1e-300, -1e300, std::numeric_limits<double>::infinity()};
  for (int i = 0; i < 20000; ++i) values.push_back(std::ldexp(double(rng() % 100000) - 50000, int(rng() % 40) - 20));
  std::set<Expr> distinct;
  for (double v : values) {
    Expr c = ctx.constant(v);
    ASSERT_EQ(c->value, v);
    ASSERT_EQ(ctx.constant(v), c);  // cached or not, the same node
    distinct.insert(c);
  }
  EXPECT_EQ(distinct.size(), std::set<double>(values.begin(), values.end()).size());
  EXPECT_EQ(ctx.constant(-0.0), ctx.zero());
  Expr nan = ctx.constant(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ctx.constant(-std::numeric_limits<double>::quiet_NaN()), nan);
}

TEST(Storage, ManySymbolsWithLongNames) {
  Context ctx;
  const size_t N = 20000;
  std::vector<Expr> syms;
  for (size_t i = 0; i < N; ++i) syms.push_back(ctx.symbol(numbered("$der(der(a_rather_long_name[", i) + "]))"));
  EXPECT_EQ(ctx.symbolCount(), N);
  for (size_t i = 0; i < N; i += 997) {
    std::string name = numbered("$der(der(a_rather_long_name[", i) + "]))";
    EXPECT_EQ(ctx.findSymbol(name), syms[i]);
    EXPECT_EQ(ctx.symbol(name), syms[i]);
    EXPECT_EQ(ctx.symbolName(syms[i]), name);
    EXPECT_EQ(syms[i]->symbolId, i);
  }
  EXPECT_EQ(ctx.findSymbol("$der(der(a_rather_long_name[20000]))"), nullptr);
  EXPECT_EQ(ctx.findSymbol(""), nullptr);
}

// Context::reserve resizes the intern and name tables ahead of what is made: every expression and
// symbol made before is found again (the same node), both after reserving and after the tables
// later grow past the reservation, and a symbol never becomes a node of the intern table's kind
// (x*x is x^2, not a second x).
TEST(Storage, ReserveKeepsInterningAndNames) {
  Context ctx;
  auto build = [&](size_t i) {
    Expr x = ctx.symbol(numbered("x", i));
    return ctx.add(ctx.mul(ctx.constant(0.5 + double(i)), ctx.pow(x, ctx.constant(2))), ctx.unary(Kind::Sin, x));
  };
  std::vector<Expr> before;
  for (size_t i = 0; i < 300; ++i) before.push_back(build(i));
  size_t symbols = ctx.symbolCount(), nodes = ctx.nodeCount();
  ctx.reserve(100000, 100000);
  EXPECT_EQ(ctx.symbolCount(), symbols);
  EXPECT_EQ(ctx.nodeCount(), nodes);
  for (size_t i = 0; i < before.size(); ++i) EXPECT_EQ(build(i), before[i]) << i;
  EXPECT_EQ(ctx.nodeCount(), nodes);  // nothing new: every node was found
  std::vector<Expr> after;
  for (size_t i = 300; i < 60000; ++i) after.push_back(build(i));  // past the reservation: the tables grow
  for (size_t i = 0; i < before.size(); ++i) EXPECT_EQ(build(i), before[i]) << i;
  for (size_t i = 300; i < 60000; i += 599) EXPECT_EQ(build(i), after[i - 300]) << i;
  EXPECT_EQ(ctx.symbolCount(), 60000u);
  for (size_t i = 0; i < 60000; i += 1009) {
    Expr x = ctx.findSymbol(numbered("x", i));
    ASSERT_NE(x, nullptr);
    EXPECT_EQ(x->symbolId, i);
    EXPECT_EQ(ctx.symbolName(x), numbered("x", i));
    EXPECT_EQ(ctx.mul(x, x), ctx.pow(x, ctx.constant(2)));
    EXPECT_EQ(ctx.sub(ctx.add(x, ctx.one()), x), ctx.one());
  }
  EXPECT_EQ(ctx.findSymbol("x60000"), nullptr);
}

// A product of two numbers is the constant of their product, whichever path builds it.
TEST(Storage, ProductOfNumbersIsAConstant) {
  Context ctx;
  for (double a : {0.01, -3.0, 0.0, 1e300, 7.5})
    for (double b : {3.0, -0.0, 1e10, std::numeric_limits<double>::infinity()}) {
      Expr expected = ctx.constant(a * b);
      EXPECT_EQ(ctx.mul(ctx.constant(a), ctx.constant(b)), expected) << a << " * " << b;
      Expr both[] = {ctx.constant(a), ctx.constant(b)};
      EXPECT_EQ(ctx.mul(both), expected) << a << " * " << b;
    }
}

// S·cos(S) with S = Σ sin(s_i), so S is reached twice: 2n + 4 nodes, small (inline visited set,
// up to 32 nodes) and large (hash set) cases.
TEST(Storage, TraversalsAgreeOnSmallAndLargeExpressions) {
  for (size_t n : {3u, 15u, 16u, 17u, 40u, 1000u}) {
    Context ctx;
    std::vector<Expr> syms, terms;
    for (size_t i = 0; i < n; ++i) syms.push_back(ctx.symbol(numbered("s", i)));
    for (size_t i = 0; i < n; ++i) terms.push_back(ctx.unary(Kind::Sin, syms[i]));
    Expr sum = ctx.add(terms);
    Expr e = ctx.mul(sum, ctx.unary(Kind::Cos, sum));
    std::vector<Expr> fs = ctx.freeSymbols(e);
    EXPECT_EQ(fs, syms) << n;
    Expr root = e;
    EXPECT_EQ(ctx.dagSize(std::span<const Expr>(&root, 1)), 2 * n + 4) << n;  // s, sin s, S, cos S, 1, *
    EXPECT_TRUE(ctx.dependsOn(e, syms[n - 1]));
    EXPECT_FALSE(ctx.dependsOn(e, ctx.symbol("other")));
  }
}

TEST(Storage, MulOperandsAreOneArray) {
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y");
  Expr m = ctx.mul(ctx.pow(x, ctx.constant(2)), ctx.unary(Kind::Sin, y));
  ASSERT_EQ(m->kind, Kind::Mul);
  ASSERT_EQ(m->args.size(), 2u);
  EXPECT_EQ(m->exps().data(), m->args.data() + m->args.size());  // children: args, then exps
  EXPECT_TRUE(m->coefs().empty());
  Expr s = ctx.add(x, ctx.scale(3, y));
  EXPECT_EQ(s->coefs().size(), s->args.size());
  EXPECT_TRUE(s->exps().empty());
}

}  // namespace

// Context::clear (qdot run frees every node once the kernels are built): the Context is as new —
// no old name is found, symbols are numbered from the start again, and what is built after it
// simplifies and differentiates exactly as in a fresh Context.
TEST(Storage, ClearGivesAContextAsNew) {
  Context used, fresh;
  for (size_t i = 0; i < 5000; ++i) used.symbol(numbered("old", i));
  Expr x0 = used.symbol("x");
  (void)used.diff(used.mul(x0, x0), x0);
  used.clear();
  EXPECT_EQ(used.findSymbol("old1"), nullptr);
  EXPECT_EQ(used.findSymbol("x"), nullptr);
  EXPECT_EQ(used.symbolCount(), fresh.symbolCount());
  Expr x = used.symbol("x"), y = used.symbol("y");
  Expr fx = fresh.symbol("x"), fy = fresh.symbol("y");
  EXPECT_EQ(x->symbolId, fx->symbolId);
  EXPECT_EQ(y->symbolId, fy->symbolId);
  EXPECT_TRUE(used.zero()->isZero());
  EXPECT_TRUE(used.one()->isOne());
  Expr e = used.add(used.mul(x, y), used.pow(x, used.constant(3)));
  Expr fe = fresh.add(fresh.mul(fx, fy), fresh.pow(fx, fresh.constant(3)));
  EXPECT_EQ(used.diff(e, x)->hash, fresh.diff(fe, fx)->hash);
  EXPECT_EQ(used.add(used.mul(x, y), used.mul(y, x)), used.scale(2, used.mul(x, y)));
}

// Context::constants (a large array's start values at once) gives the nodes constant() gives one by
// one: the same node for the same value (across the batch and before it), -0 as 0, every value exact.
TEST(Storage, ConstantsInOneBatchAreTheConstantsOneByOne) {
  Context ctx;
  Expr before = ctx.constant(0.25);
  std::vector<double> values;
  for (int i = 0; i < 5000; ++i) values.push_back(0.01 * (i % 1700) - 3.0);
  values.insert(values.end(), {0.25, -0.0, 0.0, std::numeric_limits<double>::infinity(), 1e-300});
  std::vector<Expr> batch = ctx.constants(values);
  ASSERT_EQ(batch.size(), values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    ASSERT_TRUE(batch[i]->isConstant());
    EXPECT_EQ(batch[i], ctx.constant(values[i])) << i;
    EXPECT_EQ(batch[i]->value, values[i] == 0 ? 0.0 : values[i]) << i;
  }
  EXPECT_EQ(batch[values.size() - 5], before);
  EXPECT_EQ(batch[values.size() - 4], ctx.zero());
  EXPECT_EQ(batch[values.size() - 3], ctx.zero());
  EXPECT_EQ(batch[0], batch[1700]);
  EXPECT_TRUE(ctx.constants({}).empty());
}

// symbolArray makes an array's element symbols as one block, outside the name table: they are the
// symbols symbol() finds and makes by those names (one symbol per name, whichever came first),
// named and ordered as the flattener names elements, and symbolArrayOf finds their array.
TEST(Storage, SymbolArraysAreFoundByName) {
  Context ctx;
  Expr before = ctx.symbol("a");
  std::vector<int> shape{2, 3};
  std::vector<Expr> m = ctx.symbolArray("der(M", shape, ")");
  ASSERT_EQ(m.size(), 6u);
  const char* names[] = {"der(M[1,1])", "der(M[1,2])", "der(M[1,3])", "der(M[2,1])", "der(M[2,2])", "der(M[2,3])"};
  for (size_t k = 0; k < m.size(); ++k) {
    EXPECT_EQ(ctx.symbolName(m[k]), names[k]);
    EXPECT_EQ(m[k]->symbolId, before->symbolId + 1 + k);
    EXPECT_EQ(ctx.findSymbol(names[k]), m[k]);
    EXPECT_EQ(ctx.symbol(names[k]), m[k]);
    auto info = ctx.symbolArrayOf(m[k]);
    ASSERT_TRUE(info);
    EXPECT_EQ(info->prefix, "der(M");
    EXPECT_EQ(info->suffix, ")");
    EXPECT_EQ(std::vector<int>(info->shape.begin(), info->shape.end()), shape);
    EXPECT_EQ(info->first, m[0]->symbolId);
  }
  EXPECT_EQ(ctx.symbolCount(), 7u);
  EXPECT_FALSE(ctx.symbolArrayOf(before));
  // Not elements: out of range, written differently, another family.
  for (const char* other : {"der(M[3,1])", "der(M[0,1])", "der(M[1, 2])", "der(M[01,2])", "der(M[1])", "der(M[1,2,1])",
                            "der(M[1,2]", "M[1,2]", "der(M[x,2])"})
    EXPECT_EQ(ctx.findSymbol(other), nullptr) << other;
  Expr outside = ctx.symbol("der(M[3,1])");  // an ordinary symbol of the same family
  EXPECT_EQ(outside->symbolId, 7u);
  EXPECT_EQ(ctx.findSymbol("der(M[3,1])"), outside);
  // A family whose names may be in the table already is made through it: the same symbols.
  Expr x2 = ctx.symbol("x[2]");
  std::vector<Expr> x = ctx.symbolArray("x", std::vector<int>{3});
  ASSERT_EQ(x.size(), 3u);
  EXPECT_EQ(x[1], x2);
  EXPECT_FALSE(ctx.symbolArrayOf(x[0]));
  EXPECT_EQ(ctx.symbolName(x[2]), "x[3]");
  // A second array of a family already made is made through the names too.
  std::vector<Expr> again = ctx.symbolArray("der(M", shape, ")");
  EXPECT_EQ(again, m);
  // An empty array has no symbols.
  EXPECT_TRUE(ctx.symbolArray("e", std::vector<int>{0}).empty());
}

// A large array is made in two halves on two threads (Context::symbolArray): every element still
// has its own id in order, its own node, and the name the flattener gives it, written out here
// independently (a 2-D shape whose halves meet inside a row, subscripts gaining digits on both
// sides of the cut), and is found by that name.
TEST(Storage, ALargeSymbolArrayIsMadeInTwoHalvesWithEveryName) {
  Context ctx;
  Expr before = ctx.symbol("a");
  std::vector<int> shape{1001, 131};  // 131 131 elements: the cut at 65 565 = row 501, column 66
  std::vector<Expr> m = ctx.symbolArray("der(M", shape, ")");
  ASSERT_EQ(m.size(), 1001u * 131u);
  size_t k = 0, wrong = 0;
  for (int i = 1; i <= shape[0]; ++i)
    for (int j = 1; j <= shape[1]; ++j, ++k) {
      std::string name = "der(M[" + std::to_string(i) + "," + std::to_string(j) + "])";
      bool right = m[k]->isSymbol() && m[k]->symbolId == before->symbolId + 1 + k && ctx.symbolName(m[k]) == name &&
                   (k % 997 != 0 || ctx.findSymbol(name) == m[k]);  // the lookup on a sample
      if (!right && wrong++ < 5) ADD_FAILURE() << "element " << k << " (" << name << ") is " << ctx.symbolName(m[k]);
    }
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(ctx.symbolCount(), 1 + m.size());
  EXPECT_EQ(ctx.symbol("b")->symbolId, 1 + m.size());  // the next symbol after the block
  std::vector<Expr> rates = ctx.symbolArrayAround(m[0], "$der(", ")");
  EXPECT_EQ(ctx.symbolName(rates[65565]), "$der(der(M[501,66]))");
  EXPECT_EQ(ctx.symbolName(rates.back()), "$der(der(M[1001,131]))");
}

// wholeSymbolArrayAt recognises an array's symbols only whole and in order, and symbolArrayAround
// makes the array of the names around them (der(q[i]) for q[i]) as a block of the same shape.
TEST(Storage, ASymbolArrayIsRecognisedWholeAndWrapped) {
  Context ctx;
  std::vector<int> shape{2, 2};
  std::vector<Expr> q = ctx.symbolArray("q", shape);
  Expr other = ctx.symbol("b");
  EXPECT_EQ(ctx.wholeSymbolArrayAt(q), 4u);
  std::vector<Expr> longer = q;
  longer.push_back(other);
  EXPECT_EQ(ctx.wholeSymbolArrayAt(longer), 4u);
  EXPECT_EQ(ctx.wholeSymbolArrayAt(std::span(q).subspan(1)), 0u);  // not from its first element
  EXPECT_EQ(ctx.wholeSymbolArrayAt(std::span(q).first(3)), 0u);    // not whole
  std::vector<Expr> swapped{q[0], q[2], q[1], q[3]};
  EXPECT_EQ(ctx.wholeSymbolArrayAt(swapped), 0u);                  // not in order
  std::vector<Expr> notSymbols{ctx.add(q[0], other), q[1], q[2], q[3]};
  EXPECT_EQ(ctx.wholeSymbolArrayAt(notSymbols), 0u);
  EXPECT_EQ(ctx.wholeSymbolArrayAt({}), 0u);
  EXPECT_EQ(ctx.wholeSymbolArrayAt(std::vector<Expr>{other}), 0u);

  std::vector<Expr> rates = ctx.symbolArrayAround(q[0], "der(", ")");
  ASSERT_EQ(rates.size(), 4u);
  EXPECT_EQ(ctx.symbolName(rates[3]), "der(q[2,2])");
  EXPECT_EQ(ctx.findSymbol("der(q[1,2])"), rates[1]);
  EXPECT_EQ(ctx.wholeSymbolArrayAt(rates), 4u);
  std::vector<Expr> twice = ctx.symbolArrayAround(rates[0], "der(", ")");
  EXPECT_EQ(ctx.symbolName(twice[2]), "der(der(q[2,1]))");
  EXPECT_THROW(ctx.symbolArrayAround(q[1], "der(", ")"), std::logic_error);
  EXPECT_THROW(ctx.symbolArrayAround(other, "der(", ")"), std::logic_error);
}

// A block's names are written as the subscripts count up in place: every one equals the name
// formatted from scratch, through carries (9 → 10, 99 → 100) and rows that wrap.
TEST(Storage, SymbolArrayNamesCountUpThroughCarries) {
  Context ctx;
  std::vector<int> line{1005};
  std::vector<Expr> v = ctx.symbolArray("v", line, ".s");
  for (int i = 1; i <= 1005; ++i) EXPECT_EQ(ctx.symbolName(v[i - 1]), "v[" + std::to_string(i) + "].s") << i;
  std::vector<int> grid{11, 3, 12};
  std::vector<Expr> g = ctx.symbolArray("der(g", grid, ")");
  size_t k = 0;
  for (int i = 1; i <= 11; ++i)
    for (int j = 1; j <= 3; ++j)
      for (int l = 1; l <= 12; ++l, ++k) {
        std::string name = "der(g[" + std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(l) + "])";
        ASSERT_EQ(ctx.symbolName(g[k]), name);
        EXPECT_EQ(ctx.findSymbol(name), g[k]);
      }
  EXPECT_EQ(k, g.size());
}
