// Test helper shared by the stage tests that start from .qd text: compiles it through the
// driver's pipeline (driver/Pipeline.h) up to a given stage and keeps every result; the members
// name the stages' results the way the tests use them. Header-only: tests/unit/common has no
// .cpp, so it is not a test binary of its own.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "driver/Pipeline.h"

namespace qdot::test {

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The pipeline's results for one source text up to `until`; `dae` is empty (and the test failed)
/// on errors.
struct SourceDae {
  SourceDae(const std::string& name, const std::string& text, driver::Stage until = driver::Stage::Dae,
            const llvmbackend::JitOptions& jit = {}) {
    compilation.options.jit = jit;
    if (!driver::compileSource(compilation, name, text, "", until)) {
      std::ostringstream rendered;
      diags.render(rendered, sources);
      ADD_FAILURE() << name << ":\n" << rendered.str() << compilation.internalError;
      dae.reset();
    }
  }
  SourceDae(const SourceDae&) = delete;

  driver::Compilation compilation;
  SourceManager& sources = compilation.sources;
  DiagnosticEngine& diags = compilation.diags;
  sym::Context& ctx = compilation.ctx;
  std::optional<dae::Dae>& dae = compilation.dae;
};

}  // namespace qdot::test
