// Runs every file of tests/diagnostics/syntax/ through the parser alone and demands exactly the
// diagnostics the file states, in order, as `// expect: LINE:COL: error[CODE]: message` comments
// (the format of the pipeline's diagnostics corpus).
#include <algorithm>
#include <filesystem>
#include <fstream>

#include "SyntaxTestUtil.h"

namespace qdot::testing {
namespace {

namespace fs = std::filesystem;

std::string corpusDir() { return std::string(QDOT_SOURCE_DIR) + "/tests/diagnostics/syntax"; }

std::vector<std::string> corpusFiles() {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(corpusDir()))
    if (e.path().extension() == ".qd") files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> expectations(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  const std::string marker = "// expect: ";
  for (std::string line; std::getline(in, line);)
    if (auto p = line.find(marker); p != std::string::npos) out.push_back(line.substr(p + marker.size()));
  return out;
}

class SyntaxCorpus : public ::testing::TestWithParam<std::string> {};

TEST_P(SyntaxCorpus, ReportsExactlyTheExpectedDiagnostics) {
  std::ifstream in(corpusDir() + "/" + GetParam(), std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> expected = expectations(text);
  ASSERT_FALSE(expected.empty()) << "a corpus file must state what it expects";
  auto p = parseText(text);
  std::vector<std::string> got;
  for (const auto& d : p->diags.diagnostics()) {
    std::ostringstream os;
    DiagnosticEngine::renderOne(os, p->sm, d, false);
    std::string first = os.str().substr(0, os.str().find('\n'));
    got.push_back(first.substr(first.find(':') + 1));  // drop the file name
  }
  EXPECT_EQ(got, expected) << p->rendered();
}

INSTANTIATE_TEST_SUITE_P(Corpus, SyntaxCorpus, ::testing::ValuesIn(corpusFiles()), [](const auto& info) {
  std::string name = info.param.substr(0, info.param.size() - 3);
  std::replace_if(name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
  return name;
});

}  // namespace
}  // namespace qdot::testing
