// qdot modes and qdot linearize (see Modes.h).
#include "driver/Modes.h"

#include "sim/Names.h"
#include "sim/RunOptions.h"
#include "vm/Vm.h"

namespace qdot::driver {
namespace {

LinearizeResult failed(ExitCode code, std::string why) {
  LinearizeResult r;
  r.code = code;
  r.error = std::move(why);
  return r;
}

}  // namespace

LinearizeResult linearizeModel(Compilation& c, const std::vector<std::string>& parameters, linear::OperatingPoint at) {
  if (!continueTo(c, Stage::Bytecode)) return failed(ExitCode::ModelError, "the model has errors");
  Result<ModelPtr> model = vm::createModel(*c.bytecode);
  if (!model) return failed(ExitCode::Internal, model.error());
  const QdotModel& m = *model.value();
  linear::ModelValues values;
  values.time = c.dae->experiment.startTime.value_or(0.0);
  try {
    values.parameters = rt::evaluateParameters(m, rt::parameterOverrides(m, parameters));
  } catch (const rt::UsageError& e) {
    return failed(ExitCode::Usage, e.what());
  } catch (const std::exception& e) {
    return failed(ExitCode::ModelError, e.what());
  }
  values.start.resize(m.nVariables);
  if (m.initialValues(&m, values.parameters.data(), values.time, values.start.data(), nullptr, nullptr) != 0)
    return failed(ExitCode::ModelError, std::string("the start values cannot be computed: ") + m.lastError(&m));
  linear::Linearization l = linear::linearize(*c.dae, c.ctx, values, at);
  if (!l.error.empty()) return failed(ExitCode::ModelError, l.error);
  LinearizeResult r;
  r.model = std::move(l.model);
  return r;
}

ModesResult computeModes(Compilation& c, const std::vector<std::string>& parameters, linear::OperatingPoint at) {
  LinearizeResult l = linearizeModel(c, parameters, at);
  ModesResult r{l.code, std::move(l.error), std::move(l.model), {}};
  if (r.error.empty()) r.modes = linear::modes(r.system);
  return r;
}

}  // namespace qdot::driver
