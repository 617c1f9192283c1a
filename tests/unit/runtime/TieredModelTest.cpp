// rt::TieredModel on two stand-in models whose residuals differ (1.0 against 2.0), so each call
// shows which tier answered: the first until the compile thread publishes the second, the second
// after; destroy cancels a compile that is still running and releases both tiers.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "sim/TieredModel.h"

namespace qdot::rt::test {
namespace {

struct StandIn : QdotModel {
  double value = 0;
  std::string error;
  std::atomic<int>* destroyed = nullptr;
  int callMilliseconds = 0;  ///< how long a residual call takes
};

ModelPtr standIn(double value, std::atomic<int>* destroyed) {
  auto* m = new StandIn();
  m->abiVersion = QDOT_MODEL_ABI_VERSION;
  m->nVariables = 1;
  m->value = value;
  m->error = "tier " + std::to_string(static_cast<int>(value));
  m->destroyed = destroyed;
  m->residual = [](const QdotModel* s, double, const double*, const double*, const double*, double* F) {
    std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<const StandIn*>(s)->callMilliseconds));
    F[0] = static_cast<const StandIn*>(s)->value;
    return 0;
  };
  m->outputs = [](const QdotModel* s, double, const double*, const double*, const double*, double* out) {
    out[0] = static_cast<const StandIn*>(s)->value;
    return 0;
  };
  m->parameters = [](const QdotModel* s, const double*, const uint8_t*, double* p) {
    p[0] = static_cast<const StandIn*>(s)->value;
    return 0;
  };
  m->lastError = [](const QdotModel* s) { return static_cast<const StandIn*>(s)->error.c_str(); };
  m->destroy = [](QdotModel* s) {
    auto* self = static_cast<StandIn*>(s);
    ++*self->destroyed;
    delete self;
  };
  return ModelPtr(m);
}

double residualOf(const QdotModel* m, double t = 0) {
  double y = 0, yp = 0, F = -1;
  EXPECT_EQ(m->residual(m, t, &y, &yp, nullptr, &F), 0);
  return F;
}

double outputOf(const QdotModel* m) {
  double y = 0, yp = 0, out = -1;
  EXPECT_EQ(m->outputs(m, 0, &y, &yp, nullptr, &out), 0);
  return out;
}

// Calls the residual until the second tier answers (bounded by a deadline).
void waitForTheSecondTier(const QdotModel* m) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((residualOf(m) != 2.0 || tierReport(m)->compiling) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::yield();
}

TEST(TieredModel, RunsTheFirstTierUntilTheSecondIsReadyThenTheSecond) {
  std::atomic<int> destroyed{0};
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  ModelPtr tiered = createTieredModel(standIn(1.0, &destroyed), [&, released](const std::atomic<bool>&) {
    released.wait();
    return standIn(2.0, &destroyed);
  });
  QdotModel* m = tiered.get();
  EXPECT_EQ(m->nVariables, 1u);  // the first tier's table
  EXPECT_EQ(residualOf(m), 1.0);
  EXPECT_EQ(residualOf(m), 1.0);
  EXPECT_STREQ(m->lastError(m), "tier 1");
  release.set_value();
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((residualOf(m) != 2.0 || tierReport(m)->compiling) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::yield();
  EXPECT_EQ(residualOf(m), 2.0);
  EXPECT_STREQ(m->lastError(m), "tier 2");
  std::optional<TierReport> report = tierReport(m);
  ASSERT_TRUE(report.has_value());
  EXPECT_TRUE(report->ready);
  EXPECT_FALSE(report->compiling);
  EXPECT_GE(report->firstTierCalls, 2u);
  EXPECT_GE(report->secondTierCalls, 2u);
  tiered.reset();
  EXPECT_EQ(destroyed.load(), 2);
}

// With the compile's expected duration, a call waits for the second tier when the first tier's
// calls take longer than what is left of the compile (100 ms calls, a 200 ms compile expected to
// take 150 ms: after the first call 50 ms are left); without it, or with calls shorter than that,
// the first tier answers while the compile runs.
TEST(TieredModel, ACallLongerThanTheRestOfTheCompileWaitsForTheSecondTier) {
  for (auto [callMs, expected, waits] : {std::tuple{100, 0.15, true}, std::tuple{100, 0.0, false}, std::tuple{5, 0.15, false}}) {
    std::atomic<int> destroyed{0};
    ModelPtr first = standIn(1.0, &destroyed);
    static_cast<StandIn*>(first.get())->callMilliseconds = callMs;
    ModelPtr tiered = createTieredModel(
        std::move(first),
        [&](const std::atomic<bool>&) {
          std::this_thread::sleep_for(std::chrono::milliseconds(200));
          return standIn(2.0, &destroyed);
        },
        {}, expected);
    QdotModel* m = tiered.get();
    EXPECT_EQ(residualOf(m), 1.0);  // nothing to go by before the first call
    EXPECT_EQ(residualOf(m), waits ? 2.0 : 1.0) << callMs << " ms calls, " << expected << " s expected";
    EXPECT_EQ(tierReport(m)->callsThatWaited, waits ? 1u : 0u);
    tiered.reset();
    EXPECT_EQ(destroyed.load(), 2);
  }
}

TEST(TieredModel, DestroyCancelsACompileStillRunning) {
  std::atomic<int> destroyed{0};
  std::atomic<bool> sawCancel{false};
  ModelPtr tiered = createTieredModel(standIn(1.0, &destroyed), [&](const std::atomic<bool>& cancel) -> ModelPtr {
    while (!cancel.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    sawCancel = true;
    return nullptr;  // gave up
  });
  QdotModel* m = tiered.get();
  EXPECT_EQ(residualOf(m), 1.0);
  std::optional<TierReport> report = tierReport(m);
  ASSERT_TRUE(report.has_value());
  EXPECT_FALSE(report->ready);
  EXPECT_TRUE(report->compiling);
  EXPECT_EQ(report->firstTierCalls, 1u);
  tiered.reset();
  EXPECT_TRUE(sawCancel.load());
  EXPECT_EQ(destroyed.load(), 1);
}

TEST(TieredModel, ASecondTierFinishedAfterTheRunIsReleasedUnused) {
  std::atomic<int> destroyed{0};
  ModelPtr tiered = createTieredModel(standIn(1.0, &destroyed), [&](const std::atomic<bool>& cancel) {
    while (!cancel.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return standIn(2.0, &destroyed);  // finished anyway
  });
  QdotModel* m = tiered.get();
  EXPECT_EQ(residualOf(m), 1.0);
  tiered.reset();
  EXPECT_EQ(destroyed.load(), 2);
}

TEST(TieredModel, TheTriggerStartsTheCompileAndSeesTheProgress) {
  std::atomic<int> destroyed{0};
  std::vector<TierObservation> seen;
  ModelPtr tiered = createTieredModel(
      standIn(1.0, &destroyed), [&](const std::atomic<bool>&) { return standIn(2.0, &destroyed); },
      [&](const TierObservation& o) {
        seen.push_back(o);
        return o.progress >= 0.5;
      });
  QdotModel* m = tiered.get();
  setTierHorizon(m, 10, 20);
  for (int k = 1; k < 40; ++k) EXPECT_EQ(residualOf(m, 10 + k * 0.1), 1.0);  // up to t = 13.9
  std::optional<TierReport> report = tierReport(m);
  EXPECT_FALSE(report->started);
  EXPECT_FALSE(report->compiling);
  EXPECT_NEAR(report->startedAt.progress, 0.39, 1e-12);
  ASSERT_FALSE(seen.empty());
  EXPECT_NEAR(seen.front().progress, 0.08, 1e-12);  // asked first after 8 calls, at t = 10.8
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_GT(seen[i].progress, seen[i - 1].progress);
    EXPECT_GT(seen[i].recentProgress, 0);
    EXPECT_LE(seen[i].recentProgress, seen[i].progress);
    EXPECT_GE(seen[i].firstTierSeconds, seen[i - 1].firstTierSeconds);
  }
  for (int k = 40; k <= 60; ++k) residualOf(m, 10 + k * 0.1);
  EXPECT_TRUE(tierReport(m)->started);
  EXPECT_GE(tierReport(m)->startedAt.progress, 0.5);
  waitForTheSecondTier(m);
  EXPECT_EQ(residualOf(m), 2.0);
}

// The calls a run repeats (residual and Jacobian per step, outputs per row) move to the second
// tier and are counted as first-tier time before it; what runs once per run (parameters, start
// values) stays on the first.
TEST(TieredModel, TheCallsARunRepeatsMoveToTheSecondTier) {
  std::atomic<int> destroyed{0};
  std::vector<TierObservation> seen;
  ModelPtr tiered = createTieredModel(
      standIn(1.0, &destroyed), [&](const std::atomic<bool>&) { return standIn(2.0, &destroyed); },
      [&](const TierObservation& o) {
        seen.push_back(o);
        return o.firstTierCalls >= 16;
      });
  QdotModel* m = tiered.get();
  for (int k = 0; k < 8; ++k) EXPECT_EQ(outputOf(m), 1.0);
  EXPECT_EQ(tierReport(m)->firstTierCalls, 8u);
  ASSERT_EQ(seen.size(), 1u);  // asked after 8 calls, outputs among them
  for (int k = 0; k < 8; ++k) EXPECT_EQ(residualOf(m), 1.0);
  EXPECT_TRUE(tierReport(m)->started);
  waitForTheSecondTier(m);
  EXPECT_EQ(outputOf(m), 2.0);
  EXPECT_STREQ(m->lastError(m), "tier 2");
  double p = -1;
  EXPECT_EQ(m->parameters(m, nullptr, nullptr, &p), 0);
  EXPECT_EQ(p, 1.0);  // once per run: not worth moving
  EXPECT_STREQ(m->lastError(m), "tier 1");
}

TEST(TieredModel, ReportIsOnlyForTieredModels) {
  std::atomic<int> destroyed{0};
  ModelPtr plain = standIn(1.0, &destroyed);
  EXPECT_FALSE(tierReport(plain.get()).has_value());
}

}  // namespace
}  // namespace qdot::rt::test
