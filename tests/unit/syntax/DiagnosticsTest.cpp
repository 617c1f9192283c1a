// Syntax error tests: a table of bad inputs, each with the exact line:col, code and a message
// substring of its first diagnostic; recovery (several independent errors per run); the caret
// rendering; and inputs that must neither crash nor hang (deep nesting, garbage, error limit).
#include <chrono>
#include <random>

#include "SyntaxTestUtil.h"

namespace qdot::testing {
namespace {

struct BadInput {
  const char* name;
  const char* text;
  const char* where;  ///< line:col of the first diagnostic
  const char* code;
  const char* message;  ///< substring of its message
  const char* help;     ///< substring of its help ("" = not checked)
};

const BadInput kBadInputs[] = {
    {"missing semicolon after declaration", "model M\n  parameter Real k = 1\n  Real x;\nend M;\n", "2:23", "E0112",
     "expected ';' after the declaration of 'k', found 'Real'", "add ';' here"},
    {"missing semicolon after equation", "model M\nequation\n  x = 1\n  y = 2;\nend M;\n", "3:8", "E0112",
     "expected ';' after the equation, found identifier 'y'", ""},
    {"missing semicolon after end", "model M\nend M\n", "2:6", "E0112", "expected ';' after 'end M'", ""},
    {"unbalanced parenthesis", "model M\nequation\n  x = (1 + 2;\nend M;\n", "3:13", "E0113", "expected ')', found ';'",
     "add ')'"},
    {"unbalanced brace", "model M\n  Real x[2] = {1, 2;\nend M;\n", "2:20", "E0113", "expected ',' or '}', found ';'", ""},
    {"unbalanced bracket", "model M\nequation\n  y = x[1;\nend M;\n", "3:10", "E0113", "expected ',' or ']'", ""},
    {"extra closing parenthesis", "model M\nequation\n  x = 1);\nend M;\n", "3:8", "E0112",
     "expected ';' after the equation, found ')'", ""},
    {"expression expected", "model M\nequation\n  x = );\nend M;\n", "3:7", "E0111", "expected an expression, found ')'",
     ""},
    {"operator without operand", "model M\nequation\n  x = 1 + ;\nend M;\n", "3:11", "E0111",
     "expected an expression, found ';'", ""},
    {"bad number", "model M\n  Real x = 1e;\nend M;\n", "2:12", "E0104", "malformed number '1e'", "1e-3"},
    {"bad exponent sign", "model M\n  Real x = 2.5E+;\nend M;\n", "2:12", "E0104", "malformed number '2.5E+'", ""},
    {"unterminated string", "model M\n  Real x \"open;\n  Real y;\nend M;\n", "2:10", "E0103", "unterminated string",
     "closing"},
    {"unterminated comment", "model M\n  Real x; /* never\nend M;\n", "2:11", "E0101", "unterminated block comment", "*/"},
    {"mismatched end name", "model Pendulum\nend Pendulm;\n", "2:5", "E0121",
     "'end Pendulm' does not match the class name 'Pendulum'", "write 'end Pendulum;'"},
    {"end without name", "model M\nend;\n", "2:4", "E0121", "expected the class name 'M' after 'end', found ';'", ""},
    {"stray token among declarations", "model M\n  ) Real x;\nend M;\n", "2:3", "E0123",
     "expected a declaration, found ')'", ""},
    {"equation before the equation keyword", "model M\n  Real x;\n  x = 1;\nend M;\n", "3:3", "E0123",
     "expected a declaration, found identifier 'x'", "after the 'equation' keyword"},
    {"chained power", "model M\n  Real x = a^b^c;\nend M;\n", "2:15", "E0114", "'^' is not associative",
     "add parentheses: (a^b)^c or a^(b^c)"},
    {"chained comparison", "model M\n  Boolean b = 1 < x < 3;\nend M;\n", "2:21", "E0115",
     "comparison operators cannot be chained", "and"},
    {"range with four parts", "model M\n  Real x = 1:2:3:4;\nend M;\n", "2:17", "E0115", "at most three parts", ""},
    {"garbage bytes", "model M\n  Real x = 3 \x01\xfe\xff;\nend M;\n", "2:14", "E0102", "unexpected characters", ""},
    {"unexpected character", "model M\n  Real x = 3 $ 4;\nend M;\n", "2:14", "E0102", "unexpected character '$'", ""},
    {"empty file", "", "1:1", "E0120", "expected 'model', 'connector' or 'package', found end of file", ""},
    {"only a comment", "// nothing here\n", "2:1", "E0120", "found end of file", ""},
    {"no class at top level", "x = 1;\nmodel M end M;\n", "1:1", "E0120",
     "expected 'model', 'connector' or 'package', found identifier 'x'", ""},
    {"missing class name", "model\n  Real x;\nend M;\n", "2:3", "E0116", "expected a class name after 'model', found 'Real'",
     ""},
    {"missing end at end of file", "model M\n  Real x;\n", "2:10", "E0126", "expected 'end M;' before the end of the file",
     "add 'end M;'"},
    {"inner class not closed", "package P\n  model A\n    Real x;\nend P;\n", "4:1", "E0126",
     "expected 'end A;' before 'end P'", ""},
    {"missing then", "model M\nequation\n  if x > 1\n    y = 1;\n  end if;\nend M;\n", "4:5", "E0117",
     "expected 'then' after the condition, found identifier 'y'", ""},
    {"missing loop", "model M\nequation\n  for i in 1:n\n    x[i] = 1;\n  end for;\nend M;\n", "4:5", "E0117",
     "expected 'loop' after the for-indices", ""},
    {"missing in", "model M\nequation\n  for i 1:n loop\n  end for;\nend M;\n", "3:9", "E0117",
     "expected 'in' after the loop variable 'i', found number '1'", "for i in 1:n"},
    {"missing end for", "model M\nequation\n  for i in 1:2 loop\n    x[i] = 1;\nend M;\n", "5:1", "E0117",
     "expected 'end for', found 'end'", "end for;"},
    {"stray end for", "model M\nequation\n  x = 1;\n  end for;\nend M;\n", "4:3", "E0123",
     "'end for' without a matching 'for'", ""},
    {"if-expression without else", "model M\n  Real x = if a then 1;\nend M;\n", "2:23", "E0117",
     "expected 'else' in the if-expression, found ';'", "needs an 'else'"},
    {"if-expression inside an operation", "model M\n  Real x = 1 + if a then 1 else 2;\nend M;\n", "2:16", "E0111",
     "expected an expression, found 'if'", "parentheses"},
    {"duplicate prefix", "model M\n  parameter parameter Real k;\nend M;\n", "2:13", "E0122", "duplicate prefix 'parameter'",
     ""},
    {"conflicting prefix", "model M\n  parameter constant Real k;\nend M;\n", "2:13", "E0122",
     "'constant' conflicts with an earlier prefix", "either 'parameter' or 'constant'"},
    {"bad mechanics statement", "model M\nmechanics\n  x = 1;\nend M;\n", "3:3", "E0124",
     "expected a mechanics statement, found identifier 'x'", "equation"},
    {"kinetic without =", "model M\nmechanics\n  kinetic 0.5*m;\nend M;\n", "3:11", "E0117",
     "expected '=' after 'kinetic', found number '0.5'", ""},
    {"force without parentheses", "model M\nmechanics\n  force q = 1;\nend M;\n", "3:9", "E0117",
     "expected '(' after 'force', found identifier 'q'", ""},
    {"declaration after a section", "model M\nequation\n  x = 1;\n  Real y;\nend M;\n", "4:3", "E0125",
     "declarations must come before the first section", "'equation'"},
    {"within not first", "model M end M;\nwithin A;\n", "2:1", "E0127", "'within' must come first", ""},
    {"positional after named argument", "model M\n  Real x = f(a = 1, 2);\nend M;\n", "2:21", "E0118",
     "positional argument after a named argument", ""},
    {"reduction with other arguments", "model M\n  Real x = sum(1, x for i in 1:3);\nend M;\n", "2:21", "E0118",
     "must be the only argument", ""},
    {"calling a subscripted name", "model M\n  Real x = y[1](2);\nend M;\n", "2:16", "E0118",
     "only a name can be called, not 'y[1]'", ""},
    // Found by fuzz_frontend: a member of a number printed back as `5.rho`, which lexes differently.
    {"member of a number", "model M\n  Real x = 5.0.rho;\nend M;\n", "2:15", "E0118",
     "only a component can have members, not '5.0'", "a.b"},
    {"member of a call", "model M\n  Real x = f(1).y;\nend M;\n", "2:16", "E0118", "not 'f(1)'", ""},
    {"der without parentheses", "model M\nequation\n  der x = 1;\nend M;\n", "3:7", "E0117",
     "expected '(' after 'der', found identifier 'x'", ""},
    {"double equals in an equation", "model M\nequation\n  x == 1;\nend M;\n", "3:9", "E0117",
     "expected '=' in the equation, found ';'", "'==' compares"},
    {"unknown escape", "model M\n  Real x \"a\\qb\";\nend M;\n", "2:12", "E0105", "unknown escape sequence '\\q'", ""},
    {"number too large", "model M\n  Real x = 1e999;\nend M;\n", "2:12", "E0106", "too large", ""},
    {"missing name after dot", "model M\n  Real x = a.;\nend M;\n", "2:14", "E0116", "expected a name after '.', found ';'",
     ""},
    {"square-bracket array literal", "model M\n  Real x[2] = [1, 2];\nend M;\n", "2:15", "E0111",
     "expected an expression, found '['", "braces"},
    {"missing type", "model M\n  parameter k = 1;\nend M;\n", "2:13", "E0116", "missing type in the declaration of 'k'",
     "parameter Real k"},
    {"prefix without anything", "model M\n  parameter;\nend M;\n", "2:12", "E0116",
     "expected a type name after the prefixes, found ';'", ""},
    {"missing declared name", "model M\n  parameter Real = 1;\nend M;\n", "2:18", "E0116",
     "expected a name after the type 'Real', found '='", ""},
    {"bad modification", "model M\n  Real x(= 1);\nend M;\n", "2:10", "E0116", "expected a name in the modification", ""},
    {"else without if", "model M\nequation\n  else x = 1;\nend M;\n", "3:3", "E0123", "expected an equation, found 'else'", ""},
    {"algorithm section", "model M\n  Real x;\nequation\n  x = 1;\nalgorithm\n  x := 2;\n  y := x;\nequation\n  y = 1;\nend M;\n",
     "5:1", "E0119", "'algorithm' sections are not supported", "equation"},
    {"protected section", "model M\nprotected\n  Real x;\nend M;\n", "2:1", "E0119", "'protected' sections are not supported",
     ""},
    {"partial class", "partial model M\nend M;\n", "1:1", "E0119", "'partial' classes are not supported", "remove"},
    {"when with else", "model M\nequation\n  when c then\n    y = 1;\n  else\n    y = 2;\n  end when;\nend M;\n", "5:3",
     "E0117", "expected 'end when', found 'else'", ""},
    {"connect without comma", "model M\nequation\n  connect(a b);\nend M;\n", "3:13", "E0117",
     "expected ',' between the two connectors, found identifier 'b'", ""},
};

class BadInputTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputTest, FirstDiagnosticIsExact) {
  const BadInput& c = GetParam();
  auto p = parseText(c.text);
  ASSERT_TRUE(p->diags.hasErrors()) << c.name;
  const Diagnostic& d = p->diags.diagnostics()[0];
  EXPECT_EQ(p->where(d), c.where) << c.name << "\n" << p->rendered();
  EXPECT_EQ(diagCodeName(d.code), c.code) << c.name << "\n" << p->rendered();
  EXPECT_NE(d.message.find(c.message), std::string::npos) << c.name << ": " << d.message;
  EXPECT_NE(d.help.find(c.help), std::string::npos) << c.name << ": " << d.help;
  EXPECT_EQ(d.severity, Severity::Error);
  // One mistake, one message: none of these inputs should cascade.
  EXPECT_EQ(p->diags.errorCount(), 1u) << c.name << "\n" << p->rendered();
}

std::string caseName(const ::testing::TestParamInfo<BadInput>& info) {
  std::string s;
  for (const char* c = info.param.name; *c; ++c) s += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(Syntax, BadInputTest, ::testing::ValuesIn(kBadInputs), caseName);

TEST(Recovery, SeveralIndependentErrorsAreReportedSeparately) {
  auto p = parseText(R"(model M
  parameter Real k = 1
  Real x;
  Real y = (2 + ;
equation
  x = (1 + ;
  der(x) = -k*x
  y = 2 $ 3;
  z = 1 < 2 < 3;
end N;
)");
  const auto& d = p->diags.diagnostics();
  ASSERT_EQ(d.size(), 7u) << p->rendered();
  EXPECT_EQ(p->where(d[0]) + " " + std::string(diagCodeName(d[0].code)), "2:23 E0112");
  EXPECT_EQ(p->where(d[1]) + " " + std::string(diagCodeName(d[1].code)), "4:17 E0111");
  EXPECT_EQ(p->where(d[2]) + " " + std::string(diagCodeName(d[2].code)), "6:12 E0111");
  EXPECT_EQ(p->where(d[3]) + " " + std::string(diagCodeName(d[3].code)), "7:16 E0112");
  EXPECT_EQ(p->where(d[4]) + " " + std::string(diagCodeName(d[4].code)), "8:9 E0102");
  EXPECT_EQ(p->where(d[5]) + " " + std::string(diagCodeName(d[5].code)), "9:13 E0115");
  EXPECT_EQ(p->where(d[6]) + " " + std::string(diagCodeName(d[6].code)), "10:5 E0121");
  // What parsed is kept: x, k, y declared; the der(x) equation survived its missing ';'.
  EXPECT_EQ(p->cls().declarations.size(), 3u);
  ASSERT_FALSE(p->cls().equations.empty());
  EXPECT_EQ(sexpr(p->cls().equations[0].lhs.get()), "(call der x)");
}

TEST(Recovery, TheTreeKeepsWhatParsed) {
  auto p = parseText(R"(model M
  Real a = );
  Real b = 2;
equation
  a = ;
  b = 3;
mechanics
  kinetic = ;
  potential = b^2;
end M;)");
  EXPECT_EQ(p->diags.errorCount(), 3u) << p->rendered();
  const ast::ClassDef& m = p->cls();
  ASSERT_EQ(m.declarations.size(), 2u);
  EXPECT_EQ(m.declarations[1].name, "b");
  ASSERT_EQ(m.equations.size(), 1u);
  EXPECT_EQ(sexpr(m.equations[0].rhs.get()), "3");
  ASSERT_EQ(m.mechanics.size(), 2u);
  EXPECT_EQ(m.mechanics[1].kind, ast::MechanicsKind::Potential);
}

TEST(Recovery, BrokenForHeaderKeepsTheBody) {
  auto p = parseText("model M\nequation\n  for i in 1:n x loop\n    a = 1;\n  end for;\n  b = 2;\nend M;\n");
  EXPECT_EQ(p->diags.errorCount(), 1u) << p->rendered();
  ASSERT_EQ(p->cls().equations.size(), 2u);
  EXPECT_EQ(p->cls().equations[0].body.size(), 1u);
}

TEST(Recovery, BrokenIfConditionKeepsTheBranches) {
  auto p = parseText("model M\nequation\n  if x > then\n    a = 1;\n  else\n    a = 2;\n  end if;\nend M;\n");
  EXPECT_EQ(p->diags.errorCount(), 1u) << p->rendered();
  ASSERT_EQ(p->cls().equations.size(), 1u);
  EXPECT_EQ(p->cls().equations[0].elseBranch.size(), 1u);
}

TEST(Recovery, ErrorsInsideNestedClassesDoNotLeak) {
  auto p = parseText("package P\n  model A\n    Real x = ;\n  end A;\n  model B\n    Real y;\n  end B;\nend P;\n");
  EXPECT_EQ(p->diags.errorCount(), 1u) << p->rendered();
  ASSERT_EQ(p->cls().classes.size(), 2u);
  EXPECT_EQ(p->cls().classes[1]->declarations.size(), 1u);
}

TEST(Recovery, UnsupportedSectionsAreSkippedWhole) {
  auto p = parseText("partial model M\n  Real x;\nprotected\n  Real y;\nequation\n  x = 1;\nalgorithm\n  x := 2;\n"
                     "  when x > 1 then y := 0; end when;\ninitial algorithm\n  y := 1;\nequation\n  y = 2;\n"
                     "initial algorithm\n  y := 3;\nend M;\n");
  EXPECT_EQ(p->diags.errorCount(), 5u) << p->rendered();
  for (const auto& d : p->diags.diagnostics()) EXPECT_EQ(diagCodeName(d.code), "E0119");
  EXPECT_EQ(p->cls().declarations.size(), 2u);
  EXPECT_EQ(p->cls().equations.size(), 2u);
}

TEST(Recovery, MismatchedEndNameIsNotACascade) {
  auto p = parseText("model A\n  Real x;\nend B;\nmodel C\n  Real y;\nend C;\n");
  EXPECT_EQ(p->diags.errorCount(), 1u) << p->rendered();
  EXPECT_EQ(p->def->classes.size(), 2u);
}

TEST(Rendering, CaretUnderTheErrorWithHelp) {
  auto p = parseText("model M\n  parameter Real k = 1\n  Real x;\nend M;\n");
  EXPECT_EQ(p->rendered(),
            "test.qd:2:23: error[E0112]: expected ';' after the declaration of 'k', found 'Real'\n"
            "   |\n"
            " 2 |   parameter Real k = 1\n"
            "   |                       ^\n"
            "help: add ';' here\n");
}

TEST(Rendering, NoteOnTheOpeningBracketAndMultiCharCaret) {
  auto p = parseText("model Pendulum\nend Pendulm;\n");
  EXPECT_EQ(p->rendered(),
            "test.qd:2:5: error[E0121]: 'end Pendulm' does not match the class name 'Pendulum'\n"
            "   |\n"
            " 2 | end Pendulm;\n"
            "   |     ^~~~~~~\n"
            "test.qd:1:7: note: the class is named here\n"
            "   |\n"
            " 1 | model Pendulum\n"
            "   |       ^~~~~~~~\n"
            "help: write 'end Pendulum;'\n");
}

TEST(Rendering, LongLineIsEchoedAsAWindowAroundTheCaret) {
  std::string before(300, 'a'), after(300, 'b');
  auto p = parseText("model M\n  Real x = " + before + " $ " + after + ";\nend M;\n");
  std::string r = p->rendered();
  std::istringstream lines(r);
  std::string head, bar, echoed, caret;
  std::getline(lines, head), std::getline(lines, bar), std::getline(lines, echoed), std::getline(lines, caret);
  EXPECT_EQ(head, "test.qd:2:313: error[E0102]: unexpected character '$'");
  // 120 bytes from 40 before the caret, cut on both sides
  EXPECT_EQ(echoed, " 2 | …" + std::string(39, 'a') + " $ " + std::string(78, 'b') + "…");
  EXPECT_EQ(caret, "   | " + std::string(41, ' ') + "^");
}

TEST(Rendering, CaretCountsCharactersNotBytes) {
  auto p = parseText("model M\n  Real x \"\u03c9\u03c9\" $;\nend M;\n");  // ω is two bytes
  EXPECT_EQ(p->rendered(),
            "test.qd:2:17: error[E0102]: unexpected character '$'\n"
            "   |\n"
            " 2 |   Real x \"\u03c9\u03c9\" $;\n"
            "   |               ^\n"
            "help: remove it; operators are + - * / ^ = == <> < <= > >= and names use letters, digits and '_'\n");
}

// --- inputs that must neither crash nor hang ------------------------------------------------

std::string wrap(const std::string& expr) { return "model M\nequation\n  x = " + expr + ";\nend M;\n"; }

void expectOnlyNestingError(const std::string& text) {
  auto t0 = std::chrono::steady_clock::now();
  auto p = parseText(text);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(p->diags.hasErrors());
  EXPECT_EQ(diagCodeName(p->diags.diagnostics()[0].code), "E0110") << p->rendered().substr(0, 500);
  EXPECT_NE(p->diags.diagnostics()[0].message.find("nested too deeply"), std::string::npos);
  EXPECT_LE(p->diags.errorCount(), 3u) << p->rendered().substr(0, 2000);
  EXPECT_LT(seconds, 2.0);
}

TEST(Robustness, DeepParentheses) {
  expectOnlyNestingError(wrap(std::string(100000, '(') + "y" + std::string(100000, ')')));
  auto p = parseText(wrap(std::string(100000, '(')));
  EXPECT_EQ(diagCodeName(p->diags.diagnostics()[0].code), "E0110");
}

TEST(Robustness, DeepBracesMinusesNotsAndIfs) {
  expectOnlyNestingError(wrap(std::string(100000, '{') + "1" + std::string(100000, '}')));
  expectOnlyNestingError(wrap(std::string(100000, '-') + "1"));
  std::string nots, ifs, calls, subs;
  for (int i = 0; i < 100000; ++i) nots += "not ";
  for (int i = 0; i < 100000; ++i) ifs += "if ";
  for (int i = 0; i < 50000; ++i) calls += "f(";
  for (int i = 0; i < 50000; ++i) subs += "x[";
  expectOnlyNestingError(wrap(nots + "a"));
  expectOnlyNestingError(wrap(ifs + "a"));
  expectOnlyNestingError(wrap(calls + "1"));
  expectOnlyNestingError(wrap(subs + "1"));
}

TEST(Robustness, LongOperatorChainsCountAsNesting) {
  std::string sum = "a", power = "a", index = "x", member = "x[1]";
  for (int i = 0; i < 100000; ++i) sum += "+a";
  for (int i = 0; i < 1000; ++i) power += "^a";
  for (int i = 0; i < 100000; ++i) index += "[1]";
  for (int i = 0; i < 100000; ++i) member += ".a";
  expectOnlyNestingError(wrap(sum));
  expectOnlyNestingError(wrap(index));
  expectOnlyNestingError(wrap(member));
  auto p = parseText(wrap(power));
  EXPECT_EQ(diagCodeName(p->diags.diagnostics()[0].code), "E0114");  // reported once, then E0110
  // A sum of 200 terms is fine.
  std::string ok = "a";
  for (int i = 0; i < 200; ++i) ok += " + a";
  EXPECT_FALSE(parseText(wrap(ok))->diags.hasErrors());
}

TEST(Robustness, DeepStatementsClassesAndModifications) {
  std::string fors = "model M\nequation\n", classes, mods = "model M\n  Real x";
  for (int i = 0; i < 20000; ++i) fors += "for i in 1:2 loop ";
  fors += "x = 1;";
  for (int i = 0; i < 20000; ++i) fors += " end for;";
  fors += "\nend M;\n";
  for (int i = 0; i < 20000; ++i) classes += "model A" + std::to_string(i) + " ";
  for (int i = 0; i < 20000; ++i) mods += "(a";
  expectOnlyNestingError(fors);
  expectOnlyNestingError(classes);
  expectOnlyNestingError(mods);
  std::string whens = "model M\nequation\n";
  for (int i = 0; i < 20000; ++i) whens += "when c then ";
  expectOnlyNestingError(whens);
}

TEST(Robustness, ModerateNestingIsAccepted) {
  EXPECT_FALSE(parseText(wrap(std::string(200, '(') + "y" + std::string(200, ')')))->diags.hasErrors());
  EXPECT_FALSE(parseText(wrap(std::string(200, '{') + "y" + std::string(200, '}')))->diags.hasErrors());
}

TEST(Robustness, RandomBytesStopAtTheErrorLimit) {
  std::mt19937 rng(1234);
  for (int round = 0; round < 50; ++round) {
    std::string text(20000, ' ');
    for (char& c : text) c = static_cast<char>(1 + rng() % 255);  // NUL makes it one error (below)
    auto t0 = std::chrono::steady_clock::now();
    auto p = parseText(text);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_TRUE(p->diags.hasErrors());
    EXPECT_LE(p->diags.diagnostics().size(), 50u);
    EXPECT_LT(seconds, 1.0);
    std::ostringstream os;
    p->diags.render(os, p->sm);
    ast::printAST(os, *p->def, p->sm);
  }
}

TEST(Robustness, ABinaryFileIsOneShortError) {
  std::mt19937 rng(7);
  std::string text(200000, ' ');
  for (char& c : text) c = static_cast<char>(rng() & 0xFF);
  text.replace(0, 5, "model");
  text[5000] = '\0';
  for (size_t i = 0; i < 5000; ++i)
    if (text[i] == '\0') text[i] = '?';
  auto p = parseText(text);
  ASSERT_EQ(p->diags.diagnostics().size(), 1u) << p->rendered().substr(0, 2000);
  EXPECT_EQ(p->diags.diagnostics()[0].message, "this is not a text file (it has a NUL byte)");
  EXPECT_EQ(p->diags.diagnostics()[0].range.begin, 5000u);
  EXPECT_LT(p->rendered().size(), 1000u);
}

TEST(Robustness, RandomTokenSoupTerminates) {
  const char* pieces[] = {"model", "end", "M", "x", "(", ")", "[", "]", "{", "}", "=", ";", ",", ".", ":", "+", "-",
                          "*", "^", "1", "2.5", "\"s\"", "if", "then", "else", "for", "in", "loop", "when",
                          "equation", "mechanics", "kinetic", "force", "der", "parameter", "Real", "annotation",
                          "connect", "initial", "elseif", "elsewhen", "not", "and", "<", "==", "end for", "within",
                          "import", "extends", "package", "connector", "flow", "constraint", "\n"};
  std::mt19937 rng(99);
  for (int round = 0; round < 300; ++round) {
    std::string text;
    size_t n = 1 + rng() % 400;
    for (size_t i = 0; i < n; ++i) text += std::string(pieces[rng() % std::size(pieces)]) + " ";
    auto p = parseText(text);
    std::ostringstream os;
    p->diags.render(os, p->sm);
    ast::printAST(os, *p->def, p->sm);
    for (const auto& d : p->diags.diagnostics()) {
      EXPECT_TRUE(d.range.valid());
      EXPECT_LE(d.range.end, text.size());
      EXPECT_LE(d.range.begin, d.range.end);
      EXPECT_FALSE(d.message.empty());
      EXPECT_EQ(diagCodeName(d.code).substr(0, 3), "E01");
    }
  }
}

TEST(Robustness, ParserStopsEarlyAtTheErrorLimit) {
  std::string text = "model M\nequation\n";
  for (int i = 0; i < 200000; ++i) text += "x = ;\n";
  text += "end M;\n";
  auto t0 = std::chrono::steady_clock::now();
  auto p = parseText(text);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(p->diags.limitReached());
  EXPECT_LT(seconds, 0.5);
}

}  // namespace
}  // namespace qdot::testing
