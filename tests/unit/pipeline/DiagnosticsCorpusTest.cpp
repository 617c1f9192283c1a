// Runs every model in tests/diagnostics/ through the front end and the kernel stage and compares
// the reported diagnostics with the file's own expectations, written as comments:
//   // expect: LINE:COL: error[CODE]: exact message
//   // help: exact help line (optional; each must be among the rendered help lines)
// Every expected diagnostic must be reported and nothing else (exact location, code and message).
#include <algorithm>
#include <filesystem>

#include "CompiledModel.h"
#include "kernel/Kernel.h"

namespace qdot::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> corpusFiles() {
  std::vector<std::string> files;
  const fs::path root = std::string(QDOT_SOURCE_DIR) + "/tests/diagnostics";
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.path().extension() == ".qd") files.push_back(fs::relative(e.path(), root).string());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> expectations(const std::string& text, const std::string& marker = "// expect: ") {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (auto p = line.find(marker); p != std::string::npos) out.push_back(line.substr(p + marker.size()));
  return out;
}

// "LINE:COL: severity[CODE]: message" of each reported diagnostic (notes and help lines are not compared).
std::vector<std::string> reported(driver::Compilation& c) {
  std::vector<std::string> out;
  for (const auto& d : c.diags.diagnostics()) {
    std::ostringstream os;
    DiagnosticEngine::renderOne(os, c.sources, d, false);
    std::string first = os.str().substr(0, os.str().find('\n'));
    if (d.range.valid()) first = first.substr(first.find(':') + 1);  // drop the file name
    out.push_back(first);
  }
  return out;
}

class DiagnosticsCorpus : public ::testing::TestWithParam<std::string> {};

TEST_P(DiagnosticsCorpus, ReportsExactlyTheExpectedDiagnostics) {
  std::string text = readSource("tests/diagnostics/" + GetParam());
  std::vector<std::string> expected = expectations(text);
  ASSERT_FALSE(expected.empty()) << "a corpus file must state what it expects";
  driver::Compilation c;
  driver::compileSource(c, GetParam(), text, "", driver::Stage::Kernel);  // every check short of solving
  EXPECT_TRUE(c.diags.hasErrors());
  std::vector<std::string> got = reported(c);
  std::ostringstream all;
  c.diags.render(all, c.sources);
  for (const auto& e : expected)
    EXPECT_NE(std::find(got.begin(), got.end(), e), got.end()) << "missing: " << e << "\nreported:\n" << all.str();
  for (const auto& g : got)
    EXPECT_NE(std::find(expected.begin(), expected.end(), g), expected.end()) << "unexpected: " << g;
  for (const auto& h : expectations(text, "// help: "))
    EXPECT_NE(all.str().find("\nhelp: " + h + "\n"), std::string::npos) << "missing help: " << h << "\n" << all.str();
  // Every error names its location and shows the line with a caret.
  for (const auto& d : c.diags.diagnostics())
    if (d.range.valid()) {
      EXPECT_NE(all.str().find('^'), std::string::npos);
    }
}

// E0001 is about reading the file itself, so no corpus text can produce it.
TEST(DiagnosticsOfTheFile, AMissingFileIsReported) {
  driver::Compilation c;
  std::string path = std::string(QDOT_SOURCE_DIR) + "/tests/diagnostics/missing.qd";
  EXPECT_FALSE(driver::compileFile(c, path, "", driver::Stage::Dae));
  std::ostringstream rendered;
  c.diags.render(rendered, c.sources);
  EXPECT_EQ(rendered.str(), "error[E0001]: cannot open file '" + path + "'\nhelp: check the path of the model file\n");
}

INSTANTIATE_TEST_SUITE_P(Corpus, DiagnosticsCorpus, ::testing::ValuesIn(corpusFiles()),
                         [](const auto& info) {
                           std::string n = info.param.substr(0, info.param.size() - 3);
                           std::replace_if(n.begin(), n.end(), [](char ch) { return !std::isalnum(ch); }, '_');
                           return n;
                         });

}  // namespace
}  // namespace qdot::test
