// Times the whole scan pipeline (undistortion, downsampling, source covariances, GICP, map
// update) per frame on generated sequences and on folders of recorded scans, on the GPU and the
// CPU over the same scans, and prints a short table: median / p99 / max per frame, each stage's
// median and p99 (CUDA events on the GPU), device memory, and the pose agreement of the two
// backends; then the scan's upload time and the effective bandwidth of the k-NN and the GICP
// reduction against a device-to-device copy. Run by scripts/gpu_check.sh.
// On the GPU each sequence runs twice: with each scan uploaded in its own frame (a live scan's
// latency), and with the next scan staged before each frame (ScanPipeline::stage_next: offline,
// scans back to back, its upload overlaps the frame's kernels); the row "NAME+next" is the second,
// its dt_max / dr_max the largest pose difference to the first (0: the same results), followed by
// how many of its scans the backend found staged (all but the first, or the staging did nothing).
// Usage: gpu_pipeline [--frames N] [--profile urban|racetrack|handheld|tunnel]... [--scans DIR]...
//                     [--device cuda|cpu|auto] [--no-cpu-compare] [--no-staged] [--repeats R]
// --no-staged: without the run with the next scan staged.
// --repeats R: launches timed per bandwidth sample (0: no bandwidth samples).
// --scans DIR: every point cloud file of DIR (PCD, PLY, KITTI .bin, optionally .gz), in name
// order, as scans 0.1 s apart without per-point times (KITTI's scans are already undistorted).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "farlio/io/point_cloud_io.hpp"
#include "farlio/pipeline/backend_availability.hpp"
#include "farlio/pipeline/scan_pipeline.hpp"
#include "farlio/sim/sequence_generator.hpp"
#ifdef FARLIO_WITH_CUDA
#include <cuda_runtime_api.h>

#include "farlio/cuda/cuda_scan_backend.hpp"
#endif

using namespace farlio;

namespace {

constexpr std::size_t kDefaultFrames = 100;
constexpr double kFirstScan_s = 2.5;  // generated sequences start at rest for 2 s
constexpr int kDefaultRepeats = 20;
constexpr double kMsPerS = 1e3;
constexpr double kMiB = 1024.0 * 1024.0;
constexpr double kMedian = 0.5, kP99 = 0.99;
constexpr std::int64_t kRecordedScanPeriod_ns = 100'000'000;  // 10 Hz
constexpr int kStages = 4;
constexpr const char* kStageNames[kStages] = {"prep", "source", "gicp", "update"};

struct Options {
  std::size_t frames = kDefaultFrames;
  std::vector<std::string> profiles;
  std::vector<std::string> scan_dirs;
  Device device = Device::Cuda;
  bool compare_cpu = true;
  bool staged = true;
  int repeats = kDefaultRepeats;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return std::string(argv[++i]);
    };
    if (a == "--frames")
      o.frames = std::stoul(value());
    else if (a == "--profile")
      o.profiles.push_back(value());
    else if (a == "--scans")
      o.scan_dirs.push_back(value());
    else if (a == "--device")
      o.device = parse_device(value(), "--device");
    else if (a == "--no-cpu-compare")
      o.compare_cpu = false;
    else if (a == "--no-staged")
      o.staged = false;
    else if (a == "--repeats")
      o.repeats = std::stoi(value());
    else
      throw std::invalid_argument("unknown option " + a + " (see the comment at the top of bench/gpu_pipeline.cpp)");
  }
  if (o.profiles.empty() && o.scan_dirs.empty()) o.profiles = {"urban", "racetrack"};
  return o;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::llround(q * static_cast<double>(v.size() - 1)))];
}

std::vector<Scan> generate(const std::string& profile, std::size_t frames) {
  sim::SimConfig cfg = sim::default_config(sim::parse_profile(profile));
  const auto first = static_cast<std::size_t>(std::llround(kFirstScan_s * cfg.lidar_rate_hz));
  cfg.duration_s = static_cast<double>(first + frames + 1) / cfg.lidar_rate_hz;
  const sim::SequenceGenerator gen(cfg);
  std::vector<Scan> scans;
  for (std::size_t i = first; i < first + frames; ++i) scans.push_back(gen.scan(i));
  return scans;
}

/// The first `frames` point cloud files of dir in name order, 0.1 s apart.
std::vector<Scan> read_scans(const std::string& dir, std::size_t frames) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file() && io::is_point_cloud_file(e.path())) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw std::invalid_argument("--scans " + dir + ": no point cloud file in it");
  if (files.size() > frames) files.resize(frames);
  std::vector<Scan> scans;
  for (std::size_t i = 0; i < files.size(); ++i) {
    Scan s = io::read_point_cloud(files[i]);
    s.remove_non_finite();
    s.start_stamp_ns = static_cast<std::int64_t>(i) * kRecordedScanPeriod_ns;
    s.end_stamp_ns = s.start_stamp_ns + kRecordedScanPeriod_ns;
    scans.push_back(std::move(s));
  }
  return scans;
}

/// Device memory in use (bytes), or 0 without CUDA.
double device_used_bytes() {
#ifdef FARLIO_WITH_CUDA
  std::size_t free_b = 0, total_b = 0;
  if (cudaMemGetInfo(&free_b, &total_b) == cudaSuccess) return static_cast<double>(total_b - free_b);
#endif
  return 0.0;
}

struct Run {
  std::vector<double> total_ms, stage_ms[kStages];
  std::vector<double> between_ms;  // the frame's time outside its four stages
  std::vector<SE3> poses;
  double prealloc_bytes = 0.0, used_bytes = 0.0;
  std::size_t max_voxels = 0;
  bool device_timed = false;
  std::size_t found_staged = 0;  // frames whose scan the backend found staged
};

/// `stage_next`: the next scan is handed to the pipeline before each frame (in the frame's time).
Run run(pipeline::ScanPipeline& p, const std::vector<Scan>& scans, double used_before, bool stage_next = false) {
  Run r;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const Scan& s = scans[i];
    const auto t0 = std::chrono::steady_clock::now();
    if (stage_next && i + 1 < scans.size()) p.stage_next(scans[i + 1]);
    const auto f = p.process(s);
    r.found_staged += p.backend().last_scan_was_staged() ? 1 : 0;
    r.total_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    const double st[kStages] = {f.timings.preprocess_s, f.timings.covariance_s, f.timings.registration_s,
                                f.timings.map_update_s};
    double between = r.total_ms.back();
    for (int k = 0; k < kStages; ++k) {
      r.stage_ms[k].push_back(st[k] * kMsPerS);
      between -= st[k] * kMsPerS;
    }
    r.between_ms.push_back(between);
    r.poses.push_back(f.pose);
    r.max_voxels = std::max(r.max_voxels, f.map_voxels);
    r.device_timed = f.timings.device_timed;
  }
  r.prealloc_bytes = static_cast<double>(p.backend().memory_bytes());
  r.used_bytes = device_used_bytes() - used_before;
  return r;
}

void print_row(const std::string& name, double points, Device device, const Run& r, double dt, double dr) {
  std::printf("%-12s %7.0f %6s %6zu %9.2f %8.2f %8.2f | %9.1f %9.1f | %9.2e %10.2e | %7zu\n", name.c_str(), points,
              device_name(device), r.total_ms.size(), quantile(r.total_ms, kMedian), quantile(r.total_ms, kP99),
              quantile(r.total_ms, 1.0), r.prealloc_bytes / kMiB, r.used_bytes / kMiB, dt, dr, r.max_voxels);
  std::printf("    stages (%s), median / p99 ms:", r.device_timed ? "CUDA events" : "wall clock");
  for (int k = 0; k < kStages; ++k)
    std::printf("  %s %.3f / %.3f", kStageNames[k], quantile(r.stage_ms[k], kMedian), quantile(r.stage_ms[k], kP99));
  std::printf("  between %.3f / %.3f\n", quantile(r.between_ms, kMedian), quantile(r.between_ms, kP99));
}

void print_bandwidth(pipeline::ScanPipeline& p, int repeats, double frame_median_ms) {
#ifdef FARLIO_WITH_CUDA
  if (p.backend().device() != Device::Cuda || repeats <= 0) return;
  const auto samples = cuda::measure_kernel_bandwidth(p.backend(), repeats);
  const double ceiling = samples.front().gb_per_s();
  std::printf("    %-22s %10s %12s %10s %10s\n", "kernel", "ms", "MB asked", "GB/s", "of copy");
  for (const auto& s : samples) {
    std::printf("    %-22s %10.3f %12.1f %10.1f %9.0f%%\n", s.kernel.c_str(), s.ms, s.bytes / 1e6, s.gb_per_s(),
                100.0 * s.gb_per_s() / ceiling);
    if (s.kernel.rfind("scan upload", 0) == 0)
      std::printf("    (the last scan's upload is %.1f %% of the median frame)\n", 100.0 * s.ms / frame_median_ms);
  }
#else
  (void)p;
  (void)repeats;
  (void)frame_median_ms;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    resolve_device(o.device);  // cuda without a GPU: the error before anything else
    std::printf("%-12s %7s %6s %6s %9s %8s %8s | %9s %9s | %9s %10s | %7s\n", "sequence", "points", "device", "frames",
                "median ms", "p99 ms", "max ms", "prealloc", "used MiB", "dt_max m", "dr_max deg", "voxels");
    std::vector<std::pair<std::string, std::vector<Scan>>> sequences;
    for (const auto& profile : o.profiles) sequences.emplace_back(profile, generate(profile, o.frames));
    for (const auto& dir : o.scan_dirs)
      sequences.emplace_back(std::filesystem::path(dir).filename().string(), read_scans(dir, o.frames));
    for (const auto& [name, scans] : sequences) {
      double points = 0;
      for (const auto& s : scans) points += static_cast<double>(s.size()) / static_cast<double>(scans.size());
      Config cfg;
      cfg.device = o.device;
      const double used_before = device_used_bytes();  // also creates the CUDA context
      pipeline::ScanPipeline p(cfg);
      if (!p.device_message().empty()) std::fprintf(stderr, "%s\n", p.device_message().c_str());
      const Run r = run(p, scans, used_before);
      if (o.compare_cpu && p.backend().device() != Device::Cpu) {
        Config c = cfg;
        c.device = Device::Cpu;
        pipeline::ScanPipeline cpu(c);
        Run rc = run(cpu, scans, 0.0);
        rc.used_bytes = NAN;  // the CPU backend uses no device memory
        double dt = 0.0, dr = 0.0;
        for (std::size_t i = 0; i < scans.size(); ++i) {
          const SE3 d = rc.poses[i].inverse() * r.poses[i];
          dt = std::max(dt, d.translation().norm());
          dr = std::max(dr, d.angle_rad() * 180.0 / M_PI);
        }
        print_row(name, points, p.backend().device(), r, dt, dr);
        print_row(name, points, Device::Cpu, rc, NAN, NAN);
        std::printf("    GPU faster than the CPU (median): %.1fx\n",
                    quantile(rc.total_ms, kMedian) / quantile(r.total_ms, kMedian));
      } else {
        print_row(name, points, p.backend().device(), r, NAN, NAN);
      }
      if (o.staged && p.backend().device() == Device::Cuda) {
        const double used_by_the_first = device_used_bytes();
        pipeline::ScanPipeline staged(cfg);
        const Run rs = run(staged, scans, used_by_the_first, true);
        double dt = 0.0, dr = 0.0;
        for (std::size_t i = 0; i < scans.size(); ++i) {
          const SE3 d = r.poses[i].inverse() * rs.poses[i];
          dt = std::max(dt, d.translation().norm());
          dr = std::max(dr, d.angle_rad() * 180.0 / M_PI);
        }
        print_row(name + "+next", points, staged.backend().device(), rs, dt, dr);
        std::printf("    scans found staged: %zu of %zu\n", rs.found_staged, scans.size());
      }
      print_bandwidth(p, o.repeats, quantile(r.total_ms, kMedian));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gpu_pipeline: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
