// The warp-wide nearest-neighbour search (the GICP systems' search on the GPU) against the
// one-thread search map::nearest_neighbor on the host map that holds the same points: the same
// point for every query, ties between voxels included, at every search bound.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "cuda_test_support.hpp"
#include "farlio/cuda/cuda_check.hpp"
#include "farlio/cuda/warp_search.cuh"
#include "farlio/exec/cpu_executor.hpp"
#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "scene_fixture.hpp"

using namespace farlio;
namespace gpu = farlio::cuda;

namespace {

constexpr unsigned kBlockThreads = 128;

__global__ void warp_nearest_kernel(map::ConstMapView m, const Eigen::Vector3f* queries, std::size_t n,
                                    float max_distance2, std::int64_t* out) {
  const std::size_t q = (static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x) / gpu::kWarpLanes;
  if (q >= n) return;  // the whole warp: one query
  const unsigned lane = threadIdx.x % gpu::kWarpLanes;
  const std::int64_t nn = gpu::warp_nearest_neighbor(m, queries[q], max_distance2, lane);
  if (lane == 0) out[q] = nn;
}

/// The warp search of each query on the device map.
std::vector<std::int64_t> warp_nearest(test::DeviceMapRig& rig, const std::vector<Eigen::Vector3f>& queries,
                                       float max_distance2) {
  const std::size_t n = queries.size();
  gpu::DeviceBuffer<Eigen::Vector3f> q(n, "queries");
  gpu::DeviceBuffer<std::int64_t> out(n, "queries");
  const cudaStream_t stream = rig.executor.stream();
  q.upload(queries.data(), n, stream, "queries");
  const auto blocks = static_cast<unsigned>((n * gpu::kWarpLanes + kBlockThreads - 1) / kBlockThreads);
  warp_nearest_kernel<<<blocks, kBlockThreads, 0, stream>>>(rig.map.view(), q.data(), n, max_distance2, out.data());
  FARLIO_CUDA_CHECK(cudaGetLastError());
  std::vector<std::int64_t> r(n);
  out.download(r.data(), n, stream);
  return r;
}

/// For every bound: the warp's point is the host search's; some queries find one and, with
/// `some_missing`, some do not.
void expect_host_results(const map::VoxelMap& cpu, test::DeviceMapRig& gpu, const std::vector<Eigen::Vector3f>& queries,
                         const std::vector<float>& bounds2, bool some_missing) {
  for (const float max_d2 : bounds2) {
    const std::vector<std::int64_t> warp = warp_nearest(gpu, queries, max_d2);
    std::size_t found = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
      const std::int64_t host = map::nearest_neighbor(cpu.view(), queries[q], max_d2);
      ASSERT_EQ(warp[q], host) << "query " << q << " bound2 " << max_d2;
      found += host >= 0 ? 1 : 0;
    }
    EXPECT_GT(found, 0u) << "bound2 " << max_d2;
    if (some_missing) EXPECT_LT(found, queries.size()) << "bound2 " << max_d2;
  }
}

}  // namespace

TEST(CudaWarpSearch, TheWarpFindsTheHostSearchsPointInAScene) {
  FARLIO_REQUIRE_GPU();
  const VoxelMapConfig cfg;
  exec::CpuExecutor ex(2);
  map::VoxelMap cpu(cfg, ex);
  test::DeviceMapRig gpu(cfg, 1 << 16);
  const auto pts = test::sample_scene(120000, 31, 0.02f);
  cpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  gpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  // near the surfaces and far from them (queries 1 m off find nothing within the tight bounds)
  std::vector<Eigen::Vector3f> queries = test::sample_scene(6000, 32, 0.3f);
  for (const auto& q : test::sample_scene(2000, 33, 1.5f)) queries.push_back(q);
  expect_host_results(cpu, gpu, queries, {0.01f, 0.25f, 1.0f, 4.0f}, true);
  expect_host_results(cpu, gpu, queries, {map::kUnboundedDistance2}, false);
}

TEST(CudaWarpSearch, TiesBetweenVoxelsGoToTheVoxelTheHostSearchVisitsFirst) {
  FARLIO_REQUIRE_GPU();
  VoxelMapConfig cfg;
  cfg.voxel_size_m = 1.0;
  exec::CpuExecutor ex(2);
  map::VoxelMap cpu(cfg, ex);
  test::DeviceMapRig gpu(cfg, 1 << 12);
  // one point at the centre of each voxel of an 8 m cube: a query on a face, an edge or a corner
  // of a voxel is exactly as far from 2, 4 or 8 of them (halves and quarters are exact floats)
  std::vector<Eigen::Vector3f> pts;
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z) pts.emplace_back(x + 0.5f, y + 0.5f, z + 0.5f);
  cpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  gpu.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40));
  ASSERT_EQ(cpu.num_voxels(), pts.size());
  std::vector<Eigen::Vector3f> queries;
  for (int x = 1; x < 7; ++x)
    for (int y = 1; y < 7; ++y)
      for (int z = 1; z < 7; ++z) {
        const Eigen::Vector3f c(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        queries.push_back(c);                                      // a corner: 8 at the same distance
        queries.push_back(c + Eigen::Vector3f(0.5f, 0.0f, 0.0f));  // an edge: 4
        queries.push_back(c + Eigen::Vector3f(0.5f, 0.5f, 0.0f));  // a face: 2
        queries.push_back(c + Eigen::Vector3f(0.25f, 0.5f, 0.75f));
      }
  expect_host_results(cpu, gpu, queries, {0.8f, 2.0f, map::kUnboundedDistance2}, false);
}
