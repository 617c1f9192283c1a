// The registry of diagnostic codes (support/DiagnosticCodes.def) against the tree: every code is
// reported by some call site in compiler/, documented in docs/diagnostics.md under its stage with
// the registry's title, and produced by a model of the diagnostics corpus (tests/diagnostics/).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "support/Diagnostic.h"

namespace qdot::test {
namespace {

namespace fs = std::filesystem;
const fs::path kRoot = QDOT_SOURCE_DIR;

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The text of every file under `dir` whose name ends in one of `extensions`, concatenated.
std::string allText(const fs::path& dir, const std::set<std::string>& extensions) {
  std::string out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && extensions.count(e.path().extension().string())) out += readFile(e.path()) + "\n";
  return out;
}

// The `// expect:` lines of the corpus (only what a corpus file states it produces counts).
std::string corpusExpectations() {
  std::string out;
  for (const auto& e : fs::recursive_directory_iterator(kRoot / "tests/diagnostics")) {
    if (e.path().extension() != ".qd") continue;
    std::istringstream in(readFile(e.path()));
    for (std::string line; std::getline(in, line);)
      if (line.find("// expect: ") != std::string::npos) out += line + "\n";
  }
  return out;
}

// Codes no .qd text can produce, with the test that produces them instead.
const std::map<std::string, std::string> kNotFromSource = {
    {"E0001", "tests/unit/pipeline/DiagnosticsCorpusTest.cpp"},  // about reading the file itself
};

// docs/diagnostics.md: the "## stage" section and title of each "| CODE | title | ... |" row.
struct DocumentedCode {
  std::string stage, title;
};
std::map<std::string, DocumentedCode> documentedCodes() {
  std::map<std::string, DocumentedCode> out;
  std::istringstream in(readFile(kRoot / "docs/diagnostics.md"));
  std::string stage;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) stage = line.substr(3);
    if (line.size() < 9 || line.rfind("| ", 0) != 0 || (line[2] != 'E' && line[2] != 'W')) continue;
    std::string code = line.substr(2, 5);
    size_t titleEnd = line.find(" |", 10);
    if (line.compare(7, 3, " | ") == 0 && titleEnd != std::string::npos)
      out[code] = {stage, line.substr(10, titleEnd - 10)};
  }
  return out;
}

TEST(DiagnosticRegistry, CodesAreWellFormedAndUnique) {
  std::set<std::string_view> seen;
  for (const auto& c : allDiagCodes()) {
    EXPECT_TRUE(seen.insert(c.name).second) << c.name;
    EXPECT_EQ(c.name.size(), 5u) << c.name;
    EXPECT_TRUE(c.name[0] == 'E' || c.name[0] == 'W') << c.name;
    EXPECT_FALSE(c.title.empty()) << c.name;
    EXPECT_EQ(diagCodeName(c.code), c.name);
  }
}

TEST(DiagnosticRegistry, EveryCodeIsReportedByTheCompiler) {
  std::string sources = allText(kRoot / "compiler", {".cpp", ".h"});
  for (const auto& c : allDiagCodes())
    EXPECT_NE(sources.find("DiagCode::" + std::string(c.name)), std::string::npos)
        << c.name << " is registered but no call site in compiler/ reports it: use it or remove it";
}

TEST(DiagnosticRegistry, EveryCodeIsDocumentedUnderItsStage) {
  std::map<std::string, DocumentedCode> documented = documentedCodes();
  for (const auto& c : allDiagCodes()) {
    auto it = documented.find(std::string(c.name));
    if (it == documented.end()) {
      ADD_FAILURE() << c.name << " (" << c.title << ") has no row in docs/diagnostics.md";
      continue;
    }
    EXPECT_EQ(it->second.stage, c.stage) << c.name << ": documented under the wrong stage";
    EXPECT_EQ(it->second.title, c.title) << c.name << ": the title differs from DiagnosticCodes.def";
    documented.erase(it);
  }
  for (const auto& [code, doc] : documented) ADD_FAILURE() << code << " is documented but not registered";
}

TEST(DiagnosticRegistry, EveryCodeIsProducedByATestInput) {
  std::string expected = corpusExpectations();
  for (const auto& c : allDiagCodes()) {
    std::string tag = "[" + std::string(c.name) + "]: ";
    if (auto it = kNotFromSource.find(std::string(c.name)); it != kNotFromSource.end()) {
      EXPECT_NE(readFile(kRoot / it->second).find(tag), std::string::npos) << c.name << " is not tested in " << it->second;
      continue;
    }
    EXPECT_NE(expected.find(tag), std::string::npos)
        << c.name << " is produced by no file in tests/diagnostics/: add one with its // expect: line";
  }
}

// Stage READMEs point to docs/diagnostics.md instead of keeping tables of their own.
TEST(DiagnosticRegistry, StageReadmesDoNotRepeatTheTables) {
  for (const auto& e : fs::directory_iterator(kRoot / "compiler")) {
    fs::path readme = e.path() / "README.md";
    if (!fs::exists(readme)) continue;
    std::istringstream in(readFile(readme));
    for (std::string line; std::getline(in, line);)
      EXPECT_FALSE(line.rfind("| E0", 0) == 0 || line.rfind("| W0", 0) == 0)
          << readme << " repeats a row of docs/diagnostics.md: " << line;
  }
}

}  // namespace
}  // namespace qdot::test
