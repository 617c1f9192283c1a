// `qdot linearize` output: CSV blocks (a header row of names, then one row per state or output),
// or one JSON object. Numbers in shortest round-trip form, so the matrices can be read back exactly.
#include <ostream>

#include "linear/Linearize.h"
#include "qdot/number_text.hpp"

namespace qdot::linear {
namespace {

// A CSV field: quoted when the name has a comma or a quote (array elements such as "M[1,2]").
std::string field(const std::string& s) {
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double x) { return shortestText(x == 0 ? 0.0 : x); }

// "title,column names..." then "row name,values..." for every row, then a blank line.
void block(std::ostream& os, const std::string& title, const std::vector<std::string>& rows,
           const std::vector<std::string>& columns, const Eigen::MatrixXd& values) {
  os << title;
  for (const auto& c : columns) os << ',' << field(c);
  os << '\n';
  for (size_t i = 0; i < rows.size(); ++i) {
    os << field(rows[i]);
    for (size_t j = 0; j < columns.size(); ++j) os << ',' << number(values(i, j));
    os << '\n';
  }
}

std::string pointText(const LinearModel& m) {
  std::string at = m.equilibrium ? "the static equilibrium" : "the start state";
  return at + " at t = " + number(m.time);
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

std::string jsonNames(const std::vector<std::string>& names) {
  std::string out = "[";
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + jsonString(names[i]);
  return out + "]";
}

std::string jsonRow(const Eigen::MatrixXd& M, Eigen::Index i) {
  std::string out = "[";
  for (Eigen::Index j = 0; j < M.cols(); ++j) out += (j ? ", " : "") + number(M(i, j));
  return out + "]";
}

std::string jsonMatrix(const Eigen::MatrixXd& M) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < M.rows(); ++i) out += (i ? ", " : "") + jsonRow(M, i);
  return out + "]";
}

// x* as a one-row matrix.
Eigen::MatrixXd pointRow(const LinearModel& m) {
  return Eigen::Map<const Eigen::RowVectorXd>(m.statePoint.data(), static_cast<Eigen::Index>(m.statePoint.size()));
}

}  // namespace

void printStateSpace(std::ostream& os, const LinearModel& m) {
  const StateSpace& s = m.stateSpace;
  os << "# der(x) = A x + B u, y = C x + D u in deviations from " << pointText(m) << "\n";
  block(os, "point", {"value"}, s.states, pointRow(m));
  os << '\n';
  block(os, "A", s.states, s.states, s.A);
  os << '\n';
  block(os, "B", s.states, s.inputs, s.B);
  if (s.outputs.empty()) return;
  os << '\n';
  block(os, "C", s.outputs, s.states, s.C);
  os << '\n';
  block(os, "D", s.outputs, s.inputs, s.D);
}

void printStateSpaceJson(std::ostream& os, const LinearModel& m) {
  const StateSpace& s = m.stateSpace;
  os << "{\"states\": " << jsonNames(s.states) << ", \"inputs\": " << jsonNames(s.inputs)
     << ", \"outputs\": " << jsonNames(s.outputs) << ", \"A\": " << jsonMatrix(s.A) << ", \"B\": " << jsonMatrix(s.B)
     << ", \"C\": " << jsonMatrix(s.C) << ", \"D\": " << jsonMatrix(s.D) << ", \"point\": " << jsonRow(pointRow(m), 0)
     << ", \"equilibrium\": " << (m.equilibrium ? "true" : "false") << ", \"time\": " << number(m.time) << "}\n";
}

}  // namespace qdot::linear
