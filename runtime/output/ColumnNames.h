// How result columns are named in a CSV header. Modelica's names (`der(x)`, `x[1]`, `M[1,2]`) are
// the default; some tools read a header only as identifiers (numpy.genfromtxt(names=True) deletes
// the brackets: `der(x)` becomes `derx`), so they can be asked for as identifiers instead.
#pragma once

#include <span>
#include <string>
#include <vector>

namespace qdot::rt {

enum class ColumnNaming {
  Modelica,    ///< der(x), x[1], M[1,2], a.b: as in the model and in `qdot equations`
  Identifier,  ///< der_x, x_1, M_1_2, a_b: [A-Za-z_][A-Za-z0-9_]*, unique
};

/// The names as identifiers: a name that already is one is kept; in the others '(' '[' ',' '.'
/// and any other character that cannot be in an identifier become '_' (one for a run of them),
/// ')' and ']' are dropped, so is a '_' the name would end with, and a leading digit gets a '_'
/// before it. A name that would then
/// repeat an earlier one, or `time`, gets _2, _3, … appended.
std::vector<std::string> identifierNames(std::span<const std::string> names);

}  // namespace qdot::rt
