// Printers of the derived system for `qdot equations`: readable text and JSON.
#include <ostream>

#include "dae/Dae.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <unordered_set>

namespace qdot::dae {
namespace {

std::string where(const SourceManager& sm, SourceRange r) {
  if (!r.valid()) return "";
  LineCol lc = sm.lineCol(r.file, r.begin);
  return sm.name(r.file) + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.col);
}

std::string equationText(const Equation& e, const sym::Context& ctx) {
  if (e.lhs) return sym::toString(ctx, e.lhs) + " = " + sym::toString(ctx, e.rhs);
  return sym::toString(ctx, e.residual) + " = 0";
}

std::string joinVariables(const Dae& dae, VarKind kind) {
  std::string s;
  for (const auto& v : dae.variables)
    if (v.kind == kind) s += (s.empty() ? "" : ", ") + v.name;
  return s.empty() ? "(none)" : s;
}

void printSystemSummary(std::ostream& os, const Dae& dae) {
  size_t states = dae.stateCount();
  os << "system: " << dae.equations.size() << " equations, " << dae.variables.size() << " unknowns (" << states
     << " differential, " << dae.variables.size() - states << " algebraic), " << dae.parameters.size()
     << " parameters\n";
  if (dae.differentiatedRows.empty()) return;
  // Index reduction: which links may be dropped is decided by the run (dummy derivatives).
  size_t dummies = dae.dummyDerivativeCount();
  os << "index reduction: " << dae.differentiatedRows.size() << " equation"
     << (dae.differentiatedRows.size() == 1 ? "" : "s") << " differentiated (Pantelides); the run drops " << dummies
     << " of the links der(v) = ..., choosing " << dummies << " dummy derivative" << (dummies == 1 ? "" : "s")
     << " where the differentiated equations are best conditioned (" << dummies << " of the states above become "
     << "algebraic)\n";
}

// ", differentiated twice" for an equation index reduction differentiated.
std::string differentiatedText(const flat::Origin& o) {
  switch (o.differentiated) {
    case 0: return "";
    case 1: return ", differentiated once";
    case 2: return ", differentiated twice";
    default: return ", differentiated " + std::to_string(o.differentiated) + " times";
  }
}

std::string jsonString(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else out += c;
  }
  return out + "\"";
}

// The value an explicit initial equation `v = expr` (or `expr = v`) gives v, or null.
sym::Expr initialValueOf(const Dae& dae, const Variable& v) {
  for (const auto& e : dae.initialEquations) {
    if (e.lhs == v.y && e.rhs) return e.rhs;
    if (e.rhs == v.y && e.lhs) return e.lhs;
  }
  return nullptr;
}

// The textbook's order of an Euler–Lagrange row: terms with an acceleration (the derivative
// symbol of a velocity), then with a velocity, then the rest.
std::function<int(sym::Expr)> textbookOrder(const Dae& dae, const sym::Context& ctx) {
  auto accelerations = std::make_shared<std::unordered_set<sym::Expr>>();
  auto velocities = std::make_shared<std::unordered_set<sym::Expr>>();
  for (const auto& v : dae.variables) {
    if (v.role != UnknownRole::Velocity) continue;
    velocities->insert(v.y);
    if (v.yp) accelerations->insert(v.yp);
  }
  return [accelerations, velocities, &ctx](sym::Expr term) {
    int g = 2;
    for (sym::Expr s : ctx.freeSymbols(term)) {
      if (accelerations->count(s)) return 0;
      if (velocities->count(s)) g = 1;
    }
    return g;
  };
}

}  // namespace

void printEquations(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm) {
  os << "model " << dae.name;
  if (!dae.description.empty()) os << " \"" << dae.description << "\"";
  os << "\n\n";
  if (!dae.rowCoordinates.empty()) os << "Euler-Lagrange equations (d/dt dL/dder(q) - dL/dq + dD/dder(q) = Q):\n";
  std::function<int(sym::Expr)> order = textbookOrder(dae, ctx);
  for (size_t row = 0; row < dae.rowCoordinates.size(); ++row) {
    const Equation& e = dae.equations[row];
    os << "  " << dae.rowCoordinates[row] << ":  " << sym::toStringGrouped(ctx, e.residual, order) << " = 0\n";
    os << "      (" << where(sm, e.origin.range) << ")\n";
  }
  bool header = false;
  for (const auto& e : dae.equations) {
    if (e.origin.kind == flat::OriginKind::EulerLagrange || e.origin.kind == flat::OriginKind::Kinematic) continue;
    if (!header) os << (dae.rowCoordinates.empty() ? "" : "\n") << "equations:\n";
    header = true;
    std::string origin = e.origin.kind == flat::OriginKind::Constraint ? "constraint" : "";
    origin += differentiatedText(e.origin);
    if (!origin.empty() && origin[0] == ',') origin = "equation" + origin;
    os << "  " << equationText(e, ctx) << (origin.empty() ? "" : "   (" + origin + ")") << "\n";
  }
  if (!dae.initialEquations.empty()) {
    os << "\ninitial equations:\n";
    for (const auto& e : dae.initialEquations) os << "  " << equationText(e, ctx) << "\n";
  }
  os << "\n";
  printSystemSummary(os, dae);
  os << "  states:     " << joinVariables(dae, VarKind::State) << "\n";
  os << "  algebraic:  " << joinVariables(dae, VarKind::Algebraic) << "\n";
  os << "  parameters: ";
  for (size_t i = 0; i < dae.parameters.size(); ++i)
    os << (i ? ", " : "") << dae.parameters[i].name << " = " << sym::toString(ctx, dae.parameters[i].value);
  os << (dae.parameters.empty() ? "(none)\n" : "\n");
  if (!dae.outputs.empty()) {
    os << "\noutputs:\n";
    for (const auto& o : dae.outputs) os << "  " << o.name << " = " << sym::toString(ctx, o.value) << "\n";
  }
  auto isConstraint = [](const Invariant& inv) { return inv.kind == "constraint residual"; };
  os << "\nfirst integrals:";
  if (std::all_of(dae.invariants.begin(), dae.invariants.end(), isConstraint))
    os << " none (explicit time, dissipation or non-conservative forces)";
  os << "\n";
  for (const auto& inv : dae.invariants)
    if (!isConstraint(inv)) os << "  " << inv.name << " (" << inv.kind << ", conserved) = " << sym::toString(ctx, inv.value) << "\n";
  if (std::none_of(dae.invariants.begin(), dae.invariants.end(), isConstraint)) return;
  os << "\nconstraint residuals (invariant columns, kept at 0 to the tolerance):\n";
  for (const auto& inv : dae.invariants)
    if (isConstraint(inv)) os << "  " << inv.name << " = " << sym::toString(ctx, inv.value) << "\n";
}

// A start is fixed when an initial equation sets it or `fixed = true` is written; `fixed = false`
// makes it a guess; otherwise a state's start is fixed by default (initial equations that are not
// start values may replace it: the initialization system decides, kernel stage).
bool startIsFixed(const Variable& v, sym::Expr initial) {
  if (initial) return true;
  if (v.declaration.fixedGiven) return v.declaration.fixed;
  return v.kind == VarKind::State || v.declaration.fixed;
}

void printEquationsJson(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm) {
  auto str = [&](sym::Expr e) { return jsonString(sym::toString(ctx, e)); };
  os << "{\n  \"model\": " << jsonString(dae.name) << ",\n  \"description\": " << jsonString(dae.description)
     << ",\n  \"coordinates\": [";
  for (size_t i = 0; i < dae.rowCoordinates.size(); ++i) {
    const Equation& e = dae.equations[i];
    os << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(dae.rowCoordinates[i]) << ", \"equation\": " << str(e.residual)
       << ", \"location\": " << jsonString(where(sm, e.origin.range)) << "}";
  }
  os << "\n  ],\n  \"equations\": [";
  bool first = true;
  for (const auto& e : dae.equations) {
    if (e.origin.kind == flat::OriginKind::EulerLagrange || e.origin.kind == flat::OriginKind::Kinematic) continue;
    os << (first ? "\n" : ",\n") << "    {\"residual\": " << str(e.residual) << ", \"text\": "
       << jsonString(equationText(e, ctx)) << ", \"origin\": "
       << jsonString(e.origin.kind == flat::OriginKind::Constraint   ? "constraint"
                     : e.origin.kind == flat::OriginKind::Connection ? "connection"
                                                                     : "equation")
       << ", \"location\": " << jsonString(where(sm, e.origin.range)) << "}";
    first = false;
  }
  os << "\n  ],\n  \"variables\": [";
  for (size_t i = 0; i < dae.variables.size(); ++i) {
    const Variable& v = dae.variables[i];
    sym::Expr initial = initialValueOf(dae, v);
    sym::Expr start = initial ? initial : v.declaration.start;
    os << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(v.name) << ", \"kind\": "
       << jsonString(v.kind == VarKind::State ? "state" : "algebraic") << ", \"role\": " << jsonString(roleName(v.role))
       << (start ? ", \"start\": " + str(start) : std::string())
       << (start ? std::string(", \"startFrom\": ") + (initial ? "\"initial equation\"" : "\"start\"") : std::string())
       << (start ? std::string(", \"fixed\": ") + (startIsFixed(v, initial) ? "true" : "false") : std::string())
       << "}";
  }
  os << "\n  ],\n  \"parameters\": [";
  for (size_t i = 0; i < dae.parameters.size(); ++i)
    os << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(dae.parameters[i].name)
       << ", \"value\": " << str(dae.parameters[i].value) << "}";
  os << "\n  ],\n  \"firstIntegrals\": [";
  for (size_t i = 0; i < dae.invariants.size(); ++i)
    os << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(dae.invariants[i].name) << ", \"kind\": "
       << jsonString(dae.invariants[i].kind) << ", \"value\": " << str(dae.invariants[i].value) << "}";
  os << "\n  ]\n}\n";
}

}  // namespace qdot::dae
