// Per-scan generation time of the sequence generator, per profile, on one core (TBB limited
// to one thread) and on all cores. Usage: sim_speed [scans_per_profile]
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "farlio/sim/sequence_generator.hpp"

namespace {
constexpr std::size_t kDefaultScans = 10;
constexpr double kFirstScan_s = 3.0;  // skip the first scans: every profile starts at rest for 2 s

struct Timing {
  double mean_ms = 0.0, max_ms = 0.0;
  double mean_points = 0.0;
};

Timing time_scans(const farlio::sim::SequenceGenerator& gen, std::size_t count) {
  Timing t;
  const auto first = static_cast<std::size_t>(std::llround(kFirstScan_s * gen.lidar_rate_hz()));
  for (std::size_t i = first; i < first + count; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const farlio::Scan scan = gen.scan(i);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    t.mean_ms += ms / static_cast<double>(count);
    t.max_ms = std::max(t.max_ms, ms);
    t.mean_points += static_cast<double>(scan.size()) / static_cast<double>(count);
  }
  return t;
}
}  // namespace

int main(int argc, char** argv) {
  const std::size_t scans = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : kDefaultScans;
  std::printf("%-10s %12s %14s %14s %14s %12s\n", "profile", "points/scan", "1 core ms", "1 core max ms",
              "all cores ms", "threads");
  for (const auto profile : {farlio::sim::Profile::Racetrack, farlio::sim::Profile::Urban,
                             farlio::sim::Profile::Handheld, farlio::sim::Profile::Tunnel}) {
    farlio::sim::SimConfig cfg = farlio::sim::default_config(profile);
    const farlio::sim::SequenceGenerator gen(cfg);
    Timing one;
    {
      const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
      one = time_scans(gen, scans);
    }
    const Timing all = time_scans(gen, scans);
    std::printf("%-10s %12.0f %14.1f %14.1f %14.1f %12d\n", farlio::sim::profile_name(profile).c_str(), one.mean_points,
                one.mean_ms, one.max_ms, all.mean_ms, tbb::info::default_concurrency());
  }
  return 0;
}
