// Test helper: compiles a model through the whole front end and evaluates its derived residuals
// with named symbol values, so tests can compare them with independently written equations.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "driver/Pipeline.h"

namespace qdot::test {

inline std::string readSource(const std::string& relative) {
  std::ifstream in(std::string(QDOT_SOURCE_DIR) + "/" + relative);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class CompiledModel {
 public:
  /// Compiles `text` (named `name` in diagnostics); fails the test with the diagnostics if it has errors.
  CompiledModel(const std::string& name, const std::string& text) {
    ok_ = driver::compileSource(c_, name, text, "", driver::Stage::Dae);
    std::ostringstream diag;
    c_.diags.render(diag, c_.sources);
    EXPECT_TRUE(ok_) << diag.str();
    values_.assign(c_.ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN());
  }
  static CompiledModel fromFile(const std::string& relative) { return CompiledModel(relative, readSource(relative)); }

  bool ok() const { return ok_; }
  driver::Compilation& compilation() { return c_; }
  const dae::Dae& dae() const { return *c_.dae; }

  /// Sets a symbol by its user-facing name: "m", "th[2]", "der(th[2])", "der(der(th[2]))".
  void set(const std::string& name, double v) {
    sym::Expr s = c_.ctx.findSymbol(name);
    ASSERT_NE(s, nullptr) << "no symbol " << name;
    values_.resize(c_.ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN());
    values_[s->symbolId] = v;
  }
  double eval(sym::Expr e) const { return sym::evaluate(e, values_); }

  /// The Euler–Lagrange residual of coordinate `q` at the current values.
  double eulerLagrange(const std::string& q) const { return eval(row(q)); }
  sym::Expr row(const std::string& q) const {
    for (size_t i = 0; i < c_.dae->rowCoordinates.size(); ++i)
      if (c_.dae->rowCoordinates[i] == q) return c_.dae->equations[i].residual;
    ADD_FAILURE() << "no coordinate " << q;
    return c_.ctx.zero();
  }
  const dae::Invariant* invariant(const std::string& name) const {
    for (const auto& inv : c_.dae->invariants)
      if (inv.name == name) return &inv;
    return nullptr;
  }

 private:
  driver::Compilation c_;
  bool ok_ = false;
  std::vector<double> values_;
};

/// |a − b| ≤ rel · scale, where scale is the magnitude of the terms that were summed.
inline ::testing::AssertionResult closeRelative(double a, double b, double scale, double rel = 1e-12) {
  if (std::fabs(a - b) <= rel * std::max(scale, 1e-300)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << " (difference " << a - b << ", allowed "
                                       << rel * scale << ")";
}

}  // namespace qdot::test
