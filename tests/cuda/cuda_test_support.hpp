#pragma once
// What the GPU tests share: the skip without a device, and a device map beside a host map.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <vector>

#include "farlio/cuda/cuda_executor.hpp"
#include "farlio/cuda/device_algorithms.hpp"
#include "farlio/cuda/device_buffer.hpp"
#include "farlio/cuda/device_voxel_map.hpp"
#include "farlio/cuda/map_scratch.hpp"
#include "farlio/pipeline/backend_availability.hpp"

#define FARLIO_REQUIRE_GPU()                                                  \
  do {                                                                        \
    if (::farlio::cuda_device_count() == 0) GTEST_SKIP() << "no CUDA device"; \
  } while (0)

namespace farlio::test {

/// A device voxel map with its executor and work arrays, and a buffer for inputs.
struct DeviceMapRig {
  static constexpr std::size_t kMaxPoints = 1 << 18;
  cuda::CudaExecutor executor;
  cuda::DeviceAlgorithms algorithms;
  cuda::MapScratch scratch;
  cuda::DeviceVoxelMap map;
  cuda::DeviceBuffer<Eigen::Vector3f> input;

  DeviceMapRig(const VoxelMapConfig& config, std::size_t voxel_capacity)
      : algorithms(std::max(kMaxPoints, voxel_capacity) + 1, executor.stream()),
        scratch(std::max(kMaxPoints, voxel_capacity) + 1, executor),
        map(config, voxel_capacity, "test voxel capacity", executor, algorithms, scratch),
        input(kMaxPoints, "test points") {}

  /// `within_m`: how far from origin the points are said to lie (DeviceVoxelMap::insert).
  map::InsertStats insert(const std::vector<Eigen::Vector3f>& pts, const Eigen::Vector3f& origin,
                          const map::PointLimit& limit, double within_m = std::numeric_limits<double>::infinity()) {
    input.upload(pts.data(), pts.size(), executor.stream(), "DeviceMapRig::kMaxPoints");
    return map.insert(input.data(), pts.size(), origin, limit, within_m);
  }
};

}  // namespace farlio::test
