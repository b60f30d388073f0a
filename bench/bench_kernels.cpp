// Google Benchmark of the scan pipeline's kernels and of whole frames, on generated urban scans
// (64-beam LiDAR, ~118k points). Run: build/dev/bench/bench_kernels [--benchmark_filter=...]
// The thread count is a benchmark argument (the pipeline's own arena, no global setting).
#include <benchmark/benchmark.h>

#include <limits>
#include <memory>
#include <numeric>

#include "farlio/map/neighbor_search.hpp"
#include "farlio/map/voxel_map.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/cell_downsampler.hpp"
#include "farlio/pipeline/preprocess.hpp"
#include "farlio/pipeline/range_crop.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
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
  const auto cropped = pipeline::crop_by_range(scan.points, cfg.preprocess);
  const auto kept =
      pipeline::voxel_downsample(scan.points, cropped, static_cast<float>(map::point_spacing_m(cfg.map)), ex);
  std::vector<Eigen::Vector3f> out;
  for (auto i : kept) out.push_back(scan.points[static_cast<std::size_t>(i)]);
  return out;
}

/// The preprocessing as the pipeline runs it: crop and cell key per point, then the first point
/// of each cell (the downsampler's table reused from scan to scan).
void BM_Downsample(benchmark::State& state) {
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const Scan& scan = urban_scans().front();
  const pipeline::RangeCrop crop = pipeline::RangeCrop::from(PreprocessConfig{});
  const float inv_cell = 1.0f / static_cast<float>(map::point_spacing_m(VoxelMapConfig{}));
  std::vector<std::uint64_t> keys(scan.size());
  pipeline::CellDownsampler downsampler;
  for (auto _ : state) {
    ex.for_each(scan.size(), [&](std::size_t i) {
      keys[i] = crop.keeps(scan.points[i]) ? map::point_key(scan.points[i], inv_cell) : map::kEmptyKey;
    });
    benchmark::DoNotOptimize(downsampler.first_of_each_cell(keys.data(), keys.size(), ex).data());
  }
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

void BM_NearestNeighbor(benchmark::State& state) {
  MapFixture f(static_cast<int>(state.range(0)));
  const map::MapView v = f.map.view();
  std::vector<std::int64_t> out(f.queries.size());
  for (auto _ : state) {
    f.ex.for_each(f.queries.size(), [&](std::size_t i) { out[i] = map::nearest_neighbor(v, f.queries[i], 9.0f); });
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.queries.size()));
}

void BM_CovarianceKnn(benchmark::State& state) {
  // frame-map insertion with k = 10 covariances of every new point
  exec::CpuExecutor ex(static_cast<int>(state.range(0)));
  const auto pts = downsampled(urban_scans().front(), ex);
  VoxelMapConfig cfg;
  cfg.point_spacing_m = map::point_spacing_m(cfg);
  cfg.max_points_per_voxel = 20;
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

}  // namespace

BENCHMARK(BM_Downsample)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MapInsert)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NearestNeighbor)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CovarianceKnn)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GicpIteration)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(120);

BENCHMARK_MAIN();
