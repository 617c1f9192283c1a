// libFuzzer entry point for the front end: lexes and parses the input, renders the diagnostics
// and dumps the tree to a null stream, and checks invariants (diagnostic ranges inside the file,
// registered codes of the syntax stage, error limit respected, toSource of every parsed binding
// reparses to itself).
// A violated invariant traps, so libFuzzer reports it like a crash.
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>

#include "ast/ASTPrinter.h"
#include "support/Diagnostic.h"
#include "support/DiagnosticCodes.h"
#include "syntax/Lexer.h"
#include "syntax/Parser.h"

namespace {

using namespace qdot;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// Lexes the whole input on its own (the parser may stop early), checking token ranges.
void lexAll(const SourceManager& sm, uint32_t file) {
  DiagnosticEngine diags;
  syntax::Lexer lexer(sm, file, diags);
  uint32_t last = 0;
  for (syntax::Token t = lexer.next();; t = lexer.next()) {
    check(t.range.begin >= last && t.range.end >= t.range.begin && t.range.end <= sm.text(file).size());
    last = t.range.end;
    if (t.is(syntax::TokenKind::eof)) break;
  }
}

// Printing a parsed expression and parsing the print must give the same print again.
void checkRoundTrip(const ast::Expr& e) {
  std::string printed = ast::toSource(e);
  SourceManager sm;
  uint32_t file = sm.addBuffer("roundtrip.qd", "model M Real v = " + printed + "; end M;");
  DiagnosticEngine diags;
  auto def = syntax::parse(sm, file, diags);
  check(!diags.hasErrors());
  const auto& decls = def->classes.at(0)->declarations;
  check(decls.size() == 1 && decls[0].binding);
  check(ast::toSource(*decls[0].binding) == printed);
}

void checkTree(const ast::ClassDef& cls) {
  for (const auto& d : cls.declarations)
    if (d.binding && d.binding->kind != ast::ExprKind::String) checkRoundTrip(*d.binding);
  for (const auto& nested : cls.classes) checkTree(*nested);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  SourceManager sm;
  uint32_t file = sm.addBuffer("fuzz.qd", std::string(reinterpret_cast<const char*>(data), size));
  lexAll(sm, file);
  DiagnosticEngine diags;
  auto def = syntax::parse(sm, file, diags);
  check(def != nullptr);
  check(diags.diagnostics().size() <= 50);
  for (const auto& d : diags.diagnostics()) {
    check(d.range.valid() && d.range.begin <= d.range.end && d.range.end <= size);
    check(static_cast<size_t>(d.code) < allDiagCodes().size() && !d.message.empty());
    check(diagCodeInfo(d.code).stage == "syntax");
  }
  std::ostream null(nullptr);
  diags.render(null, sm);
  ast::printAST(null, *def, sm);
  if (!diags.hasErrors())
    for (const auto& cls : def->classes) checkTree(*cls);
  return 0;
}
