// structural_bench: the structural passes on a spring–damper chain of n masses (issue 10 §5: a
// chain of 100 000 masses through the structural stage in under 1 s). The DAE is built through
// the pipeline (not timed); then, best of R: the equation–unknown graph, the maximum matching and
// the BLT order (Tarjan), and their total, with ns per unknown — near-linear means that figure
// stays flat as n grows. Markdown to stdout.
//   structural_bench [--repeat R] [n ...]     (default: 1000 10000 100000)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "dae/Balance.h"
#include "dae/IndexReduction.h"
#include "driver/Pipeline.h"
#include "structural/BlockTriangular.h"
#include "structural/Matching.h"

namespace {

std::string chain(int n) {
  return "model Chain\n  parameter Integer n = " + std::to_string(n) +
         ";\n  parameter Real m = 1, k = 100, c = 0.5;\n"
         "  coordinate Real x[n](start = {0.01*i for i in 1:n});\nmechanics\n"
         "  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);\n"
         "  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i] - x[i-1])^2 for i in 2:n);\n"
         "  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i]) - der(x[i-1]))^2 for i in 2:n);\n"
         "end Chain;\n";
}

// n independent pendulums in Cartesian coordinates: 2n coordinates, n constraints (index 3).
std::string pendulums(int n) {
  return "model Pendulums\n  parameter Integer n = " + std::to_string(n) +
         ";\n  parameter Real m = 1, g = 9.81, l = 1;\n"
         "  coordinate Real x[n](start = fill(0.6, n));\n  coordinate Real y[n](start = fill(-0.8, n));\nmechanics\n"
         "  kinetic = sum(0.5*m*(der(x[i])^2 + der(y[i])^2) for i in 1:n);\n"
         "  potential = sum(m*g*y[i] for i in 1:n);\n"
         "  for i in 1:n loop\n    constraint x[i]^2 + y[i]^2 = l^2;\n  end for;\n"
         "end Pendulums;\n";
}

template <class F> double bestSeconds(int repeat, F&& f) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  std::vector<int> sizes;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else sizes.push_back(std::atoi(argv[i]));
  }
  if (sizes.empty()) sizes = {1000, 10000, 100000};
  std::printf("| n | unknowns | edges | graph [ms] | matching [ms] | BLT [ms] | total [ms] | ns per unknown | blocks |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int n : sizes) {
    qdot::driver::Compilation c;
    if (!qdot::driver::compileSource(c, "chain.qd", chain(n), qdot::driver::Stage::Dae)) {
      std::fprintf(stderr, "structural_bench: the chain of %d did not compile\n", n);
      return 1;
    }
    const qdot::dae::Dae& d = *c.dae;
    qdot::structural::BipartiteGraph g;
    qdot::structural::Matching m;
    qdot::structural::BlockTriangularOrder blt;
    double tg = bestSeconds(repeat, [&] { g = qdot::dae::incidence(d, c.ctx); });
    double tm = bestSeconds(repeat, [&] { m = qdot::structural::maximumMatching(g); });
    double tb = bestSeconds(repeat, [&] { blt = qdot::structural::blockTriangularOrder(g, m); });
    if (!m.isPerfect()) {
      std::fprintf(stderr, "structural_bench: no perfect matching for n = %d\n", n);
      return 1;
    }
    size_t edges = 0;
    for (int e = 0; e < g.numEquations(); ++e) edges += g.variablesOf(e).size();
    double total = tg + tm + tb;
    std::printf("| %d | %zu | %zu | %.2f | %.2f | %.2f | %.2f | %.0f | %zu |\n", n, d.variables.size(), edges, tg * 1e3,
                tm * 1e3, tb * 1e3, total * 1e3, total * 1e9 / d.variables.size(), blt.blocks.size());
  }
  // Index reduction (Pantelides and the differentiation of the constraints) on n pendulums: the DAE
  // is built once without it (Stage::Dae includes it, so it is rebuilt from the flat model here).
  std::printf("\n| pendulums | unknowns after | rows after | chain structure + Pantelides + differentiation [ms] | ns per unknown |\n");
  std::printf("|---:|---:|---:|---:|---:|\n");
  for (int n : sizes) {
    if (n > 10000) continue;  // deriving more pendulums is quadratic today (mechanics stage, issue 15)
    qdot::driver::Compilation c;
    if (!qdot::driver::compileSource(c, "pendulums.qd", pendulums(n), qdot::driver::Stage::Derive)) {
      std::fprintf(stderr, "structural_bench: the %d pendulums did not compile\n", n);
      return 1;
    }
    qdot::DiagnosticEngine diags;
    std::optional<qdot::dae::Dae> base = qdot::dae::buildDae(*c.flat, *c.eom, c.ctx, diags);
    if (!base) return 1;
    qdot::dae::Dae reduced;
    double t = bestSeconds(repeat, [&] {
      reduced = *base;
      qdot::dae::reduceIndex(reduced, c.ctx, diags);
    });
    std::printf("| %d | %zu | %zu | %.2f | %.0f |\n", n, reduced.variables.size(), reduced.equations.size(), t * 1e3,
                t * 1e9 / reduced.variables.size());
  }
  return 0;
}
