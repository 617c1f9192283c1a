// Every residual, Jacobian, output and invariant call goes to the second tier once it has been
// published (one acquire load per call), else to the first, timed (all or a sample); every other
// call goes to the first. The table (names, sizes, Jacobian pattern) is the first tier's: both
// tiers are built from the same kernels.
// lastError asks whichever tier made the last call. The ABI hands out const pointers to the model,
// but the tiered model is ours and mutable: its counters and the trigger live on the solver thread.
#include "sim/TieredModel.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "sim/IdleCores.h"

namespace qdot::rt {
namespace {

using Clock = std::chrono::steady_clock;

// First-tier calls between two questions to the trigger (a few floating-point operations), unless
// the calls take kAskEachCallAbove or more on average (a large model's): then after every call,
// since a question costs nothing beside them and each call waited for is a call not on native code.
constexpr uint64_t kAskEvery = 8;
constexpr double kAskEachCallAbove = 1e-3;
// Calls of at least kLongCall are all timed; shorter ones one in kSparse, counting kSparse times:
// reading the clock twice costs about as much as a call of the smallest models, which the solver
// may make millions of.
constexpr double kLongCall = 2e-6;
constexpr uint64_t kSparse = 16;
// A timed call longer than kOutlier x the mean of the samples so far (once there are
// kSamplesBeforeOutliers) was interrupted: VM calls of one model differ by less (a Jacobian costs a
// few residuals).
constexpr double kOutlier = 16;
constexpr uint64_t kSamplesBeforeOutliers = 8;

double secondsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

// How often the idle cores are read again (a reading costs ~10-20 µs, and only until the compile
// starts): every 2 ms while the gauge answers from instants, so that one taken while the previous
// process was still exiting is outvoted by the first decision (5 ms into a run), then every 5 ms.
constexpr double kIdleReadEvery = 5e-3;
constexpr double kIdleReadEarly = 2e-3;

// What one reading of the clock costs, measured once: a timed call of the smallest models is
// mostly clock, and counting it as model time would overstate what native code can save.
double clockReadSeconds() {
  static const double seconds = [] {
    constexpr int kReads = 64;
    Clock::time_point start = Clock::now();
    for (int i = 0; i < kReads; ++i) (void)Clock::now();
    return secondsBetween(start, Clock::now()) / (kReads + 1);
  }();
  return seconds;
}

struct Tiered : QdotModel {
  ModelPtr first;
  std::atomic<QdotModel*> second{nullptr};  // owned (published once, released by destroy)
  std::atomic<bool> cancel{false};
  TierCompiler compile;
  TierTrigger trigger;
  std::thread compiler;
  double compileSeconds = 0;  // expected (0: unknown)
  Clock::time_point created = Clock::now(), compileStarted, idleRead = created;
  IdleCoreGauge idle;  // read when created, then at most every kIdleReadEarly / kIdleReadEvery
  std::atomic<bool> done{false};  // the compile thread has finished, or never started (release)
  std::atomic<double> readySeconds{0};
  // The solver thread's own: which tier answered last, what the first tier has cost, the horizon.
  const QdotModel* last = nullptr;
  uint64_t firstCalls = 0, secondCalls = 0, callsThatWaited = 0;
  double firstSeconds = 0;
  uint64_t timeEvery = 1, untilTimed = 1;  // calls per timed call, calls until the next one
  bool hasHorizon = false;
  double start = 0, stop = 0, latest = 0;
  bool started = false;
  uint64_t nextQuestion = kAskEvery;
  TierObservation look;  // what the trigger saw last (frozen once it started the compile)
  // The recent window starts at `windowStart`, a look at between a quarter and a half of the
  // progress so far; `nextStart` takes its place once the progress has doubled since.
  TierObservation windowStart, nextStart;

  TierObservation observe() const {
    TierObservation o;
    if (hasHorizon && stop > start) o.progress = std::clamp((latest - start) / (stop - start), 0.0, 1.0);
    o.elapsedSeconds = secondsBetween(created, Clock::now());
    o.firstTierSeconds = firstSeconds;
    o.firstTierCalls = firstCalls;
    o.recentProgress = o.progress - windowStart.progress;
    o.recentFirstTierSeconds = o.firstTierSeconds - windowStart.firstTierSeconds;
    o.idleCores = idle.idleCores();
    return o;
  }

  void refreshIdleCores() {
    Clock::time_point now = Clock::now();
    if (secondsBetween(idleRead, now) < (idle.fromTicks() ? kIdleReadEvery : kIdleReadEarly)) return;
    idleRead = now;
    idle.read();
  }

  void startCompile() {
    started = true;
    compileStarted = Clock::now();
    done.store(false, std::memory_order_release);
    compiler = std::thread([this] {
      ModelPtr model = compile(cancel);
      if (model && cancel.load()) model.reset();  // too late: the run is over
      if (model) {
        readySeconds = secondsBetween(created, Clock::now());
        second.store(model.release(), std::memory_order_release);
      }
      done.store(true, std::memory_order_release);
      done.notify_all();
    });
  }

  // Whether the next call is answered sooner by waiting for the compile than by the first tier:
  // its calls so far took longer on average than what the estimate leaves of the compile.
  // Calls shorter than kAskEachCallAbove never wait (nor read the clock for it): a compile is
  // longer than that until its last moment, and they are the hot path of small models.
  bool worthWaiting() const {
    if (!started || compileSeconds <= 0 || firstSeconds < kAskEachCallAbove * double(firstCalls) || firstCalls == 0 ||
        done.load(std::memory_order_acquire))
      return false;
    double left = compileSeconds - secondsBetween(compileStarted, Clock::now());
    return firstSeconds / double(firstCalls) > left;
  }

  // Asks the trigger every kAskEvery first-tier calls (every call, if they are long) until it
  // starts the compile.
  void consider() {
    if (started) return;
    bool longCalls = firstCalls > 0 && firstSeconds >= kAskEachCallAbove * double(firstCalls);
    if (firstCalls < nextQuestion && !longCalls) return;
    nextQuestion = firstCalls + kAskEvery;
    refreshIdleCores();
    look = observe();
    if (trigger(look)) return startCompile();
    if (look.progress >= 2 * nextStart.progress) windowStart = nextStart, nextStart = look;
  }

  // One timed call, as counted: on a busy machine the solver thread is sometimes descheduled in
  // the middle of one, for milliseconds; a sample far above the mean so far counts as the mean.
  double sample(double seconds) const {
    uint64_t before = firstCalls - 1;
    double mean = before > 0 ? firstSeconds / double(before) : 0;
    if (before >= kSamplesBeforeOutliers && seconds > kOutlier * mean) return mean;
    return std::max(0.0, seconds);
  }

  // Times the call if it is its turn.
  template <class Call>
  int timed(Call call) {
    if (--untilTimed > 0) return call(*first);
    Clock::time_point t0 = Clock::now();
    int status = call(*first);
    firstSeconds += double(timeEvery) * sample(secondsBetween(t0, Clock::now()) - clockReadSeconds());
    timeEvery = firstSeconds < kLongCall * double(firstCalls) ? kSparse : 1;
    untilTimed = timeEvery;
    return status;
  }

  // A residual, Jacobian, output or invariant call: the second tier once published, else the
  // first, timed.
  template <class Call>
  int hot(Call call) {
    if (worthWaiting()) {
      ++callsThatWaited;
      done.wait(false, std::memory_order_acquire);
    }
    if (const QdotModel* m = second.load(std::memory_order_acquire)) {
      ++secondCalls;
      last = m;
      return call(*m);
    }
    last = first.get();
    ++firstCalls;
    int status = timed(call);
    consider();
    return status;
  }

  const QdotModel& cold() {
    last = first.get();
    return *first;
  }

  void join() {
    cancel.store(true);
    if (compiler.joinable()) compiler.join();
  }
};

Tiered& self(const QdotModel* s) { return *const_cast<Tiered*>(static_cast<const Tiered*>(s)); }

int parameters(const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
  const QdotModel& m = self(s).cold();
  return m.parameters(&m, given, overridden, p);
}
int initialValues(const QdotModel* s, const double* p, double t0, double* y0, double* yp0, double* nominal) {
  const QdotModel& m = self(s).cold();
  return m.initialValues(&m, p, t0, y0, yp0, nominal);
}
int fixedStarts(const QdotModel* s, int32_t* fixed) {
  const QdotModel& m = self(s).cold();
  return m.fixedStarts(&m, fixed);
}
int residual(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
  Tiered& tiered = self(s);
  tiered.latest = std::max(tiered.latest, t);
  return tiered.hot([&](const QdotModel& m) { return m.residual(&m, t, y, yp, p, F); });
}
int jacobian(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
             double* values) {
  return self(s).hot([&](const QdotModel& m) { return m.jacobian(&m, t, y, yp, p, cj, values); });
}
int outputs(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return self(s).hot([&](const QdotModel& m) { return m.outputs(&m, t, y, yp, p, out); });
}
int invariants(const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
  return self(s).hot([&](const QdotModel& m) { return m.invariants(&m, t, y, yp, p, out); });
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

ModelPtr createTieredModel(ModelPtr first, TierCompiler compile, TierTrigger trigger, double compileSeconds) {
  auto* t = new Tiered();
  t->compileSeconds = compileSeconds;
  static_cast<QdotModel&>(*t) = *first;  // sizes, names, pattern: the first tier's
  t->first = std::move(first);
  t->parameters = parameters, t->initialValues = initialValues, t->fixedStarts = fixedStarts;
  t->residual = residual, t->jacobian = jacobian, t->outputs = outputs, t->invariants = invariants;
  t->lastError = lastError, t->destroy = destroy;
  t->compile = std::move(compile);
  t->trigger = std::move(trigger);
  t->done.store(true);  // nothing compiles until the trigger says so
  if (t->trigger) t->idle.read();  // where the run's interval starts
  clockReadSeconds();   // measured now rather than inside the first timed call
  if (!t->trigger) t->startCompile();
  return ModelPtr(t);
}

void setTierHorizon(const QdotModel* model, double start, double stop) {
  if (!model || model->destroy != destroy) return;
  Tiered& t = self(model);
  t.hasHorizon = true;
  t.start = start, t.stop = stop, t.latest = start;
}

std::optional<TierReport> tierReport(const QdotModel* model) {
  if (!model || model->destroy != destroy) return std::nullopt;
  const Tiered& t = self(model);
  TierReport r;
  r.started = t.started;
  r.startedAt = t.started || !t.trigger ? t.look : t.observe();
  r.compiling = !t.done.load(std::memory_order_acquire);
  r.ready = t.second.load(std::memory_order_acquire) != nullptr;
  r.readySeconds = r.ready ? t.readySeconds.load() : 0;
  r.firstTierCalls = t.firstCalls;
  r.secondTierCalls = t.secondCalls;
  r.callsThatWaited = t.callsThatWaited;
  r.firstTierSeconds = t.firstSeconds;
  return r;
}

}  // namespace qdot::rt
