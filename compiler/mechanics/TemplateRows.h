// TemplateRows: the Euler–Lagrange rows of coordinate arrays derived once per region of subscripts
// instead of once per element (issue 15, docs/loops.md). Each IndexedSum of the flat model that
// contains `x[%1+o]` or `der(x)[%1+o]` contributes, on its box shifted by +o, the derivative of its
// body by that symbol with every offset shifted by −o (so that %k is the row's own subscript).
// An IndexedForce on `x[%1+o]` contributes its body, shifted by −o, as a generalized force.
// Splitting each dimension at the ends of those boxes gives regions on which the row is one
// template. Regions of a single element, and elements that also occur in scalar terms, forces or
// constraints (peeled), are left to the scalar derivation.
#pragma once

#include <utility>
#include <vector>

#include "flatten/FlatModel.h"
#include "symbolic/Expr.h"
#include "symbolic/Simplify.h"

namespace qdot::mech {

/// The Euler–Lagrange rows of array[region], one template over the iterators %1 … %rank (the
/// row's subscripts): relative symbols of the coordinates, their velocities and accelerations.
struct TemplateRow {
  int array = -1;                             ///< ElementPatterns::arrays index (the coordinates)
  flat::Box region;                           ///< per dimension: first and last subscript
  sym::Expr residual = nullptr;               ///< d/dt(∂L/∂v) − ∂L/∂q + ∂D/∂v = 0
  sym::Expr momentum = nullptr;               ///< ∂L/∂v
};

/// One summand of the rows of a coordinate array on a box of subscripts: the derivative of an
/// IndexedSum's body by `x[%+o]` or `der(x)[%+o]`, shifted by −o (so %k is the row's subscript).
struct Contribution {
  int array = -1;  ///< the coordinates
  flat::Box box;
  /// ∂L/∂v, ∂L/∂q, ∂D/∂v, or a generalized force Q (IndexedForce; the row has −Q)
  enum class Part : uint8_t { Momentum, Position, Dissipation, Force } part = Part::Position;
  sym::Expr value = nullptr;
};

struct TemplateDerivation {
  std::vector<TemplateRow> rows;
  /// Every contribution: the scalar rows of elements outside the rows' regions (peeled) add those
  /// whose box contains them, instantiated there.
  std::vector<Contribution> contributions;
  /// IndexedSums (indices into FlatModel::indexedSums) that cannot give template rows (a body
  /// coupling an element to a scalar coordinate, or indexing coordinates other than x[%1+o, %2+p]):
  /// the caller expands them into the scalar terms.
  std::vector<int> scalarSums;
  /// IndexedForces (indices into FlatModel::indexedForces) whose body reads a scalar coordinate or
  /// velocity, or an array across its iterators: the caller makes them scalar forces.
  std::vector<int> scalarForces;
};

/// The IndexedSums and IndexedForces that cannot give template rows (TemplateDerivation::scalarSums,
/// scalarForces; no rows derived).
TemplateDerivation templatesWithoutRows(const flat::FlatModel& model, sym::Context& ctx);

/// Derives the template rows of model.indexedSums. `peeled` (by flat variable) marks coordinates
/// that also occur in scalar terms, forces or constraints: their rows stay scalar.
TemplateDerivation deriveTemplateRows(const flat::FlatModel& model, sym::Context& ctx,
                                      const std::vector<char>& peeled, sym::SimplifyLevel level);

}  // namespace qdot::mech
