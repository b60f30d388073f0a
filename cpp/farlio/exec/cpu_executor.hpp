#pragma once
// The CPU executor: runs a kernel body for every index, in parallel on this executor's own TBB
// arena. The thread count belongs to the instance (no process-wide setting), so two pipelines
// in one process do not interfere.
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>

namespace farlio::exec {

class CpuExecutor {
 public:
  /// num_threads <= 0: all hardware threads.
  explicit CpuExecutor(int num_threads = 0) : arena_(num_threads > 0 ? num_threads : tbb::task_arena::automatic) {}

  [[nodiscard]] int num_threads() const { return arena_.max_concurrency(); }

  /// Calls body(i) for every i in [0, n), in tasks of at least `grain` indices (smaller for
  /// bodies of uneven cost, such as one voxel's points).
  template <typename Body>
  void for_each(std::size_t n, const Body& body, std::size_t grain = kGrain) {
    if (n == 0) return;
    arena_.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) body(i);
      });
    });
  }

  /// Sum over i in [0, n) of map(i), combined with `combine` (associative), starting from
  /// `identity`. Deterministic for a given thread count and n (static partitioning).
  template <typename T, typename Map, typename Combine>
  T reduce(std::size_t n, const T& identity, const Map& map, const Combine& combine) {
    return accumulate(
        n, identity, [&](T& acc, std::size_t i) { acc = combine(acc, map(i)); }, combine);
  }

  /// reduce with each index's term added to its task's running sum in place: add(acc, i) does
  /// acc = acc + term(i). The same sums in the same order as reduce(n, identity, term, combine)
  /// with combine(a, b) = a + b, without a term object per index. The tasks' sums are combined
  /// with `combine`.
  template <typename T, typename Add, typename Combine>
  T accumulate(std::size_t n, const T& identity, const Add& add, const Combine& combine) {
    if (n == 0) return identity;
    T result = identity;
    arena_.execute([&] {
      result = tbb::parallel_deterministic_reduce(
          tbb::blocked_range<std::size_t>(0, n, kGrain), identity,
          [&](const tbb::blocked_range<std::size_t>& r, T acc) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) add(acc, i);
            return acc;
          },
          combine);
    });
    return result;
  }

  /// Brings up the threads of the arena before the first parallel loop: TBB starts a worker
  /// when the first loop asks for it, and that loop (a pipeline's first frame) waits for it.
  /// One task per thread waits until every thread has taken one, or until `timeout` (fewer
  /// threads than asked may be available: more than the machine's cores, other arenas).
  /// Returns how many threads took part.
  int warm_up(std::chrono::microseconds timeout = kWarmUpTimeout) {
    const int threads = std::min(num_threads(), tbb::info::default_concurrency());
    if (threads <= 1) return 1;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::atomic<int> arrived{0};
    arena_.execute([&] {
      tbb::parallel_for(
          0, threads, 1,
          [&](int) {
            arrived.fetch_add(1, std::memory_order_relaxed);
            while (arrived.load(std::memory_order_relaxed) < threads && std::chrono::steady_clock::now() < deadline) {
            }
          },
          tbb::simple_partitioner());
    });
    return std::min(arrived.load(), threads);
  }

  /// Runs f() inside this executor's arena (for code that uses TBB algorithms directly).
  template <typename F>
  auto run(F&& f) {
    return arena_.execute(std::forward<F>(f));
  }

 private:
  static constexpr std::size_t kGrain = 256;  // indices per task: small enough to balance
  /// How long warm_up waits for the threads (starting one takes well under a millisecond).
  static constexpr std::chrono::microseconds kWarmUpTimeout{10000};
  tbb::task_arena arena_;
};

}  // namespace farlio::exec
