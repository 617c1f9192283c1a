// Test helper: runs the front end by hand from .qd text to a kernel::KernelModule (parse → check →
// flatten → derive → DAE → kernel), then compiles it with the LLVM JIT. The kernel reference
// interpreter (kernel::interpret) is what the compiled code is compared with.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include "unit/common/SourceDae.h"
#include "kernel/Kernel.h"
#include "llvm/JitModel.h"

namespace qdot::test {

class KernelSource : public SourceDae {
 public:
  /// Compiles `text` (named `name` in locations) to kernels and a JIT model; fails the test on errors.
  KernelSource(const std::string& name, const std::string& text, llvmbackend::JitOptions options = {})
      : SourceDae(name, text) {
    if (!dae) return;
    kernel = kernel::buildKernels(*dae, ctx, diags);
    EXPECT_FALSE(diags.hasErrors());
    options.verifyIR = true;
    std::string error;
    model = llvmbackend::createJitModel(kernel, sources, options, error, &stats);
    EXPECT_NE(model, nullptr) << error;
  }
  KernelSource(const KernelSource&) = delete;
  ~KernelSource() {
    if (model) model->destroy(model);
  }
  bool ok() const { return model != nullptr; }

  kernel::KernelModule kernel;
  llvmbackend::JitStats stats;
  QdotModel* model = nullptr;
};

/// Distance in units in the last place (0 for equal values or two NaNs, huge for NaN against a number).
inline uint64_t ulpDistance(double a, double b) {
  if (a == b) return 0;
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  auto key = [](double x) {
    auto i = std::bit_cast<int64_t>(x);
    return i < 0 ? -static_cast<__int128>(i & INT64_MAX) : static_cast<__int128>(i);
  };
  __int128 d = key(a) - key(b);
  return static_cast<uint64_t>(d < 0 ? -d : d);
}

/// Bitwise identity, except that any two NaNs are equal.
inline bool sameBits(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}

}  // namespace qdot::test
