// Google Benchmark of the scan pipeline's kernels and of whole frames, on generated urban scans
// (64-beam LiDAR, ~118k points). Run: build/dev/bench/bench_kernels [--benchmark_filter=...]
// The thread count is a benchmark argument (the pipeline's own arena, no global setting).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <utility>

#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/cpu_scan_backend.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "farlio/pipeline/stage_limits.hpp"
#include "farlio/preprocess/preprocess.hpp"
#include "farlio/registration/gicp.hpp"
#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;

namespace {

constexpr std::size_t kWarmupScans = 30;  // urban starts at rest: take scans while driving
constexpr std::size_t kFrameScans = 60;   // scans cycled through by the whole-frame benchmark

/// Generated urban scans, shared by all benchmarks (generated once).
const std::vector<Scan>& urban_scans() {
  static const std::vector<Scan> scans = [] {
    sim::SimConfig cfg = sim::default_config(sim::Profile::Urban);
    cfg.duration_s = 0.1 * static_cast<double>(kWarmupScans + kFrameScans + 1);
    const sim::SequenceGenerator gen(cfg);
    std::vector<Scan> out;
    for (std::size_t i = kWarmupScans; i < kWarmupScans + kFrameScans; ++i) out.push_back(gen.scan(i));
    return out;
  }();
  return scans;
}

/// A scan downsampled to the map spacing, in the sensor frame (what the map and GICP see).
std::vector<Eigen::Vector3f> downsampled(const Scan& scan, exec::CpuExecutor& ex) {
  Config cfg;
  const auto cropped = preprocess::crop_by_range(scan.points, cfg.preprocess);
  const auto kept =
      preprocess::voxel_downsample(scan.points, cropped, static_cast<float>(map::point_spacing_m(cfg.map)), ex);
  std::vector<Eigen::Vector3f> out;
  for (auto i : kept) out.push_back(scan.points[static_cast<std::size_t>(i)]);
  return out;
}

/// The preprocessing as the pipeline runs it (CpuScanBackend::preprocess): crop and cell key per
/// point, the first point of each cell, and (second argument 1) the undistortion of the kept
/// points with a constant twist of urban speed. The backend's buffers are reused from scan to scan.
void BM_Preprocess(benchmark::State& state) {
  Config cfg;
  cfg.num_threads = static_cast<int>(state.range(0));
  const bool undistort = state.range(1) != 0;
  pipeline::CpuScanBackend backend(cfg);
  const Scan& scan = urban_scans().front();
  deskew::Vec6f twist;
  twist << 10.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.3f;  // m/s and rad/s
  const auto motion = deskew::ScanMotion::constant_twist(twist, static_cast<float>(scan.duration_s()));
  for (auto _ : state) benchmark::DoNotOptimize(backend.preprocess(scan, motion, undistort));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(scan.size()));
}

void BM_MapInsert(benchmark::State& state) {
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const auto pts = downsampled(urban_scans().front(), ex);
  for (auto _ : state) {
    state.PauseTiming();
    map::VoxelMap m(VoxelMapConfig{}, ex);
    state.ResumeTiming();
    benchmark::DoNotOptimize(m.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(40)));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pts.size()));
}

/// A submap built from several scans (sensor moving), and a later scan's downsampled points.
struct MapFixture {
  exec::CpuExecutor ex;
  map::VoxelMap map{VoxelMapConfig{}, ex};
  std::vector<Eigen::Vector3f> queries;
  explicit MapFixture(int threads) : ex(threads) {
    for (int i = 0; i < 5; ++i)
      map.insert(downsampled(urban_scans()[static_cast<std::size_t>(i)], ex), Eigen::Vector3f::Zero(),
                 map::PointLimit::constant(40));
    queries = downsampled(urban_scans()[5], ex);
  }
};

/// Points a nearest-neighbour search compares (the same pruning as map::nearest_neighbor).
double nn_candidates(const map::ConstMapView& v, const Eigen::Vector3f& p, float max_distance2) {
  float best = max_distance2;
  double candidates = 0;
  map::for_each_nearby_voxel(
      v, p, [&] { return best; },
      [&](std::int32_t vox) {
        for (std::int32_t j = 0; j < v.voxel_counts[vox]; ++j) {
          ++candidates;
          best = std::min(best, (v.points[v.point_index(vox, j)].head<3>() - p).squaredNorm());
        }
      });
  return candidates;
}

void BM_NearestNeighbor(benchmark::State& state) {
  MapFixture f(static_cast<int>(state.range(0)));
  const map::MapView v = f.map.view();
  double candidates = 0;
  for (const auto& q : f.queries) candidates += nn_candidates(v, q, 9.0f);
  state.counters["candidates_per_query"] = candidates / static_cast<double>(f.queries.size());
  std::vector<std::int64_t> out(f.queries.size());
  for (auto _ : state) {
    f.ex.for_each(f.queries.size(), [&](std::size_t i) { out[i] = map::nearest_neighbor(v, f.queries[i], 9.0f); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.queries.size()));
}

/// Points and voxels the k-nearest-neighbour searches of a map's covariances compare and visit,
/// per query (the walk of update_voxel_covariances, counted).
std::pair<double, double> knn_work(const map::ConstMapView& v, std::size_t voxels, int k) {
  double candidates = 0, visited = 0, queries = 0;
  std::int64_t idx[map::kMaxNeighbors];
  float d2[map::kMaxNeighbors];
  for (std::size_t vox = 0; vox < voxels; ++vox) {
    if (v.voxel_keys[vox] == map::kEmptyKey) continue;
    const map::VoxelNeighborhood nb = map::voxel_neighborhood(v, map::unpack_key(v.voxel_keys[vox]));
    for (std::int32_t j = 0; j < v.voxel_counts[vox]; ++j) {
      const Eigen::Vector3f p = v.points[v.point_index(static_cast<std::int32_t>(vox), j)].head<3>();
      const auto counting_walk = [&](const auto& bound, const auto& visit) {
        map::for_each_nearby_voxel(v, nb, p, bound, [&](std::int32_t w) {
          ++visited;
          candidates += v.voxel_counts[w];
          visit(w);
        });
      };
      map::knn_over(v, counting_walk, p, k, map::kUnboundedDistance2, idx, d2);
      ++queries;
    }
  }
  return {candidates / queries, visited / queries};
}

void BM_CovarianceKnn(benchmark::State& state) {
  // frame-map insertion with k = 10 covariances of every new point
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const auto pts = downsampled(urban_scans().front(), ex);
  VoxelMapConfig cfg;
  cfg.point_spacing_m = map::point_spacing_m(cfg);
  cfg.max_points_per_voxel = 20;
  {
    map::VoxelMap m(cfg, ex);
    m.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(20));
    const auto [candidates, visited] = knn_work(m.view(), m.voxel_capacity(), cfg.covariance_neighbors);
    state.counters["points"] = static_cast<double>(m.num_points());
    state.counters["candidates_per_query"] = candidates;
    state.counters["voxels_per_query"] = visited;
  }
  for (auto _ : state) {
    state.PauseTiming();
    map::VoxelMap m(cfg, ex);
    state.ResumeTiming();
    benchmark::DoNotOptimize(m.insert(pts, Eigen::Vector3f::Zero(), map::PointLimit::constant(20)));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pts.size()));
}

void BM_GicpIteration(benchmark::State& state) {
  MapFixture f(static_cast<int>(state.range(0)));
  VoxelMapConfig fcfg;
  fcfg.point_spacing_m = map::point_spacing_m(fcfg);
  fcfg.max_points_per_voxel = 20;
  map::VoxelMap frame(fcfg, f.ex);
  frame.insert(f.queries, Eigen::Vector3f::Zero(), map::PointLimit::constant(20));
  const auto src = registration::source_from_map(frame.view(), frame.voxel_capacity());
  const auto th = registration::Thresholds::from_sigma(1.0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        registration::build_linear_system(src, f.map.view(), SE3(), th, RegistrationConfig(), f.ex));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(src.size()));
}

/// Whole frames (LiDAR-only scan pipeline, undistortion included) cycling through the scans.
void BM_WholeFrame(benchmark::State& state) {
  Config cfg;
  cfg.num_threads = static_cast<int>(state.range(0));
  auto pipe = std::make_unique<pipeline::ScanPipeline>(cfg);
  const auto& scans = urban_scans();
  std::size_t i = 0;
  for (auto _ : state) {
    if (i == scans.size()) {  // start over with a fresh map (outside the timing)
      state.PauseTiming();
      pipe = std::make_unique<pipeline::ScanPipeline>(cfg);
      i = 0;
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(pipe->process(scans[i++]));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(scans.front().size()));
}

// ---- the machine's limits, the yardsticks of docs/performance.md ----------------------------

constexpr std::size_t kChaseBytes = std::size_t{64} << 20;
constexpr std::size_t kL2TableBytes = std::size_t{512} << 10;  // a hash table that stays in L2

/// Memory read bandwidth: a sum over a 256 MiB array (bytes_per_second).
void BM_MemoryRead(benchmark::State& state) {
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const std::vector<float> data(pipeline::kYardstickStreamBytes / sizeof(float), 1.0f);
  for (auto _ : state) benchmark::DoNotOptimize(pipeline::memory_read_kernel(data, ex));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(pipeline::kYardstickStreamBytes));
}

/// A cache miss to memory: dependent loads along a random cycle over 64 MiB (time per load).
void BM_MemoryLatency(benchmark::State& state) {
  const std::size_t n = kChaseBytes / sizeof(std::uint32_t);
  std::vector<std::uint32_t> next(n);
  std::vector<std::uint32_t> perm(n);
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin() + 1, perm.end(), std::mt19937(1));
  for (std::size_t i = 0; i < n; ++i) next[perm[i]] = perm[(i + 1) % n];
  constexpr std::int64_t kLoads = 1 << 20;
  std::uint32_t at = 0;
  for (auto _ : state) {
    for (std::int64_t i = 0; i < kLoads; ++i) at = next[at];
    benchmark::DoNotOptimize(at);
  }
  state.SetItemsProcessed(state.iterations() * kLoads);
}

/// Independent random probes of a 512 KiB table (a hash table held in L2), per thread count.
void BM_L2Probes(benchmark::State& state) {
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const std::size_t n = kL2TableBytes / sizeof(std::uint64_t);
  std::vector<std::uint64_t> table(n, 1);
  constexpr std::size_t kProbes = 1 << 20;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ex.reduce(
        kProbes / 1024, std::uint64_t{0},
        [&](std::size_t b) {
          std::uint64_t acc = 0, h = b;
          for (std::size_t i = 0; i < 1024; ++i) {
            h = h * 0x9E3779B97F4A7C15ULL + 1;
            acc += table[(h >> 40) & (n - 1)];
          }
          return acc;
        },
        [](std::uint64_t a, std::uint64_t b) { return a + b; }));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kProbes));
}

/// The cost of one parallel region on 2 threads: a loop of two tasks of about 20 us each,
/// after a serial gap of range(0) microseconds of busy work (the serial parts of a frame between
/// its parallel loops, during which the other thread may fall asleep). Real time per iteration,
/// gap included: compare with the gap plus 20 us.
void BM_ParallelRegion(benchmark::State& state) {
  exec::CpuExecutor ex(2);
  const auto gap = std::chrono::microseconds(state.range(0));
  constexpr auto kTask = std::chrono::microseconds(20);
  const auto spin = [](std::chrono::microseconds d) {
    const auto until = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < until) {
    }
  };
  for (auto _ : state) {
    spin(gap);
    ex.for_each(
        2, [&](std::size_t) { spin(kTask); }, 1);
  }
}

/// Point-to-query squared distances over points held in L1 (the searches' inner loop,
/// block_distances2), per thread count: the rate that bounds the neighbour searches.
void BM_L1Distances(benchmark::State& state) {
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  std::vector<Eigen::Vector4f> points(pipeline::kYardstickL1Points);
  for (auto& p : points) p = Eigen::Vector4f::Random();
  for (auto _ : state) {
    benchmark::DoNotOptimize(pipeline::l1_distances_kernel(points, pipeline::kYardstickQueries, ex));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pipeline::kYardstickQueries) *
                          pipeline::kYardstickL1Points);
}

}  // namespace

BENCHMARK(BM_L1Distances)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemoryRead)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MemoryLatency)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_L2Probes)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ParallelRegion)
    ->Arg(0)
    ->Arg(100)
    ->Arg(200)
    ->Arg(300)
    ->Arg(500)
    ->Arg(2000)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK(BM_Preprocess)->ArgsProduct({{1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MapInsert)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NearestNeighbor)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CovarianceKnn)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GicpIteration)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(120);

BENCHMARK_MAIN();
