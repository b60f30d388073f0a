#include "farlio/pipeline/stage_limits.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <numeric>

#include "farlio/map/map_view.hpp"
#include "farlio/map/neighbor_search.hpp"

namespace farlio::pipeline {
namespace {
/// Elements a task of the memory kernel sums.
constexpr std::size_t kReadBlock = 1024;
/// Partial sums of the memory kernel (kReadBlock is a multiple).
constexpr std::size_t kReadLanes = 16;
/// Query points of the distance kernel are spread over this step (any finite values do).
constexpr float kQueryStep = 1e-4f;

template <typename F>
double best_seconds(int rounds, const F& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < std::max(1, rounds); ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

double per_second(double work, double rate) { return rate > 0.0 ? work / rate : 0.0; }
}  // namespace

float memory_read_kernel(const std::vector<float>& data, exec::CpuExecutor& executor) {
  return executor.reduce(
      data.size() / kReadBlock, 0.0f,
      [&](std::size_t b) {
        // independent partial sums: one chain of float additions would measure the adder's latency
        // (about 4 B a cycle), not the memory
        std::array<float, kReadLanes> acc{};
        for (std::size_t i = b * kReadBlock; i < (b + 1) * kReadBlock; i += kReadLanes) {
          for (std::size_t l = 0; l < kReadLanes; ++l) acc[l] += data[i + l];
        }
        return std::accumulate(acc.begin(), acc.end(), 0.0f);
      },
      [](float a, float b) { return a + b; });
}

float l1_distances_kernel(const std::vector<Eigen::Vector4f>& points, std::size_t queries,
                          exec::CpuExecutor& executor) {
  map::ConstMapView v;
  v.points = points.data();
  const auto n = static_cast<std::int32_t>(points.size());
  return executor.reduce(
      queries, std::numeric_limits<float>::max(),
      [&](std::size_t q) {
        const Eigen::Vector3f p = Eigen::Vector3f::Constant(static_cast<float>(q) * kQueryStep);
        float best = std::numeric_limits<float>::max(), d2[map::kDistanceBlock];
        for (std::int32_t j0 = 0; j0 < n; j0 += map::kDistanceBlock) {
          const std::int32_t len = map::block_distances2(v, j0, n - j0, p, d2);
          for (std::int32_t j = 0; j < len; ++j) best = std::min(best, d2[j]);
        }
        return best;
      },
      [](float a, float b) { return std::min(a, b); });
}

Yardsticks measure_yardsticks(exec::CpuExecutor& executor, int rounds) {
  Yardsticks y;
  y.threads = executor.num_threads();
  {
    const std::vector<float> data(kYardstickStreamBytes / sizeof(float), 1.0f);
    volatile float sink = 0.0f;
    const double s = best_seconds(rounds, [&] { sink = memory_read_kernel(data, executor); });
    y.memory_read_bytes_per_s = static_cast<double>(kYardstickStreamBytes) / s;
  }
  {
    std::vector<Eigen::Vector4f> points(kYardstickL1Points);
    for (auto& p : points) p = Eigen::Vector4f::Random();
    volatile float sink = 0.0f;
    const double s = best_seconds(rounds, [&] { sink = l1_distances_kernel(points, kYardstickQueries, executor); });
    y.l1_distances_per_s = static_cast<double>(kYardstickQueries) * kYardstickL1Points / s;
  }
  return y;
}

FrameTimings stage_limits(const FrameResult& frame, int k, const Yardsticks& y) {
  const double bw = y.memory_read_bytes_per_s, dist = y.l1_distances_per_s, flops = kFlopsPerDistance * dist;
  const auto n = [](std::size_t v) { return static_cast<double>(v); };
  const double source = n(frame.source_points), kd = static_cast<double>(k);
  FrameTimings l;
  l.preprocess_s = per_second(kPreprocessBytesPerPoint * n(frame.input_points), bw);
  l.covariance_s = per_second(kPointBytes * n(frame.kept_points), bw) + per_second(source * kd, dist) +
                   per_second(source * kCovarianceFlops, flops);
  const double iterations = frame.registered ? static_cast<double>(frame.registration.iterations) : 0.0;
  l.registration_s =
      iterations > 0.0 ? per_second(source, dist) + per_second(iterations * source * kGicpFactorFlops, flops) : 0.0;
  const double covs = n(frame.map_insert.covariances_computed);
  l.map_update_s =
      per_second(n(frame.map_insert.candidates) + covs * kd, dist) + per_second(covs * kCovarianceFlops, flops);
  l.total_s = l.preprocess_s + l.covariance_s + l.registration_s + l.map_update_s;
  return l;
}

}  // namespace farlio::pipeline
