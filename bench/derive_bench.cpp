// Derivation benchmark: wall time from model text to the assembled DAE (parse, check, flatten,
// Euler–Lagrange, DAE) for the N-link pendulum (dense mass matrix), the spring chain (sparse) and the
// coupled pendulums (a squared sine of every angle),
// across sizes, with the growth exponent between successive sizes. Best of several repetitions.
// Usage: derive_bench [--quick] [--simplify=none|fast|full]   (run from the repository root, or set
// QDOT_SOURCE_DIR); --simplify as in qdot (default fast).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "driver/Pipeline.h"

namespace {

using namespace qdot;

sym::SimplifyLevel simplifyLevel = sym::SimplifyLevel::Fast;

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "cannot read %s (run from the repository root)\n", path.c_str());
    std::exit(2);
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Sample {
  double total = 1e300;
  driver::StageTimes stages;
  size_t equations = 0;
  size_t dagNodes = 0;
};

Sample measure(const std::string& text, int repetitions) {
  Sample best;
  for (int r = 0; r < repetitions; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    driver::Compilation c;
    c.options.simplify = simplifyLevel;
    bool ok = driver::compileSource(c, "bench.qd", text, "", driver::Stage::Dae);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!ok) {
      c.diags.render(std::cerr, c.sources);
      std::exit(1);
    }
    if (seconds < best.total) {
      best.total = seconds;
      best.stages = c.times;
      best.equations = c.dae->equations.size();
      std::vector<sym::Expr> roots;
      for (const auto& e : c.dae->equations) roots.push_back(e.residual);
      best.dagNodes = c.ctx.dagSize(roots);
    }
  }
  return best;
}

void runSeries(const char* title, const std::string& file, const std::vector<int>& sizes, double budgetSeconds) {
  std::string source = readFile(file);
  std::printf("\n### %s (`%s`)\n\n", title, file.c_str());
  std::printf("| n | equations | DAG nodes | total [ms] | parse+check | flatten | derive | dae | growth exponent |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  double prevN = 0, prevT = 0;
  for (int n : sizes) {
    std::string text = std::regex_replace(source, std::regex("parameter Integer n = [0-9]+"),
                                          "parameter Integer n = " + std::to_string(n));
    int reps = prevT > 0.5 ? 1 : prevT > 0.05 ? 3 : 7;
    Sample s = measure(text, reps);
    const auto& t = s.stages;
    std::printf("| %d | %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | ", n, s.equations, s.dagNodes, s.total * 1e3,
                (t.parse + t.check) * 1e3, t.flatten * 1e3, t.derive * 1e3, t.dae * 1e3);
    if (prevN > 0) std::printf("%.2f |\n", std::log(s.total / prevT) / std::log(n / prevN));
    else std::printf("– |\n");
    std::fflush(stdout);
    prevN = n, prevT = s.total;
    if (s.total > budgetSeconds) break;
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string level = "fast";
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--quick") quick = true;
    else if (a.rfind("--simplify=", 0) == 0 && sym::parseSimplifyLevel(a.substr(11), simplifyLevel)) level = a.substr(11);
    else return std::fprintf(stderr, "usage: derive_bench [--quick] [--simplify=none|fast|full]\n"), 2;
  }
  const char* root = std::getenv("QDOT_SOURCE_DIR");
  std::string dir = root ? std::string(root) + "/" : "";
  std::printf("## Derivation: model text to DAE (best of several runs), --simplify=%s\n", level.c_str());
  runSeries("N-link pendulum, dense", dir + "examples/pendulum/nlink.qd",
            quick ? std::vector<int>{2, 4, 8, 16} : std::vector<int>{2, 4, 8, 16, 32, 64}, 30);
  runSeries("Spring–damper chain, sparse", dir + "examples/vibration/spring_chain.qd",
            quick ? std::vector<int>{10, 100, 1000} : std::vector<int>{10, 100, 1000, 10000, 100000}, 60);
  runSeries("Coupled pendulums, sin² of every angle (the simplifier's Pythagorean rewrites)",
            dir + "examples/pendulum/coupled_pendulums.qd",
            quick ? std::vector<int>{10, 100, 1000} : std::vector<int>{10, 100, 1000, 4000}, 60);
  return 0;
}
