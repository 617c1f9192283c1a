// libFuzzer entry point for the serialised form (bc::deserialize, vm/Runs.h) and the VM behind it.
// An input is a model and, after a NUL byte, edits: the model (the pipeline fuzzer's corpus) is
// compiled to bytecode the way `qdot build` does and serialised; each edit (3 bytes: a position
// and a byte) overwrites one byte of those bytes, a 4th trailing byte truncates them. So the reader
// sees bytes close to real modules — runs, templates and counts slightly wrong — rather than noise
// it refuses at the header. No input may crash or hang, and:
// - bytes that read back are a module that validates, `serialize` of it reads back to the same
//   module, and every program of it runs on the VM (inputs of the sizes the description gives);
// - unedited bytes always read back.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "qdot/bytecode.h"
#include "qdot/model_adapter.hpp"
#include "vm/Vm.h"

namespace {

using namespace qdot;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// Runs every program once at t = 0, y = y' = 0, the default parameters: validated bytecode is safe
// to run whatever its values (a non-finite value is an error it reports, not a crash).
void runEveryProgram(const bc::Module& m) {
  Result<ModelPtr> model = vm::createModel(m);
  check(model.ok());
  const QdotModel& q = *model->get();
  const ModelDescription& d = m.description;
  std::vector<double> p(d.parameterCount()), y(d.variableCount()), yp(d.variableCount());
  std::vector<double> given(d.parameterCount());
  std::vector<uint8_t> overridden(d.parameterCount());
  ModelCall call{.t = 0, .cj = 1, .y = y.data(), .yp = yp.data(), .p = p.data(), .given = given.data(),
                 .overridden = overridden.data()};
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    std::vector<double> out(std::max<size_t>(d.outputCount(programAt(i)), 1));
    callProgram(q, programAt(i), call, out.data());
    if (programAt(i) == ModelProgram::Parameters && d.parameterCount()) std::memcpy(p.data(), out.data(), p.size() * 8);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const uint8_t* nul = static_cast<const uint8_t*>(std::memchr(data, 0, size));
  size_t textSize = nul ? static_cast<size_t>(nul - data) : size;
  driver::Compilation c;
  c.options.limits.maxScalars = 2'000;
  c.options.keepLoops = c.options.eliminateAlgebraics = c.options.rerollRows = true;  // as qdot build
  c.options.rerollMinimumRun = 2;
  if (!driver::compileSource(c, "fuzz.qd", std::string(reinterpret_cast<const char*>(data), textSize), "",
                             driver::Stage::Dae))
    return 0;
  std::vector<sym::Expr> residuals;  // a dense model's symbolic Jacobian is O(n^3): not what is fuzzed here
  for (const auto& e : c.dae->equations)
    if (e.residual) residuals.push_back(e.residual);
  if (c.ctx.dagSize(residuals) > 2'000 || !driver::continueTo(c, driver::Stage::Bytecode)) return 0;
  std::vector<uint8_t> bytes = bc::serialize(*c.bytecode);
  const uint8_t* edits = nul ? nul + 1 : data + size;
  size_t editBytes = static_cast<size_t>(data + size - edits);
  for (size_t k = 0; k + 3 <= editBytes && !bytes.empty(); k += 3)
    bytes[(edits[k] | size_t{edits[k + 1]} << 8) % bytes.size()] = edits[k + 2];
  if (editBytes % 3 == 1) bytes.resize(bytes.size() * edits[editBytes - 1] / 256);
  Result<bc::Module> read = bc::deserialize(bytes);
  check(read.ok() || editBytes > 0);
  if (!read) return 0;
  check(bc::validate(read.value()).ok());
  std::vector<uint8_t> again = bc::serialize(read.value());
  Result<bc::Module> reread = bc::deserialize(again);
  check(reread.ok() && bc::serialize(reread.value()) == again);
  runEveryProgram(read.value());
  return 0;
}
