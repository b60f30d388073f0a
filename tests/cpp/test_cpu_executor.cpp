// The CPU executor: its reductions (deterministic, exact up to rounding) and the warm-up of its threads.
#include <gtest/gtest.h>
#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"

using namespace farlio;

namespace {

/// Terms whose double sum depends on the order of the additions.
double term(std::size_t i) { return std::sin(static_cast<double>(i)) * std::pow(10.0, static_cast<double>(i % 17)); }

}  // namespace

TEST(CpuExecutor, AccumulateSumsEveryIndexTheSameWayEachTime) {
  // terms whose double sum depends on the order: a second call gives the same bits (the
  // partition does not depend on the timing), and the sum is the exact one up to rounding
  for (const int threads : {1, 2, 4}) {
    exec::CpuExecutor ex(threads);
    for (const std::size_t n : {std::size_t{1}, std::size_t{255}, std::size_t{1000}, std::size_t{100000}}) {
      const auto add = [](double& acc, std::size_t i) { acc += term(i); };
      const auto plus = [](double a, double b) { return a + b; };
      const double first = ex.accumulate(n, 0.0, add, plus);
      EXPECT_EQ(ex.accumulate(n, 0.0, add, plus), first) << threads << " threads, n = " << n;
      EXPECT_EQ(ex.reduce(n, 0.0, term, plus), first) << threads << " threads, n = " << n;
      long double exact = 0.0L, magnitude = 0.0L;
      for (std::size_t i = 0; i < n; ++i) {
        exact += static_cast<long double>(term(i));
        magnitude += std::fabs(static_cast<long double>(term(i)));
      }
      EXPECT_LE(std::fabs(static_cast<long double>(first) - exact), 1e-13L * magnitude)
          << threads << " threads, n = " << n;
    }
  }
}

TEST(CpuExecutor, AccumulateOfNothingIsTheIdentity) {
  exec::CpuExecutor ex(2);
  EXPECT_EQ(ex.accumulate(
                0, 7.0, [](double& acc, std::size_t) { acc += 1.0; }, [](double a, double b) { return a + b; }),
            7.0);
}

TEST(CpuExecutor, WarmUpBringsUpTheThreadsTheMachineHas) {
  const int cores = tbb::info::default_concurrency();
  exec::CpuExecutor one(1);
  EXPECT_EQ(one.warm_up(), 1);
  exec::CpuExecutor two(2);
  // a generous timeout: starting a thread on a loaded machine may take a while
  EXPECT_EQ(two.warm_up(std::chrono::seconds(5)), std::min(2, cores));
  // the threads then run loops as before
  std::vector<int> hits(10000, 0);
  two.for_each(hits.size(), [&](std::size_t i) { ++hits[i]; });
  EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), static_cast<long>(hits.size()));
}

TEST(CpuExecutor, WarmUpAskingForMoreThreadsThanCoresEndsAtItsTimeout) {
  const int cores = tbb::info::default_concurrency();
  exec::CpuExecutor many(cores + 2);
  const auto t0 = std::chrono::steady_clock::now();
  const int arrived = many.warm_up(std::chrono::milliseconds(50));
  const double waited_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(arrived, 1);
  EXPECT_LE(arrived, cores);
  EXPECT_LT(waited_s, 5.0);  // bounded by its timeout, not by threads that cannot come
}
