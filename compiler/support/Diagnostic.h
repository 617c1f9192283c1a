// Diagnostic + DiagnosticEngine: the one way any stage reports a problem to the user.
// Stages report into the engine and never print; the driver renders the collected diagnostics as
//   file:line:col: error[E012]: message
//      | source line
//      |     ^~~~
//   help: what to do
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "support/DiagnosticCodes.h"
#include "support/SourceManager.h"

namespace qdot {

enum class Severity { Error, Warning, Note };

/// A labelled secondary location ("note: declared here").
struct DiagnosticNote {
  SourceRange range;
  std::string message;
};

struct Diagnostic {
  Severity severity = Severity::Error;
  DiagCode code{};      ///< registered in support/DiagnosticCodes.def; see docs/diagnostics.md
  SourceRange range;    ///< primary location (may be invalid for whole-run errors)
  std::string message;  ///< what is wrong, one sentence, no trailing period
  std::string help;     ///< what to do (empty if nothing useful to say)
  std::vector<DiagnosticNote> notes;
};

class DiagnosticEngine {
 public:
  /// Stops collecting (and sets `limitReached`) after this many errors, so garbage input stays fast.
  explicit DiagnosticEngine(size_t errorLimit = 50) : errorLimit_(errorLimit) {}

  void report(Diagnostic d);
  /// Shorthand for the common case; returns the stored diagnostic so notes can be added.
  Diagnostic& error(SourceRange range, DiagCode code, std::string message, std::string help = {});
  Diagnostic& warning(SourceRange range, DiagCode code, std::string message, std::string help = {});

  size_t errorCount() const { return errors_; }
  bool hasErrors() const { return errors_ > 0; }
  bool limitReached() const { return errors_ >= errorLimit_; }
  const std::vector<Diagnostic>& diagnostics() const { return diags_; }

  /// Renders every diagnostic in report order (caret, help, notes).
  void render(std::ostream& os, const SourceManager& sm, bool color = false) const;
  static void renderOne(std::ostream& os, const SourceManager& sm, const Diagnostic& d, bool color);

 private:
  std::vector<Diagnostic> diags_;
  Diagnostic overflow_;  // sink once the limit is reached
  size_t errors_ = 0;
  size_t errorLimit_;
};

}  // namespace qdot
