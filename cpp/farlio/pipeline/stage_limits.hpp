#pragma once
// How far each stage of a frame is from its limit (docs/performance.md): the machine's
// yardsticks, measured by two small kernels, and the time the work of a frame's stages implies at
// those rates. The limit counts only the work no implementation of the stage can avoid:
//   preprocess    read every raw point and its time (16 B), write the kept ones (12 B);
//   covariance    k distances and one covariance per source point (the k neighbours must at
//                 least be looked at), and the frame's kept points read once;
//   registration  per Gauss-Newton iteration one GICP factor per source point, and one distance
//                 per source point (its first search);
//   map update    one distance per candidate (the spacing test), k distances and one covariance
//                 per covariance computed.
// Flops run at 8 flops per yardstick distance (3 subtractions, 3 multiplications, 2 additions).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "farlio/exec/cpu_executor.hpp"
#include "farlio/pipeline/frame_timings.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"

namespace farlio::pipeline {

/// The machine's rates on `threads` threads.
struct Yardsticks {
  int threads = 1;
  double memory_read_bytes_per_s = 0.0;  ///< streaming read far beyond the caches
  double l1_distances_per_s = 0.0;       ///< map::block_distances2 over points held in L1
};

/// Bytes the memory yardstick streams (far beyond the caches).
inline constexpr std::size_t kYardstickStreamBytes = std::size_t{256} << 20;
/// Points the distance yardstick searches per query: 16 voxels' worth of a frame map, 5 KiB.
inline constexpr std::int32_t kYardstickL1Points = 320;
/// Queries of one distance yardstick call.
inline constexpr std::size_t kYardstickQueries = std::size_t{1} << 14;

/// The memory yardstick's kernel: the sum of `data`, in blocks over the executor's threads.
float memory_read_kernel(const std::vector<float>& data, exec::CpuExecutor& executor);
/// The distance yardstick's kernel: for `queries` query points, the smallest squared distance
/// to `points` (map::block_distances2); returns the smallest of all.
float l1_distances_kernel(const std::vector<Eigen::Vector4f>& points, std::size_t queries, exec::CpuExecutor& executor);

/// Both yardsticks on the executor's threads, the best of `rounds` calls each (about 0.1 s a
/// round on the 2-core CI machine).
Yardsticks measure_yardsticks(exec::CpuExecutor& executor, int rounds = 3);

/// Flops of one covariance from its k neighbours: accumulation, the Frobenius regularisation (a
/// 3x3 inverse and its norm) and the shape test (closed-form eigenvalues), counted in
/// map/covariance.hpp.
inline constexpr double kCovarianceFlops = 220.0;
/// Flops of one GICP factor (registration/gicp_factor.hpp): R C R^T, the 3x3 inverse of the
/// combined covariance, J^T Omega J and J^T Omega r, and the robust weight.
inline constexpr double kGicpFactorFlops = 700.0;
/// Flops one yardstick distance stands for.
inline constexpr double kFlopsPerDistance = 8.0;
/// Bytes every raw point costs the preprocessing: xyz and time read, xyz written.
inline constexpr double kPreprocessBytesPerPoint = 28.0;
/// Bytes of a kept point (xyz).
inline constexpr double kPointBytes = 12.0;

/// The limits of one frame's stages: the time, in seconds, each stage's unavoidable work takes at
/// the yardsticks' rates, in the shape of the frame's own timings (total_s: their sum); `k` is
/// map.covariance_neighbors.
FrameTimings stage_limits(const FrameResult& frame, int k, const Yardsticks& y);

}  // namespace farlio::pipeline
