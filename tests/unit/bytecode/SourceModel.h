// Test helper: compiles .qd text through the pipeline to the bytecode and a VM model, keeping every
// intermediate result, and evaluates the DAE's own expressions with sym::evaluate as the reference
// the VM is compared with.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "bytecode/Emitter.h"
#include "unit/common/SourceDae.h"
#include "vm/Vm.h"

namespace qdot::test {

class SourceModel : public SourceDae {
 public:
  /// Compiles `text` (named `name` in locations) down to a VM model; fails the test on errors.
  SourceModel(const std::string& name, const std::string& text) : SourceDae(name, text, driver::Stage::Bytecode) {
    if (!dae) return;
    Result<ModelPtr> created = vm::createModel(module);
    EXPECT_TRUE(created.ok()) << created.error();
    if (created) owned = std::move(created).value(), model = owned.get();
  }
  SourceModel(const SourceModel&) = delete;
  bool ok() const { return model != nullptr; }

  /// Symbol values for sym::evaluate: y, y', p and time set, everything else NaN.
  std::vector<double> symbolValues(double t, std::span<const double> y, std::span<const double> yp,
                                   std::span<const double> p) const {
    std::vector<double> v(ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN());
    v[dae->time->symbolId] = t;
    for (size_t j = 0; j < dae->variables.size(); ++j) {
      v[dae->variables[j].y->symbolId] = y[j];
      if (dae->variables[j].yp) v[dae->variables[j].yp->symbolId] = yp[j];
    }
    for (size_t k = 0; k < dae->parameters.size(); ++k) v[dae->parameters[k].symbol->symbolId] = p[k];
    return v;
  }

  const kernel::KernelModule& kernel = compilation.kernels ? *compilation.kernels : kNoKernels;
  const bc::Module& module = compilation.bytecode ? *compilation.bytecode : kNoBytecode;
  ModelPtr owned;
  QdotModel* model = nullptr;  ///< owned.get()

 private:
  static inline const kernel::KernelModule kNoKernels{};
  static inline const bc::Module kNoBytecode{};
};

/// Distance in units in the last place (0 for equal values, huge for NaN against a number).
inline uint64_t ulpDistance(double a, double b) {
  if (a == b) return 0;
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  auto key = [](double x) {
    auto i = std::bit_cast<int64_t>(x);
    return i < 0 ? -static_cast<__int128>(i & INT64_MAX) : static_cast<__int128>(i);
  };
  __int128 d = key(a) - key(b);
  return static_cast<uint64_t>(d < 0 ? -d : d);
}

}  // namespace qdot::test

namespace qdot::test {

/// The magnitude of the terms a value is computed from: |c| + Σ|k|·mag(t) for a sum, |k|·Π mag(b)^e
/// for a product, |value| for everything else. Rounding differences between two evaluation orders
/// are bounded by a small multiple of eps times this, however much the terms cancel.
class Magnitudes {
 public:
  Magnitudes(std::span<const sym::Expr> roots) {
    std::unordered_map<sym::Expr, char> seen;
    std::vector<std::pair<sym::Expr, bool>> stack;
    for (sym::Expr r : roots) stack.emplace_back(r, false);
    while (!stack.empty()) {  // post-order, children first
      auto [e, expanded] = stack.back();
      stack.pop_back();
      if (expanded) { nodes_.push_back(e); continue; }
      if (seen.count(e)) continue;
      seen[e] = 1;
      stack.emplace_back(e, true);
      for (sym::Expr c : e->args) stack.emplace_back(c, false);
      for (sym::Expr c : e->exps()) stack.emplace_back(c, false);
    }
  }
  /// Evaluates every node at `values`; then magnitude(e) is available for the roots.
  void update(std::span<const double> values) {
    std::vector<double> v(nodes_.size());
    sym::evaluate(nodes_, values, v);
    mag_.clear();
    for (size_t i = 0; i < nodes_.size(); ++i) mag_[nodes_[i]] = magnitudeOf(nodes_[i], v[i]);
  }
  double magnitude(sym::Expr e) const { return mag_.at(e); }

 private:
  double magnitudeOf(sym::Expr e, double value) const {
    if (e->kind == sym::Kind::Add) {
      double s = std::fabs(e->value);
      for (size_t j = 0; j < e->args.size(); ++j) s += std::fabs(e->coefs()[j]) * mag_.at(e->args[j]);
      return s;
    }
    if (e->kind == sym::Kind::Mul) {
      double s = std::fabs(e->value);
      for (size_t j = 0; j < e->args.size(); ++j)
        s *= e->exps()[j]->isConstant() ? std::pow(mag_.at(e->args[j]), e->exps()[j]->value) : std::fabs(value);
      return s;
    }
    return std::fabs(value);
  }
  std::vector<sym::Expr> nodes_;
  std::unordered_map<sym::Expr, double> mag_;
};

}  // namespace qdot::test
