#pragma once
// Effective memory bandwidth of the backend's hot kernels against the card's ceiling, for
// bench/gpu_pipeline: a device-to-device copy (the ceiling), the k-NN of the source points in the
// submap (the covariance kernel's search), and the GICP reduction (one linear system).
// Effective bandwidth = bytes the kernel asks for / time: for the searches, the points, counts
// and probed table slots of the 27-voxel neighbourhood within the search bound (repeated reads
// of a voxel by neighbouring queries count each time, so caches can lift it above the copy).
#include <cstddef>
#include <string>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/cuda/cuda_executor.hpp"
#include "farlio/cuda/staged_upload.hpp"
#include "farlio/map/map_view.hpp"

namespace farlio::cuda {

struct BandwidthSample {
  std::string kernel;
  double ms = 0.0;     ///< median time of one launch
  double bytes = 0.0;  ///< bytes asked for by one launch
  [[nodiscard]] double gb_per_s() const { return ms > 0.0 ? bytes / (ms * 1e6) : 0.0; }
};

/// The copy ceiling: `bytes` copied from one device buffer to another (allocates both).
BandwidthSample measure_copy(CudaExecutor& executor, std::size_t bytes, int repeats);

/// The upload of a scan: `bytes` copied from host memory (warm: the same bytes each time) to the
/// device through `staging`, as the backend copies each scan.
BandwidthSample measure_upload(CudaExecutor& executor, StagedUpload& staging, std::size_t bytes, int repeats);

/// k-NN of n device points in `target` (k neighbours within sqrt(max_distance2)).
BandwidthSample measure_knn(CudaExecutor& executor, const map::ConstMapView& target, const Eigen::Vector4f* points,
                            std::size_t n, int k, float max_distance2, int repeats);

/// One GICP linear system of n device source points against `target` at `pose` with
/// correspondences within sqrt(max_distance2).
BandwidthSample measure_gicp_reduction(CudaExecutor& executor, const map::ConstMapView& target,
                                       const Eigen::Vector4f* points, const map::Cov3* covs, std::size_t n,
                                       float max_distance2, const SE3& pose, int repeats);

}  // namespace farlio::cuda
