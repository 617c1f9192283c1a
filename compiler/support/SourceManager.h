// SourceManager: owns the text of every file the compiler reads and maps byte offsets to
// line/column, so every later stage can carry a compact SourceRange instead of strings.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace qdot {

/// A half-open byte range [begin, end) inside one file of the SourceManager.
struct SourceRange {
  uint32_t file = UINT32_MAX;  ///< index into SourceManager; UINT32_MAX = no location
  uint32_t begin = 0;
  uint32_t end = 0;

  bool valid() const { return file != UINT32_MAX; }
  bool operator==(const SourceRange&) const = default;
  /// The smallest range covering both (same file assumed).
  static SourceRange cover(SourceRange a, SourceRange b) {
    if (!a.valid()) return b;
    if (!b.valid()) return a;
    return {a.file, a.begin < b.begin ? a.begin : b.begin, a.end > b.end ? a.end : b.end};
  }
};

/// 1-based line and column (column counts bytes).
struct LineCol {
  uint32_t line = 0;
  uint32_t col = 0;
};

class SourceManager {
 public:
  /// Adds a buffer; returns its file id.
  uint32_t addBuffer(std::string name, std::string text);
  /// Reads a file from disk; returns false (and leaves `error`) if it cannot be read.
  bool addFile(const std::string& path, uint32_t& fileId, std::string& error);

  const std::string& name(uint32_t file) const { return files_[file].name; }
  std::string_view text(uint32_t file) const { return files_[file].text; }
  LineCol lineCol(uint32_t file, uint32_t offset) const;
  /// The text of the 1-based line, without its newline.
  std::string_view lineText(uint32_t file, uint32_t line) const;
  std::string_view slice(SourceRange r) const;

 private:
  struct File {
    std::string name;
    std::string text;
    std::vector<uint32_t> lineStarts;
  };
  std::vector<File> files_;
};

}  // namespace qdot
