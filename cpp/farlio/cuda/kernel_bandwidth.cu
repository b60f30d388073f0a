#include <algorithm>
#include <vector>

#include "farlio/cuda/cuda_executor.cuh"
#include "farlio/cuda/kernel_bandwidth.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/registration/factor_sums.hpp"
#include "farlio/registration/gicp.hpp"

namespace farlio::cuda {
namespace {

/// Median time in ms of `repeats` runs of launch() on the executor's stream (CUDA events).
template <typename Launch>
double median_ms(CudaExecutor& ex, int repeats, const Launch& launch) {
  cudaEvent_t start = nullptr, stop = nullptr;
  FARLIO_CUDA_CHECK(cudaEventCreate(&start));
  FARLIO_CUDA_CHECK(cudaEventCreate(&stop));
  std::vector<float> ms(static_cast<std::size_t>(std::max(repeats, 1)));
  launch();  // warm-up
  for (float& m : ms) {
    FARLIO_CUDA_CHECK(cudaEventRecord(start, ex.stream()));
    launch();
    FARLIO_CUDA_CHECK(cudaEventRecord(stop, ex.stream()));
    FARLIO_CUDA_CHECK(cudaEventSynchronize(stop));
    FARLIO_CUDA_CHECK(cudaEventElapsedTime(&m, start, stop));
  }
  FARLIO_CUDA_CHECK(cudaEventDestroy(start));
  FARLIO_CUDA_CHECK(cudaEventDestroy(stop));
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

/// Bytes a search around p within bound2 asks for: probed slots (key + voxel), then each
/// visited voxel's count and points.
FARLIO_HD double neighbourhood_bytes(const map::ConstMapView& m, const Eigen::Vector3f& p, float bound2) {
  constexpr double kSlotBytes = sizeof(std::uint64_t) + sizeof(std::int32_t);
  constexpr double kPointBytes = sizeof(Eigen::Vector4f);
  double bytes = 0.0;
  map::for_each_nearby_voxel(
      m, p, [=] { return bound2; },
      [&](std::int32_t v) { bytes += kSlotBytes + sizeof(std::int32_t) + kPointBytes * m.voxel_counts[v]; });
  return bytes;
}

/// Bytes asked for by searches around R * points[i] + t within bound2, the queries included.
double search_bytes(CudaExecutor& ex, const map::ConstMapView& m, const Eigen::Vector4f* points, std::size_t n,
                    float bound2, const Eigen::Matrix3f& R, const Eigen::Vector3f& t) {
  return ex.reduce(
      n, 0.0,
      [=] __device__(std::size_t i) {
        const Eigen::Vector3f p = R * points[i].head<3>() + t;
        return sizeof(Eigen::Vector4f) + neighbourhood_bytes(m, p, bound2);
      },
      Add{});
}

// The launches, as named functions (an extended __device__ lambda cannot live in a lambda).
void copy_kernel(CudaExecutor& ex, const float4* src, float4* dst, std::size_t n) {
  ex.for_each(n, [=] __device__(std::size_t i) { dst[i] = src[i]; });
}

void knn_kernel(CudaExecutor& ex, const map::ConstMapView& m, const Eigen::Vector4f* points, std::size_t n, int k,
                float max_distance2, int* found, std::int64_t* indices, float* distances2) {
  const auto per = static_cast<std::size_t>(k);
  ex.for_each(n, [=] __device__(std::size_t i) {
    found[i] = map::knn_search(m, points[i].head<3>(), k, max_distance2, indices + i * per, distances2 + i * per);
  });
}

void reduction_kernel(CudaExecutor& ex, const map::ConstMapView& m, const Eigen::Vector4f* points,
                      const map::Cov3* covs, std::size_t n, const registration::FactorParams& fp) {
  ex.reduce(
      n, registration::FactorSums::zero(),
      [=] __device__(std::size_t i) { return registration::factor_sums(m, points[i], covs[i], fp); },
      registration::AddFactorSums{});
}

}  // namespace

BandwidthSample measure_copy(CudaExecutor& ex, std::size_t bytes, int repeats) {
  const std::size_t n = bytes / sizeof(float4);
  DeviceBuffer<float4> a(n, "copy elements"), b(n, "copy elements");
  FARLIO_CUDA_CHECK(cudaMemsetAsync(a.data(), 0, a.bytes(), ex.stream()));
  const float4* src = a.data();
  float4* dst = b.data();
  BandwidthSample s{"copy (ceiling)", 0.0, 2.0 * static_cast<double>(n * sizeof(float4))};
  s.ms = median_ms(ex, repeats, [&] { copy_kernel(ex, src, dst, n); });
  return s;
}

BandwidthSample measure_upload(CudaExecutor& ex, StagedUpload& staging, std::size_t bytes, int repeats) {
  const std::vector<unsigned char> host(bytes, 1);
  DeviceBuffer<unsigned char> device(bytes, "upload bytes");
  BandwidthSample s{"scan upload (host)", 0.0, static_cast<double>(bytes)};
  s.ms = median_ms(ex, repeats, [&] {
    staging.begin_frame();
    staging.upload(host.data(), device.data(), bytes, ex.stream());
  });
  return s;
}

BandwidthSample measure_knn(CudaExecutor& ex, const map::ConstMapView& m, const Eigen::Vector4f* points, std::size_t n,
                            int k, float max_distance2, int repeats) {
  DeviceBuffer<std::int64_t> idx(n * static_cast<std::size_t>(k), "k-NN results");
  DeviceBuffer<float> d2(n * static_cast<std::size_t>(k), "k-NN results");
  DeviceBuffer<int> found(n, "k-NN results");
  const auto per = static_cast<std::size_t>(k);
  BandwidthSample s{
      "k-NN (k=" + std::to_string(k) + ")", 0.0,
      search_bytes(ex, m, points, n, max_distance2, Eigen::Matrix3f::Identity(), Eigen::Vector3f::Zero())};
  s.bytes += static_cast<double>(n * (sizeof(int) + per * (sizeof(std::int64_t) + sizeof(float))));  // results
  s.ms = median_ms(ex, repeats,
                   [&] { knn_kernel(ex, m, points, n, k, max_distance2, found.data(), idx.data(), d2.data()); });
  return s;
}

BandwidthSample measure_gicp_reduction(CudaExecutor& ex, const map::ConstMapView& m, const Eigen::Vector4f* points,
                                       const map::Cov3* covs, std::size_t n, float max_distance2, const SE3& pose,
                                       int repeats) {
  registration::FactorParams fp =
      registration::factor_params(pose, registration::Thresholds::from_sigma(1.0), RegistrationConfig{});
  fp.max_correspondence_distance2 = max_distance2;
  BandwidthSample s{"GICP reduction", 0.0, search_bytes(ex, m, points, n, max_distance2, fp.R, fp.t)};
  s.bytes += static_cast<double>(n * sizeof(map::Cov3));
  s.ms = median_ms(ex, repeats, [&] { reduction_kernel(ex, m, points, covs, n, fp); });  // with the result's copy
  return s;
}

}  // namespace farlio::cuda
