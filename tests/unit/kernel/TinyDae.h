// Test helper: small DAEs built by hand (no front end), so the kernel stage is tested alone.
//   Tiny: one coordinate x with velocity v = der(x), parameters m and k = 2*m (declared first),
//   F0 = m*der(v) + sin(x)*v (Euler-Lagrange row), F1 = $der(x) - v (kinematic row).
#pragma once

#include <gtest/gtest.h>

#include <limits>

#include "kernel/Kernel.h"
#include "support/Diagnostic.h"

namespace qdot::test {

struct TinyDae {
  sym::Context ctx;
  dae::Dae dae;
  DiagnosticEngine diags;  ///< what buildKernels reports
  sym::Expr t = ctx.symbol("time"), x = ctx.symbol("x"), v = ctx.symbol("der(x)"), dx = ctx.symbol("$der(x)"),
            a = ctx.symbol("der(der(x))"), k = ctx.symbol("k"), m = ctx.symbol("m");

  TinyDae() {
    dae.name = "Tiny";
    dae.time = t;
    dae.variables.push_back({.name = "x", .kind = dae::VarKind::State, .role = dae::UnknownRole::Coordinate, .flatVar = 1,
                             .y = x, .yp = dx, .declaration = {.start = ctx.mul(ctx.constant(0.5), k)}});
    dae.variables.push_back({.name = "der(x)", .kind = dae::VarKind::State, .role = dae::UnknownRole::Velocity, .flatVar = 2,
                             .y = v, .yp = a, .declaration = {.start = ctx.zero()}});
    dae.parameters.push_back({.name = "k", .symbol = k, .value = ctx.mul(ctx.constant(2), m)});
    dae.parameters.push_back({.name = "m", .symbol = m, .value = ctx.constant(1.5)});
    dae.coordinates = {0};
    addEquation(ctx.add(ctx.mul(m, a), ctx.mul(sin(x), v)), flat::OriginKind::EulerLagrange, 1);
    addEquation(ctx.sub(dx, v), flat::OriginKind::Kinematic, 1);
  }
  sym::Expr sin(sym::Expr e) { return ctx.unary(sym::Kind::Sin, e); }
  sym::Expr cos(sym::Expr e) { return ctx.unary(sym::Kind::Cos, e); }
  void addEquation(sym::Expr residual, flat::OriginKind kind = flat::OriginKind::Equation, int variable = -1) {
    dae::Equation e;
    e.residual = residual;
    e.origin.kind = kind;
    e.origin.variable = variable;
    dae.equations.push_back(e);
  }
  /// Symbol values for sym::evaluate (NaN for everything not given).
  std::vector<double> values(std::initializer_list<std::pair<sym::Expr, double>> given) const {
    std::vector<double> out(ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN());
    for (auto [s, value] : given) out[s->symbolId] = value;
    return out;
  }
};

}  // namespace qdot::test
