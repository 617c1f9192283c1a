// Mechanics: derives the equations of motion of a FlatModel (spec §5).
// For every coordinate q with velocity v = der(q):
//   d/dt(∂L/∂v) − ∂L/∂q + ∂D/∂v − Q_q − Σ_k λ_k ∂g_k/∂q = 0,   L = T − V,
// with d/dt expanded by the chain rule (q → v, v → der(v), explicit time), so each row is linear in
// the accelerations. Also finds the first integrals (cyclic momenta, the Jacobi integral).
// Costs grow with the size of the energies: derivatives are taken only of the energy terms that
// contain the coordinate (an index from symbols to terms), never of the whole Lagrangian.
// Energies with trigonometric terms are simplified first (sin² + cos² = 1, angle sums), so a
// Lagrangian written with Cartesian positions has the same terms as the textbook's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "flatten/FlatModel.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"
#include "mechanics/TemplateRows.h"
#include "symbolic/Simplify.h"

namespace qdot::mech {

/// The Euler–Lagrange row of one coordinate.
struct CoordinateRow {
  int coordinate = -1;         ///< flat variable index of q
  sym::Expr residual = nullptr;  ///< = 0
  sym::Expr momentum = nullptr;  ///< generalized momentum p = ∂L/∂v
  /// False when T does not contain der(q) (no inertia): the row then determines der(q) (if D or a
  /// force contains it: a first-order coordinate) or q itself (a massless node, spec §7).
  bool inertial = true;
  /// ≥ 0: the row is EquationsOfMotion::templateRows[templateRow] at this coordinate's element
  /// (residual and momentum are then null: the template stands for them).
  int templateRow = -1;
};

struct Multiplier {
  std::string name;  ///< "lambda[1]"
  sym::Expr symbol = nullptr;
  int constraint = -1;  ///< index into FlatModel::constraints
};

struct FirstIntegral {
  enum class Kind { CyclicMomentum, Jacobi };
  Kind kind = Kind::Jacobi;
  int coordinate = -1;  ///< CyclicMomentum: the cyclic coordinate
  std::string name;     ///< "p(phi)" or "jacobi"
  sym::Expr value = nullptr;
  /// Added to `value`: sums over every element of coordinate arrays (the Jacobi integral of a
  /// templated model: one per energy sum), computed by loops.
  std::vector<flat::IndexedTerm> sums;
};

struct EquationsOfMotion {
  std::vector<CoordinateRow> rows;  ///< one per coordinate, in declaration order
  /// Rows of coordinate arrays derived once per region (issue 15, TemplateRows.h): only when the
  /// flat model keeps IndexedSums. Their coordinates' rows point here.
  std::vector<TemplateRow> templateRows;
  std::vector<Multiplier> multipliers;
  std::vector<FirstIntegral> integrals;
  sym::Expr kinetic = nullptr, potential = nullptr, dissipation = nullptr;  ///< totals T, V, D
};

/// Derives the rows; with IndexedSums in the model (flattened with FlattenLimits::keepLoops), the
/// rows of coordinate arrays per region as templates and the peeled elements' rows as scalars, and
/// the Jacobi integral as scalar terms plus one sum per energy sum (FirstIntegral::sums). Reports located errors (E04xx) and returns nullopt on failure. At `simplify`
/// (sym/Simplify.h) the energies are simplified before they are differentiated (so cyclic
/// coordinates and time-independence are judged on the simplified Lagrangian), and the rows, the
/// momenta and the first integrals after.
std::optional<EquationsOfMotion> deriveEquationsOfMotion(const flat::FlatModel& model, sym::Context& ctx,
                                                         DiagnosticEngine& diags,
                                                         sym::SimplifyLevel simplify = sym::SimplifyLevel::Fast);

}  // namespace qdot::mech
