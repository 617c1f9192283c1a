// Test helper shared by stage tests that start from .qd text but link only their own stage library
// (not qdot_pipeline): runs parse → check → flatten → derive → DAE by hand and keeps every result.
// Header-only: tests/unit/common has no .cpp, so it is not a test binary of its own.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "dae/Dae.h"
#include "flatten/Flatten.h"
#include "mechanics/EulerLagrange.h"
#include "sema/Sema.h"
#include "syntax/Parser.h"

namespace qdot::test {

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The front end's results for one source text; `dae` is empty (and the test failed) on errors.
struct SourceDae {
  SourceDae(const std::string& name, const std::string& text) {
    uint32_t file = sources.addBuffer(name, text);
    ast = syntax::parse(sources, file, diags);
    if (!diags.hasErrors()) checked = sema::checkModel(*ast, "", diags);
    if (checked && !diags.hasErrors()) flat = flat::flatten(*checked, ctx, diags);
    if (flat) eom = mech::deriveEquationsOfMotion(*flat, ctx, diags);
    if (eom) dae = dae::buildDae(*flat, *eom, ctx, diags);
    if (!dae || diags.hasErrors()) {
      std::ostringstream rendered;
      diags.render(rendered, sources);
      ADD_FAILURE() << name << ":\n" << rendered.str();
      dae.reset();
    }
  }
  SourceDae(const SourceDae&) = delete;

  SourceManager sources;
  DiagnosticEngine diags;
  sym::Context ctx;
  std::unique_ptr<ast::StoredDefinition> ast;
  std::optional<sema::CheckedModel> checked;
  std::optional<flat::FlatModel> flat;
  std::optional<mech::EquationsOfMotion> eom;
  std::optional<dae::Dae> dae;
};

}  // namespace qdot::test
