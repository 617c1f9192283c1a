// Every ABI call goes to the second tier once it has been published (one acquire load per call),
// else to the first. The table (names, sizes, Jacobian pattern) is the first tier's: both tiers
// are built from the same kernels. lastError asks whichever tier made the last call.
#include "sim/TieredModel.h"

#include <chrono>
#include <thread>

namespace qdot::rt {
namespace {

struct Tiered : QdotModel {
  ModelPtr first;
  std::atomic<QdotModel*> second{nullptr};  // owned (published once, released by destroy)
  std::atomic<bool> cancel{false};
  std::thread compiler;
  std::chrono::steady_clock::time_point created = std::chrono::steady_clock::now();
  std::atomic<bool> done{false};     // the compile thread has finished (release)
  std::atomic<double> readySeconds{0};
  mutable const QdotModel* last = nullptr;  // the tier of the last call (solver thread only)
  mutable uint64_t firstCalls = 0, secondCalls = 0;

  const QdotModel& active() const {
    const QdotModel* m = second.load(std::memory_order_acquire);
    if (m) ++secondCalls;
    else m = first.get(), ++firstCalls;
    last = m;
    return *m;
  }

  void join() {
    cancel.store(true);
    if (compiler.joinable()) compiler.join();
  }
};

const Tiered& self(const QdotModel* s) { return *static_cast<const Tiered*>(s); }

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const QdotModel& m = self(s).active();
  return m.parameters(&m, given, overridden, p);
}
int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const QdotModel& m = self(s).active();
  return m.initialValues(&m, p, t0, y0, yp0, nominal);
}
int fixedStarts(const QdotModel* s, int32_t* fixed) {
  const QdotModel& m = self(s).active();
  return m.fixedStarts(&m, fixed);
}
int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
  const QdotModel& m = self(s).active();
  return m.residual(&m, t, y, yp, p, F);
}
int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
             double* values) {
  const QdotModel& m = self(s).active();
  return m.jacobian(&m, t, y, yp, p, cj, values);
}
int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  const QdotModel& m = self(s).active();
  return m.outputs(&m, t, y, yp, p, out);
}
int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  const QdotModel& m = self(s).active();
  return m.invariants(&m, t, y, yp, p, out);
}
const char* lastError(const QdotModel* s) {
  const QdotModel* m = self(s).last ? self(s).last : self(s).first.get();
  return m->lastError(m);
}
void destroy(QdotModel* s) {
  auto* t = static_cast<Tiered*>(s);
  t->join();
  ModelPtr second(t->second.load());
  delete t;
}

}  // namespace

ModelPtr createTieredModel(ModelPtr first, TierCompiler compile) {
  auto* t = new Tiered();
  static_cast<QdotModel&>(*t) = *first;  // sizes, names, pattern: the first tier's
  t->first = std::move(first);
  t->parameters = parameters, t->initialValues = initialValues, t->fixedStarts = fixedStarts;
  t->residual = residual, t->jacobian = jacobian, t->outputs = outputs, t->invariants = invariants;
  t->lastError = lastError, t->destroy = destroy;
  t->compiler = std::thread([t, compile = std::move(compile)] {
    ModelPtr second = compile(t->cancel);
    if (second && t->cancel.load()) second.reset();  // too late: the run is over
    if (second) {
      t->readySeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t->created).count();
      t->second.store(second.release(), std::memory_order_release);
    }
    t->done.store(true, std::memory_order_release);
  });
  return ModelPtr(t);
}

std::optional<TierReport> tierReport(const QdotModel* model) {
  if (!model || model->destroy != destroy) return std::nullopt;
  const Tiered& t = self(model);
  TierReport r;
  r.compiling = !t.done.load(std::memory_order_acquire);
  r.ready = t.second.load(std::memory_order_acquire) != nullptr;
  r.readySeconds = r.ready ? t.readySeconds.load() : 0;
  r.firstTierCalls = t.firstCalls;
  r.secondTierCalls = t.secondCalls;
  return r;
}

}  // namespace qdot::rt
