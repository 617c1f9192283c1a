#include "support/SourceManager.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace qdot {

uint32_t SourceManager::addBuffer(std::string name, std::string text) {
  File f{std::move(name), std::move(text), {0}};
  for (uint32_t i = 0; i < f.text.size(); ++i)
    if (f.text[i] == '\n') f.lineStarts.push_back(i + 1);
  files_.push_back(std::move(f));
  return static_cast<uint32_t>(files_.size() - 1);
}

bool SourceManager::addFile(const std::string& path, uint32_t& fileId, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open file '" + path + "'";
    return false;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  fileId = addBuffer(path, ss.str());
  return true;
}

LineCol SourceManager::lineCol(uint32_t file, uint32_t offset) const {
  const auto& starts = files_[file].lineStarts;
  auto it = std::upper_bound(starts.begin(), starts.end(), offset);
  uint32_t line = static_cast<uint32_t>(it - starts.begin());
  return {line, offset - starts[line - 1] + 1};
}

std::string_view SourceManager::lineText(uint32_t file, uint32_t line) const {
  const File& f = files_[file];
  if (line == 0 || line > f.lineStarts.size()) return {};
  uint32_t b = f.lineStarts[line - 1];
  uint32_t e = line < f.lineStarts.size() ? f.lineStarts[line] : static_cast<uint32_t>(f.text.size());
  while (e > b && (f.text[e - 1] == '\n' || f.text[e - 1] == '\r')) --e;
  return std::string_view(f.text).substr(b, e - b);
}

std::string_view SourceManager::slice(SourceRange r) const {
  if (!r.valid()) return {};
  return std::string_view(files_[r.file].text).substr(r.begin, r.end - r.begin);
}

}  // namespace qdot
