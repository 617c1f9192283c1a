// Components, connectors and packages (spec §7) from .qd text through the whole pipeline: modifiers
// reach the parameters and starts they name, packages and imports find the classes they name,
// QDOT_PATH finds user libraries, and connected parts move as the physics of the connected system
// says (closed forms named in each test). The located errors of connector misuse are in the
// diagnostics corpus (component_rules.qd, component_modifiers.qd, component_parameter.qd, connections.qd,
// connect_in_loop.qd, connect_index_out_of_range.qd, fixed_twice.qd). Tests of a known bug are
// skipped with the bug named.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <span>

#include "CompiledModel.h"
#include "driver/Backends.h"
#include "driver/Modes.h"
#include "output/ResultSink.h"
#include "sim/RunOptions.h"
#include "sim/Simulation.h"

namespace qdot::test {
namespace {

namespace fs = std::filesystem;

// The rows of a run, by column name.
struct Trajectory : rt::ResultSink {
  std::vector<std::string> names;
  std::vector<double> times;
  std::vector<std::vector<double>> rows;
  std::map<std::string, double> parameters;  // the run's parameter values by name
  bool ok = false;

  void begin(std::span<const std::string> columns) override { names.assign(columns.begin(), columns.end()); }
  void row(double t, std::span<const double> values) override {
    times.push_back(t);
    rows.emplace_back(values.begin(), values.end());
  }
  void finish() override {}

  bool has(const std::string& name) const { return std::find(names.begin(), names.end(), name) != names.end(); }
  std::vector<double> col(const std::string& name) const {
    auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      ADD_FAILURE() << "no column " << name << "; columns: " << columnList();
      return std::vector<double>(times.size(), std::nan(""));
    }
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r[it - names.begin()]);
    return out;
  }
  double parameter(const std::string& name) const {
    auto it = parameters.find(name);
    if (it != parameters.end()) return it->second;
    ADD_FAILURE() << "no parameter " << name;
    return std::nan("");
  }
  std::string columnList() const {
    std::string s;
    for (const auto& n : names) s += n + " ";
    return s;
  }
};

std::string rendered(driver::Compilation& c) {
  std::ostringstream os;
  c.diags.render(os, c.sources);
  return os.str();
}

// Compiles `text` and integrates it on the bytecode VM from 0 to `stop`, a row every `interval`.
std::unique_ptr<Trajectory> simulate(double stop, double interval, const std::string& text) {
  auto out = std::make_unique<Trajectory>();
  driver::Compilation c;
  if (!driver::compileSource(c, "components.qd", text, "", driver::Stage::Kernel)) {
    ADD_FAILURE() << rendered(c);
    return out;
  }
  driver::RunnableModel m = driver::makeRunnableModel(c, driver::Backend::Bytecode, false);
  if (!m.model) {
    ADD_FAILURE() << m.error;
    return out;
  }
  rt::SimulationSettings s;
  s.stop = stop;
  s.interval = interval;
  s.rtol = 1e-9;  // tight enough for the 1e-6 bounds on closed forms
  s.parameters = rt::evaluateParameters(*m.model, rt::parameterOverrides(*m.model, {}));
  for (uint32_t i = 0; i < m.model->nParameters; ++i) out->parameters[m.model->parameterNames[i]] = s.parameters[i];
  rt::SimulationResult r = rt::simulate(*m.model, s, *out);
  EXPECT_TRUE(r.success) << r.message;
  out->ok = r.success;
  return out;
}

// The largest |a[k] − b[k]| (NaN if any is NaN, so a broken run cannot pass a bound).
double maxDifference(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_FALSE(a.empty());
  double worst = 0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k)
    if (double d = std::fabs(a[k] - b[k]); !(d <= worst)) worst = d;
  return worst;
}

// The largest |x[k] − f(t[k])|.
template <class F>
double maxError(const Trajectory& r, const std::string& column, F f) {
  std::vector<double> x = r.col(column), want;
  for (double t : r.times) want.push_back(f(t));
  return maxDifference(x, want);
}

// ---------------------------------------------------------------------------------------- modifiers

TEST(ComponentModifiers, ValueAndAttributeModifiersReachParameterAndStart) {
  // m s'' = −k s, s(0) = 0.1: s = 0.1 cos(√(k/m) t) with m = 2, k = 50: ω = 5.
  auto r = simulate(2, 0.01, R"(
model M
  import Vibration.*;
  Fixed w;
  Spring k1(k = 50);
  Mass m1(m = 2, s(start = 0.1, fixed = true));
equation
  connect(w.a, k1.a);
  connect(k1.b, m1.a);
end M;)");
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->parameter("m1.m"), 2);
  EXPECT_EQ(r->parameter("k1.k"), 50);
  EXPECT_EQ(r->col("m1.s").front(), 0.1);
  EXPECT_LT(maxError(*r, "m1.s", [](double t) { return 0.1 * std::cos(5 * t); }), 1e-6);
}

TEST(ComponentModifiers, NestedModifiersReachThePartsOfAComposite) {
  auto r = simulate(0.1, 0.05, R"(
model TwoMass
  import Vibration.*;
  Mass m1, m2;
  Spring k(k = 10);
equation
  connect(m1.b, k.a);
  connect(k.b, m2.a);
end TwoMass;
model Top
  TwoMass t(m1(m = 3, s(start = 0.2)), k(k = 40));
end Top;)");
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->parameter("t.m1.m"), 3);
  EXPECT_EQ(r->parameter("t.m2.m"), 1);  // the library default
  EXPECT_EQ(r->parameter("t.k.k"), 40);
  EXPECT_EQ(r->col("t.m1.s").front(), 0.2);
}

TEST(ComponentModifiers, ArraysOfComponentsTakeArrayAndScalarModifiers) {
  auto r = simulate(0.1, 0.05, R"(
model Arrays
  import Vibration.*;
  Mass ms[3](m = {1, 2, 3});
  Mass ns[2](m = 5);
end Arrays;)");
  ASSERT_TRUE(r->ok);
  for (int i = 1; i <= 3; ++i) EXPECT_EQ(r->parameter("ms[" + std::to_string(i) + "].m"), i);
  for (int i = 1; i <= 2; ++i) EXPECT_EQ(r->parameter("ns[" + std::to_string(i) + "].m"), 5);
}

TEST(ComponentModifiers, ArrayModifierOfTheWrongSizeIsOneLocatedError) {
  driver::Compilation c;
  driver::compileSource(c, "components.qd", "model Arr\n  import Vibration.*;\n  Mass ms[2](m = {1, 2, 3});\nend Arr;",
                        "", driver::Stage::Dae);
  ASSERT_EQ(c.diags.diagnostics().size(), 1u) << rendered(c);
  const Diagnostic& d = c.diags.diagnostics().front();
  EXPECT_EQ(d.code, DiagCode::E0307);
  LineCol at = c.sources.lineCol(d.range.file, d.range.begin);
  EXPECT_EQ(at.line, 3u);
  EXPECT_EQ(at.col, 18u);
  EXPECT_NE((d.message + d.help).find("[2]"), std::string::npos) << rendered(c);
}

TEST(ComponentModifiers, ArraysOfCompositesSplitNestedArrayModifiers) {
  auto r = simulate(0.1, 0.05, R"(
model Cell
  import Vibration.*;
  Flange a, b;
  Spring k;
  Mass m;
equation
  connect(a, k.a);
  connect(k.b, m.a);
  connect(m.b, b);
end Cell;
model Cells
  Cell cs[3](k(k = {10, 20, 30}), m(s(start = {0.1, 0.2, 0.3})));
end Cells;)");
  ASSERT_TRUE(r->ok);
  for (int i = 1; i <= 3; ++i) {
    std::string c = "cs[" + std::to_string(i) + "]";
    EXPECT_EQ(r->parameter(c + ".k.k"), 10 * i);
    EXPECT_NEAR(r->col(c + ".m.s").front(), 0.1 * i, 1e-15);
  }
}

TEST(ComponentModifiers, ExtendsModifierOverridesABaseParameter) {
  // x'' = −(k/m) x, x(0) = 1 with k = 4 (not the base's 100): x = cos(2t).
  auto r = simulate(3, 0.01, R"(
model Base
  parameter Real k = 100;
  parameter Real m = 1;
  coordinate Real x(start = 1);
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
end Base;
model Derived
  extends Base(k = 4);
end Derived;)");
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->parameter("k"), 4);
  EXPECT_LT(maxError(*r, "x", [](double t) { return std::cos(2 * t); }), 1e-6);
}

TEST(ComponentModifiers, ExtendsInheritsEquationsAndMechanics) {
  // The derived model adds a spring to the base's: x'' = −(k + k2) x = −9 x, x = cos(3t); the base's
  // equation y = 2 x holds in the derived model.
  auto r = simulate(3, 0.01, R"(
model Base
  parameter Real k = 5;
  coordinate Real x(start = 1);
  Real y;
mechanics
  kinetic = 0.5*der(x)^2;
  potential = 0.5*k*x^2;
equation
  y = 2*x;
end Base;
model Derived
  extends Base;
  parameter Real k2 = 4;
mechanics
  potential = 0.5*k2*x^2;
end Derived;)");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "x", [](double t) { return std::cos(3 * t); }), 1e-6);
  std::vector<double> twiceX = r->col("x");
  for (double& v : twiceX) v *= 2;
  EXPECT_LT(maxDifference(r->col("y"), twiceX), 1e-7);  // y is an algebraic unknown: solved to the Newton tolerance
}

TEST(ComponentModifiers, ExtendsModifiesThePartsOfTheBase) {
  // m s'' = −k s with m = 4, k = 36 (not the base's 1 and 100): s = 0.1 cos(3t).
  auto r = simulate(2, 0.01, R"(
model Base
  Vibration.Mass m1(s(start = 0.1));
  Vibration.Spring k(k = 100);
  Vibration.Fixed w;
equation
  connect(w.a, k.a);
  connect(k.b, m1.a);
end Base;
model Derived
  extends Base(m1(m = 4), k(k = 36));
end Derived;)");
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->parameter("m1.m"), 4);
  EXPECT_EQ(r->parameter("k.k"), 36);
  EXPECT_LT(maxError(*r, "m1.s", [](double t) { return 0.1 * std::cos(3 * t); }), 1e-6);
}

// ----------------------------------------------------------------------------------------- packages

// A package A.B with an oscillator M (x'' = −w² x, x(0) = 1: x = cos(3t)), then `use`.
std::string withPackage(const std::string& use) {
  return R"(
package A
  package B
    model M
      parameter Real w = 3;
      coordinate Real x(start = 1);
    mechanics
      kinetic = 0.5*der(x)^2;
      potential = 0.5*w^2*x^2;
    end M;
  end B;
end A;
)" + use;
}

void expectOscillator(const std::string& text, const std::string& column) {
  auto r = simulate(2, 0.01, text);
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, column, [](double t) { return std::cos(3 * t); }), 1e-6);
}

TEST(Packages, ImportOfOneClassOfANestedPackage) {
  expectOscillator(withPackage("model Use\n  import A.B.M;\n  M c;\nend Use;"), "c.x");
}

TEST(Packages, ImportOfEveryClassOfANestedPackage) {
  expectOscillator(withPackage("model Use\n  import A.B.*;\n  M c;\nend Use;"), "c.x");
}

TEST(Packages, RenamingImport) {
  expectOscillator(withPackage("model Use\n  import Short = A.B;\n  Short.M c;\nend Use;"), "c.x");
}

TEST(Packages, FileLevelImportServesTheModel) {
  expectOscillator(withPackage("import A.B.*;\nmodel Use\n  M c;\nend Use;"), "c.x");
}

TEST(Packages, DottedTypeNameWithoutImport) {
  expectOscillator(withPackage("model Use\n  A.B.M c(w = 3);\nend Use;"), "c.x");
}

TEST(Packages, ClassInTheModelFileShadowsTheLibrary) {
  // This file's own Vibration.Mass has a parameter `mass` (the library's has `m`) and no flanges.
  auto r = simulate(2, 0.01, R"(
package Vibration
  model Mass
    parameter Real mass = 7;
    coordinate Real s(start = 1);
  mechanics
    kinetic = 0.5*mass*der(s)^2;
    potential = 0.5*s^2;
  end Mass;
end Vibration;
model Use
  Vibration.Mass b(mass = 4);
end Use;)");
  ASSERT_TRUE(r->ok);
  EXPECT_EQ(r->parameter("b.mass"), 4);
  EXPECT_LT(maxError(*r, "b.s", [](double t) { return std::cos(0.5 * t); }), 1e-6);  // ω = √(1/4)
}

TEST(Packages, ImportNamingNoClassIsReported) {
  driver::Compilation c;
  driver::compileSource(c, "components.qd",
                        "model Use\n  import Vibration.Nope;\n  import NoPkg.*;\n"
                        "  Vibration.Mass m1;\nend Use;",
                        "", driver::Stage::Check);
  ASSERT_EQ(c.diags.diagnostics().size(), 2u) << rendered(c);
  for (size_t i = 0; i < 2; ++i) {
    const Diagnostic& d = c.diags.diagnostics()[i];
    EXPECT_EQ(d.code, DiagCode::E0220);
    EXPECT_EQ(c.sources.lineCol(d.range.file, d.range.begin).line, 2 + i);
  }
}

// --------------------------------------------------------------------------------------- QDOT_PATH

// A fresh directory, removed with everything in it; QDOT_PATH set to it while the object lives.
class LibraryDirectory {
 public:
  LibraryDirectory() {
    std::string pattern = (fs::temp_directory_path() / "qdot_lib_XXXXXX").string();
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    EXPECT_NE(mkdtemp(buf.data()), nullptr);
    dir_ = buf.data();
    const char* old = std::getenv("QDOT_PATH");
    if (old) old_ = old;
    hadOld_ = old != nullptr;
    setenv("QDOT_PATH", dir_.c_str(), 1);
  }
  ~LibraryDirectory() {
    if (hadOld_)
      setenv("QDOT_PATH", old_.c_str(), 1);
    else
      unsetenv("QDOT_PATH");
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void write(const std::string& relative, const std::string& text) const {
    fs::create_directories((fs::path(dir_) / relative).parent_path());
    std::ofstream(fs::path(dir_) / relative) << text;
  }
  const std::string& path() const { return dir_; }

 private:
  std::string dir_, old_;
  bool hadOld_ = false;
};

TEST(LibraryPath, UserLibraryOnQdotPathIsFound) {
  LibraryDirectory lib;
  lib.write("MyLib/package.qd", R"(
package MyLib
  model Osc
    parameter Real w = 3;
    coordinate Real x(start = 1);
  mechanics
    kinetic = 0.5*der(x)^2;
    potential = 0.5*w^2*x^2;
  end Osc;
end MyLib;
)");
  lib.write("Single.qd", R"(
package Single
  model Twice
    parameter Real w = 2;
    coordinate Real x(start = 1);
  mechanics
    kinetic = 0.5*der(x)^2;
    potential = 0.5*w^2*x^2;
  end Twice;
end Single;
)");
  auto r = simulate(2, 0.01, "model Use\n  import MyLib.*;\n  Osc a;\n  Single.Twice b;\nend Use;");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "a.x", [](double t) { return std::cos(3 * t); }), 1e-6);
  EXPECT_LT(maxError(*r, "b.x", [](double t) { return std::cos(2 * t); }), 1e-6);
}

TEST(LibraryPath, UserLibraryComesBeforeTheStandardLibrary) {
  LibraryDirectory lib;  // its Vibration.Mass has a parameter `mass` (the standard one has `m`)
  lib.write("Vibration/package.qd", R"(
package Vibration
  model Mass
    parameter Real mass = 7;
    coordinate Real s(start = 1);
  mechanics
    kinetic = 0.5*mass*der(s)^2;
    potential = 0.5*s^2;
  end Mass;
end Vibration;
)");
  auto r = simulate(2, 0.01, "model Use\n  import Vibration.*;\n  Mass b(mass = 4);\nend Use;");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "b.s", [](double t) { return std::cos(0.5 * t); }), 1e-6);
}

TEST(LibraryPath, TheModelsOwnFolderIsSearched) {
  LibraryDirectory folder;
  unsetenv("QDOT_PATH");  // only the folder of the model file
  folder.write("Local/package.qd", R"(
package Local
  model Osc
    coordinate Real x(start = 1);
  mechanics
    kinetic = 0.5*der(x)^2;
    potential = 2*x^2;
  end Osc;
end Local;
)");
  folder.write("model.qd", "model Use\n  Local.Osc o;\nend Use;\n");
  driver::Compilation c;
  EXPECT_TRUE(driver::compileFile(c, folder.path() + "/model.qd", driver::Stage::Dae)) << rendered(c);
}

TEST(LibraryPath, MissingPackageListsTheDirectoriesSearched) {
  LibraryDirectory lib;
  driver::Compilation c;
  EXPECT_FALSE(
      driver::compileSource(c, "components.qd", "model Use\n  NoSuchLib.Mass m;\nend Use;", "", driver::Stage::Check));
  ASSERT_EQ(c.diags.diagnostics().size(), 1u) << rendered(c);
  const Diagnostic& d = c.diags.diagnostics().front();
  EXPECT_EQ(d.code, DiagCode::E0220);
  EXPECT_EQ(d.message, "unknown class 'NoSuchLib.Mass'");
  LineCol at = c.sources.lineCol(d.range.file, d.range.begin);
  EXPECT_EQ(at.line, 2u);
  EXPECT_EQ(at.col, 3u);
  EXPECT_NE(d.help.find("searched: " + lib.path() + ", "), std::string::npos) << d.help;
  EXPECT_NE(d.help.find("stdlib"), std::string::npos) << d.help;
}

// ------------------------------------------------------------------------------------- connections

TEST(Connections, ConnectInsideForLoopsBuildsTheChain) {
  // Three unit masses between walls, four springs k = 100, connected by a loop; the same chain written
  // flat (m x_i'' = k (x_{i−1} − 2 x_i + x_{i+1})) must give the same trajectories.
  auto chain = simulate(2, 0.01, R"(
model Chain
  import Vibration.*;
  Fixed w1, w2;
  Mass ms[3](s(start = {0.1, 0, -0.05}));
  Spring ks[4](k = 100);
equation
  connect(w1.a, ks[1].a);
  connect(ks[1].b, ms[1].a);
  for i in 2:3 loop
    connect(ms[i - 1].b, ks[i].a);
    connect(ks[i].b, ms[i].a);
  end for;
  connect(ms[3].b, ks[4].a);
  connect(ks[4].b, w2.a);
end Chain;)");
  auto flat = simulate(2, 0.01, R"(
model Flat
  coordinate Real x[3](start = {0.1, 0, -0.05});
mechanics
  kinetic = 0.5*(der(x[1])^2 + der(x[2])^2 + der(x[3])^2);
  potential = 50*(x[1]^2 + (x[2] - x[1])^2 + (x[3] - x[2])^2 + x[3]^2);
end Flat;)");
  ASSERT_TRUE(chain->ok && flat->ok);
  for (int i = 1; i <= 3; ++i) {
    std::string k = std::to_string(i);
    EXPECT_LT(maxDifference(chain->col("ms[" + k + "].s"), flat->col("x[" + k + "]")), 1e-6) << i;
  }
}

TEST(Connections, ConnectLoopsOverAnIntegerParameterGiveTheChainsModes) {
  // n unit masses hung in a row from a wall by springs k = 100, the last end free:
  // ω_j = 2 √(k/m) sin((2j − 1) π / (2 (2n + 1))), j = 1..n; with n = 4 set as a structural -p.
  driver::Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "chain.qd", R"(
model Chain
  import Vibration.*;
  parameter Integer n = 2;
  Fixed w;
  Mass ms[n];
  Spring ks[n](k = 100);
equation
  connect(w.a, ks[1].a);
  for i in 1:n loop
    connect(ks[i].b, ms[i].a);
  end for;
  for i in 1:n - 1 loop
    connect(ms[i].b, ks[i + 1].a);
  end for;
end Chain;)",
                                    "", driver::Stage::Check))
      << rendered(c);
  std::vector<std::string> assignments{"n=4"};
  ASSERT_EQ(driver::takeStructuralParameters(c, assignments), "");
  ASSERT_TRUE(driver::continueTo(c, driver::Stage::Kernel)) << rendered(c);
  driver::ModesResult r = driver::computeModes(c, assignments, linear::OperatingPoint::Equilibrium);
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 4u);
  for (int j = 1; j <= 4; ++j) {
    double omega = 20 * std::sin((2 * j - 1) * std::numbers::pi / 18);
    EXPECT_NEAR(r.modes[j - 1].omega, omega, 1e-8 * omega) << j;
  }
}

TEST(Connections, UnconnectedFlangeCarriesNoForce) {
  // A constant force F = 2 on m1.a, m1.b left open: m s'' = F, s = F t² / (2 m) with m = 4.
  auto r = simulate(2, 0.01, R"(
model Open
  import Vibration.*;
  Force f(F = 2);
  Mass m1(m = 4);
equation
  connect(f.a, m1.a);
end Open;)");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "m1.s", [](double t) { return 0.25 * t * t; }), 1e-7);
  EXPECT_EQ(maxError(*r, "m1.b.f", [](double) { return 0.0; }), 0);
  EXPECT_EQ(maxError(*r, "m1.a.f", [](double) { return 2.0; }), 0);  // the force arrives through a
}

TEST(Connections, MasslessNodeBetweenSpringsIsAlgebraic) {
  // wall —k1— node —k2— mass ← F, a damper from the wall to the mass settles it. The node has no
  // inertia: only the mass's position and velocity are states. Statically the springs are in series,
  // k = k1 k2 / (k1 + k2) = 80: s = F / k, and the node sits at F / k1.
  const std::string text = R"(
model Series
  import Vibration.*;
  Fixed w;
  Spring k1(k = 100), k2(k = 400);
  Damper c(c = 20);
  Mass m1(m = 1);
  Force f(F = 8);
equation
  connect(w.a, k1.a);
  connect(k1.b, k2.a);
  connect(k2.b, m1.a);
  connect(w.a, c.a);
  connect(c.b, m1.b);
  connect(f.a, m1.b);
end Series;)";
  CompiledModel m("series.qd", text);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m.dae().stateCount(), 2u);
  EXPECT_GT(m.dae().variables.size(), 2u);  // the node's position is an algebraic unknown
  auto r = simulate(8, 0.5, text);
  ASSERT_TRUE(r->ok);
  EXPECT_NEAR(r->col("m1.s").back(), 8.0 / 80.0, 1e-8);
  EXPECT_NEAR(r->col("k1.b.s").back(), 8.0 / 100.0, 1e-8);  // the node, named by its first connector
  EXPECT_NEAR(r->col("k2.b.f").back(), 8.0, 1e-8);          // the stretched spring k2 e = F
}

TEST(Connections, OutsideConnectorsOfACompositeActLikeItsParts) {
  // A cell (spring then mass) with its own flanges a and b, two cells chained to a wall, against the
  // same springs and masses connected at the top level.
  auto composite = simulate(3, 0.01, R"(
model Cell
  import Vibration.*;
  Flange a, b;
  Spring k(k = 100);
  Mass m(m = 1);
equation
  connect(a, k.a);
  connect(k.b, m.a);
  connect(m.b, b);
end Cell;
model Composite
  Vibration.Fixed w;
  Cell c1(m(s(start = 0.1))), c2(k(k = 50), m(m = 2));
equation
  connect(w.a, c1.a);
  connect(c1.b, c2.a);
end Composite;)");
  auto top = simulate(3, 0.01, R"(
model Top
  import Vibration.*;
  Fixed w;
  Spring k1(k = 100), k2(k = 50);
  Mass m1(m = 1, s(start = 0.1)), m2(m = 2);
equation
  connect(w.a, k1.a);
  connect(k1.b, m1.a);
  connect(m1.b, k2.a);
  connect(k2.b, m2.a);
end Top;)");
  ASSERT_TRUE(composite->ok && top->ok);
  EXPECT_LT(maxDifference(composite->col("c1.m.s"), top->col("m1.s")), 1e-7);
  EXPECT_LT(maxDifference(composite->col("c2.m.s"), top->col("m2.s")), 1e-7);
  EXPECT_GT(std::fabs(top->col("m2.s").back()), 1e-3);  // the second mass really moves
}

TEST(Connections, DirectlyConnectedMassesMoveAsOne) {
  // m1 and m2 rigidly joined on a spring k = 100: (m1 + m2) s'' = −k s with m1 + m2 = 4: ω = 5;
  // m2 takes m1's start (their positions are one). The joint pushes m2 with m2 s'' = −(3/4) k s.
  auto r = simulate(2, 0.01, R"(
model Rigid
  import Vibration.*;
  Fixed w;
  Spring k(k = 100);
  Mass m1(m = 1, s(start = 0.1)), m2(m = 3);
equation
  connect(w.a, k.a);
  connect(k.b, m1.a);
  connect(m1.b, m2.a);
end Rigid;)");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "m1.s", [](double t) { return 0.1 * std::cos(5 * t); }), 1e-6);
  EXPECT_LT(maxError(*r, "m2.s", [](double t) { return 0.1 * std::cos(5 * t); }), 1e-6);
  EXPECT_LT(maxError(*r, "m2.a.f", [](double t) { return -75 * 0.1 * std::cos(5 * t); }), 1e-4);
}

TEST(Connections, ConflictingStartsOfJoinedMassesAreReported) {
  driver::Compilation c;
  driver::compileSource(c, "components.qd", R"(
model Conflict
  import Vibration.*;
  Fixed w;
  Spring k;
  Mass m1(s(start = 0.1)), m2(s(start = 0.2));
equation
  connect(w.a, k.a);
  connect(k.b, m1.a);
  connect(m1.b, m2.a);
end Conflict;)",
                        "", driver::Stage::Kernel);
  ASSERT_FALSE(c.diags.diagnostics().empty());
  EXPECT_NE(rendered(c).find("m2.s"), std::string::npos) << rendered(c);
}

TEST(Connections, TopLevelConnectorLeftOpenCarriesNoForce) {
  // As UnconnectedFlangeCarriesNoForce, the open end now reaching the top model's own flange p.
  auto r = simulate(2, 0.01, R"(
model TopConnector
  import Vibration.*;
  Flange p;
  Force f(F = 2);
  Mass m1(m = 4);
equation
  connect(p, m1.b);
  connect(f.a, m1.a);
end TopConnector;)");
  ASSERT_TRUE(r->ok);
  EXPECT_LT(maxError(*r, "m1.s", [](double t) { return 0.25 * t * t; }), 1e-7);
}

TEST(Connections, InputBoundToAnotherVariableActsAsADamper) {
  // F = −c s' on a mass–spring: m s'' + c s' + k s = 0 with m = 1, k = 100, c = 2 (ζ = 0.1):
  // s = 0.1 e^{−t} (cos ωd t + sin(ωd t) / ωd), ωd = √99.
  auto r = simulate(4, 0.01, R"(
model Damped
  import Vibration.*;
  parameter Real c = 2;
  Fixed w;
  Spring k(k = 100);
  Mass m1(m = 1, s(start = 0.1));
  Force f(F = -c*der(m1.s));
equation
  connect(w.a, k.a);
  connect(k.b, m1.a);
  connect(f.a, m1.b);
end Damped;)");
  ASSERT_TRUE(r->ok);
  const double wd = std::sqrt(99.0);
  EXPECT_LT(
      maxError(*r, "m1.s", [&](double t) { return 0.1 * std::exp(-t) * (std::cos(wd * t) + std::sin(wd * t) / wd); }),
      1e-6);
}

TEST(Connections, DisplacementDrivenByTimeReachesTheSteadyAmplitude) {
  // The base moves as A sin(w t) and pulls the mass through a spring; a damper to the wall:
  // m s'' + c s' + k s = k A sin(w t), steady amplitude X = k A / √((k − m w²)² + (c w)²).
  // m = 1, k = 100, c = 4, w = 5, A = 0.01: X = 1 / √(75² + 20²); the transient decays as e^{−2t}.
  auto r = simulate(14, 0.001, R"(
model Driven
  import Vibration.*;
  Displacement d(s = 0.01*sin(5*time));
  Spring k(k = 100);
  Mass m1(m = 1);
  Damper c(c = 4);
  Fixed w;
equation
  connect(d.a, k.a);
  connect(k.b, m1.a);
  connect(m1.b, c.a);
  connect(c.b, w.a);
end Driven;)");
  ASSERT_TRUE(r->ok);
  std::vector<double> s = r->col("m1.s");
  double amplitude = 0;
  for (size_t k = 0; k < s.size(); ++k)
    if (r->times[k] > 14 - 2 * 2 * std::numbers::pi / 5) amplitude = std::max(amplitude, std::fabs(s[k]));
  const double X = 1 / std::sqrt(75.0 * 75.0 + 20.0 * 20.0);
  EXPECT_NEAR(amplitude, X, 1e-4 * X);  // sampling every 0.005 periods: the peak is off by ≤ 5e-5 X
}

}  // namespace
}  // namespace qdot::test
