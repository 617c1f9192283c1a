// Run options: parsed with CLI11 exactly as `qdot run` would, then resolved against a hand model
// (the oscillator: parameter omega, variables x and v, output a, invariant E). Defaults, each
// validation message, the -p arrays, column selection and the output grid.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <numbers>

#include "HandModels.h"
#include "sim/RunOptions.h"

namespace qdot::rt::test {
namespace {

/// Parses args (without the program name) into RunOptions plus one positional "model".
RunOptions parse(std::vector<std::string> args, std::string* positional = nullptr) {
  CLI::App app("test");
  RunOptions options;
  std::string model;
  addRunOptions(app, options);
  app.add_option("model", model);
  std::reverse(args.begin(), args.end());  // CLI11 takes a reversed vector
  app.parse(args);
  if (positional) *positional = model;
  return options;
}

ResolvedRun resolve(std::vector<std::string> args, const ExperimentDefaults& e = {}) {
  static HandModel model = oscillator(2 * std::numbers::pi);
  return resolveRunOptions(parse(std::move(args)), e, model.abi());
}

std::string usageError(std::vector<std::string> args, const ExperimentDefaults& e = {}) {
  try {
    resolve(std::move(args), e);
  } catch (const UsageError& error) {
    return error.what();
  }
  return "(no error)";
}

TEST(RunOptionsDefaults, WithoutAnnotationStopOneSecond500IntervalsRtol1e6) {
  ResolvedRun r = resolve({});
  EXPECT_EQ(r.settings.start, 0);
  EXPECT_EQ(r.settings.stop, 1);
  EXPECT_DOUBLE_EQ(r.settings.interval, 1.0 / 500);
  EXPECT_EQ(r.settings.rtol, 1e-6);
  EXPECT_FALSE(r.settings.atol.has_value());
  EXPECT_EQ(r.settings.linearSolver, LinearSolverKind::Auto);
  EXPECT_TRUE(r.settings.columns.empty());
  EXPECT_EQ(r.settings.parameters, (std::vector<double>{2 * std::numbers::pi}));
  EXPECT_TRUE(r.outputPath.empty());
  EXPECT_FALSE(r.stats);
}

TEST(RunOptionsDefaults, ExperimentAnnotationThenCommandLine) {
  ExperimentDefaults e{1.0, 11.0, 0.5, 1e-8};
  ResolvedRun a = resolve({}, e);
  EXPECT_EQ(a.settings.start, 1);
  EXPECT_EQ(a.settings.stop, 11);
  EXPECT_EQ(a.settings.interval, 0.5);
  EXPECT_EQ(a.settings.rtol, 1e-8);
  // Overriding the span drops the annotation's interval (it may not fit): span / 500.
  ResolvedRun b = resolve({"--stop", "2"}, e);
  EXPECT_DOUBLE_EQ(b.settings.interval, 1.0 / 500);
  ResolvedRun c = resolve({"--stop", "2", "--interval", "0.25", "--rtol", "1e-4", "--atol", "1e-9"}, e);
  EXPECT_EQ(c.settings.interval, 0.25);
  EXPECT_EQ(c.settings.rtol, 1e-4);
  EXPECT_EQ(*c.settings.atol, 1e-9);
}

TEST(RunOptionsParse, AllOptionsReachTheResolvedRun) {
  std::string model;
  RunOptions o = parse({"-p", "omega=3", "model.qd", "--outputs", "v,E", "-o", "out.csv", "--stats", "--invariants",
                        "--linear-solver", "klu"},
                       &model);
  EXPECT_EQ(model, "model.qd");  // -p takes exactly one value per occurrence
  HandModel m = oscillator(1.0);
  ResolvedRun r = resolveRunOptions(o, {}, m.abi());
  EXPECT_EQ(r.settings.parameters, (std::vector<double>{3.0}));
  ASSERT_EQ(r.settings.columns.size(), 2u);  // E named explicitly: not repeated by --invariants
  EXPECT_EQ(r.settings.columns[0].name, "v");
  EXPECT_EQ(r.settings.columns[1].source, Column::Source::Invariant);
  EXPECT_EQ(r.outputPath, "out.csv");
  EXPECT_TRUE(r.stats);
  EXPECT_EQ(r.settings.linearSolver, LinearSolverKind::Klu);
  EXPECT_THROW(parse({"--linear-solver", "lu"}), CLI::ValidationError);
}

TEST(RunOptionsParse, CsvNames) {
  EXPECT_EQ(resolve({}).csvNames, ColumnNaming::Modelica);
  EXPECT_EQ(resolve({"--csv-names", "modelica"}).csvNames, ColumnNaming::Modelica);
  EXPECT_EQ(resolve({"--csv-names=identifier"}).csvNames, ColumnNaming::Identifier);
  EXPECT_THROW(parse({"--csv-names", "python"}), CLI::ValidationError);
}

TEST(RunOptionsValidation, TolerancesMustBePositive) {
  EXPECT_EQ(usageError({"--rtol", "0"}), "--rtol must be positive (got 0)");
  EXPECT_EQ(usageError({"--rtol", "-1e-6"}), "--rtol must be positive (got -1e-06)");
  EXPECT_EQ(usageError({"--rtol", "2"}), "--rtol must be below 1 (got 2); e.g. 1e-6");
  EXPECT_EQ(usageError({"--atol", "0"}), "--atol must be positive (got 0)");
}

TEST(RunOptionsValidation, TimesMustMakeASpan) {
  EXPECT_EQ(usageError({"--start", "2", "--stop", "1"}), "the stop time (1) must be greater than the start time (2)");
  EXPECT_EQ(usageError({"--stop", "0"}), "the stop time (0) must be greater than the start time (0)");
  EXPECT_EQ(usageError({"--interval", "0"}), "--interval must be positive (got 0)");
  EXPECT_EQ(usageError({"--interval", "-0.1"}), "--interval must be positive (got -0.1)");
  EXPECT_EQ(usageError({"--interval", "5"}), "--interval (5) is longer than the simulated span [0, 1]");
  EXPECT_EQ(usageError({}, ExperimentDefaults{5.0, std::nullopt, std::nullopt, std::nullopt}),
            "the stop time (1) must be greater than the start time (5)");
}

// The output-size guard counts rows before anything runs (an interval of 1e-300 is refused, not an
// overflow); --force lets a large but intended output through.
TEST(RunOptionsValidation, MoreThanTenMillionRowsNeedForce) {
  EXPECT_EQ(usageError({"--stop", "10", "--interval", "1e-9"}),
            "--interval 1e-09 would write 10000000001 rows over [0, 10] (more than 1e+07); give a longer --interval, or "
            "--force if that many rows are meant");
  EXPECT_NE(usageError({"--interval", "1e-300"}).find("would write 1e+300 rows"), std::string::npos);
  EXPECT_NE(usageError({"--interval", "1e-7"}).find("would write 10000001 rows"), std::string::npos);
  EXPECT_EQ(usageError({"--interval", "2e-7"}), "(no error)");  // 5 000 001 rows
  EXPECT_EQ(usageError({"--stop", "10", "--interval", "1e-9", "--force"}), "(no error)");
  EXPECT_EQ(usageError({"--max-steps", "0"}), "--max-steps must be positive (got 0)");
  EXPECT_EQ(resolve({"--max-steps", "20"}).settings.maxSteps, 20);
}

TEST(RunOptionsValidation, ParameterMistakes) {
  EXPECT_EQ(usageError({"-p", "omgea=3"}), "unknown parameter 'omgea' (did you mean 'omega'?)");
  EXPECT_EQ(usageError({"-p", "zeta=3"}), "unknown parameter 'zeta'; the model has: omega");
  EXPECT_EQ(usageError({"-p", "omega=3x"}), "the value of parameter 'omega' is not a number: '3x'");
  EXPECT_EQ(usageError({"-p", "omega="}), "the value of parameter 'omega' is not a number: ''");
  EXPECT_EQ(usageError({"-p", "omega=1e999"}),
            "the value of parameter 'omega' is out of range: '1e999' is larger than the largest number (about 1.8e308)");
  EXPECT_EQ(usageError({"-p", "omega=-1e400"}),
            "the value of parameter 'omega' is out of range: '-1e400' is larger than the largest number (about 1.8e308)");
  EXPECT_EQ(usageError({"-p", "omega=1e-400"}),
            "the value of parameter 'omega' is out of range: '1e-400' is closer to zero than the smallest number "
            "(about 4.9e-324); write 0 if zero is meant");
  EXPECT_EQ(usageError({"-p", "omega=1e400x"}), "the value of parameter 'omega' is not a number: '1e400x'");
  EXPECT_EQ(usageError({"-p", "omega=nan"}), "the value of parameter 'omega' is not a number: 'nan'");
  EXPECT_EQ(usageError({"-p", "omega"}), "-p expects NAME=VALUE, got 'omega'");
  EXPECT_EQ(usageError({"-p", "=3"}), "-p expects NAME=VALUE, got '=3'");
  EXPECT_EQ(usageError({"-p", "omega=3", "-p", "omega=4"}),
            "parameter 'omega' is given twice (-p omega=3 and -p omega=4)");
}

TEST(RunOptionsValidation, UnknownOrRepeatedColumns) {
  EXPECT_EQ(usageError({"--outputs", "x,vv"}), "unknown output column 'vv' (did you mean 'v'?)");
  EXPECT_EQ(usageError({"--outputs", "position"}), "unknown output column 'position'; the model has: x, v, a, E");
  EXPECT_EQ(usageError({"--outputs", "x,x"}), "output column 'x' is selected twice");
}

TEST(ParameterOverrides, ArraysForTheModelsParametersFunction) {
  HandModel m;
  m.variables = {"x"};
  m.differential = {1};
  m.parameterNames = {"m", "k", "c"};
  m.parameterDefaults = {1, 2, 3};
  ParameterOverrides o = parameterOverrides(m.abi(), {"c=-0.5", "m=1e3"});
  EXPECT_EQ(o.given, (std::vector<double>{1e3, 0, -0.5}));
  EXPECT_EQ(o.overridden, (std::vector<uint8_t>{1, 0, 1}));
  EXPECT_EQ(evaluateParameters(m.abi(), o), (std::vector<double>{1e3, 2, -0.5}));
}

TEST(ParseNumber, WholeStringFiniteNumbersOnly) {
  EXPECT_EQ(parseNumber("2.5"), 2.5);
  EXPECT_EQ(parseNumber("-1e-3"), -1e-3);
  EXPECT_FALSE(parseNumber("2.5 "));
  EXPECT_FALSE(parseNumber("0x10"));
  EXPECT_FALSE(parseNumber("inf"));
  EXPECT_FALSE(parseNumber(""));
  EXPECT_FALSE(parseNumber("+1"));  // from_chars: no leading plus
  EXPECT_EQ(parseNumber("1e-310"), 1e-310);  // subnormal, but a double
  EXPECT_FALSE(parseNumber("1e-400"));
}

TEST(NameSuggestions, EditDistanceAndThreshold) {
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("omgea", "omega"), 1u);  // a swap of neighbours counts once
  std::vector<std::string_view> names = {"mass", "length", "gravity"};
  EXPECT_EQ(closestName("mas", names), "mass");
  EXPECT_EQ(closestName("lenght", names), "length");
  EXPECT_FALSE(closestName("q", names).has_value());
}

// Reference: the grid definition (start + k interval, then the stop time exactly).
TEST(OutputGrid, RegularTimesThenTheExactStop) {
  OutputGrid even(0, 1, 0.25);
  ASSERT_EQ(even.size(), 5u);
  EXPECT_EQ(even[4], 1.0);
  OutputGrid uneven(0, 1, 0.3);
  ASSERT_EQ(uneven.size(), 5u);  // 0, 0.3, 0.6, 0.9, 1
  EXPECT_DOUBLE_EQ(uneven[3], 0.9);
  EXPECT_EQ(uneven[4], 1.0);
  OutputGrid tenths(0, 1, 0.1);  // 10 * 0.1 is not exactly 1: no near-duplicate before the stop
  ASSERT_EQ(tenths.size(), 11u);
  EXPECT_DOUBLE_EQ(tenths[9], 0.9);
  OutputGrid shifted(2, 3, 0.5);
  ASSERT_EQ(shifted.size(), 3u);
  EXPECT_EQ(shifted[1], 2.5);
}

}  // namespace
}  // namespace qdot::rt::test
