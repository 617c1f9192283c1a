// Where `import Vibration.*;` and other class names not declared in the model's file are found:
// the directories of QDOT_PATH (':'-separated), the model file's own directory, then the standard
// library (`stdlib/` next to qdot, `<prefix>/share/qdot/stdlib` when installed, else the source
// tree qdot was built from). A package `P` is the file `DIR/P/package.qd` or `DIR/P.qd`.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ast/AST.h"
#include "sema/Sema.h"
#include "support/Diagnostic.h"

namespace qdot::driver {

/// The folder of the running program (`<prefix>/bin` installed, the build tree otherwise): where
/// qdot finds what it ships (the standard library; the runtime libraries of `qdot build`).
std::filesystem::path executableDirectory();

/// The directories searched, in order, for a model read from `modelFile` ("" or "-": none of its own).
std::vector<std::string> libraryPath(const std::string& modelFile);

/// Loads library packages on first use: parses the file that declares the top-level class, keeps
/// its tree (sema points into it), reports its syntax errors like the model's.
class LibraryLoader {
 public:
  LibraryLoader(std::vector<std::string> path, SourceManager& sources, DiagnosticEngine& diags)
      : path_(std::move(path)), sources_(sources), diags_(diags) {}
  sema::Library library();

 private:
  const ast::ClassDef* find(const std::string& name);

  std::vector<std::string> path_;
  SourceManager& sources_;
  DiagnosticEngine& diags_;
  std::vector<std::unique_ptr<ast::StoredDefinition>> files_;
};

}  // namespace qdot::driver
