// The CPU backend's preprocessing (CpuScanBackend::preprocess) against a brute force: the kept
// points are the first raw point of each downsampling cell of the raw positions (in key order),
// each undistorted; and against the geometry: a scan of fixed world points measured by a moving
// sensor comes out in the sensor frame at the scan's end.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/deskew/scan_motion.hpp"
#include "farlio/map/voxel_update.hpp"
#include "farlio/pipeline/cpu_scan_backend.hpp"
#include "farlio/preprocess/preprocess_point.hpp"
#include "farlio/preprocess/range_crop.hpp"

using namespace farlio;

namespace {

constexpr double kDuration_s = 0.1;

/// World points measured by a sensor that moves with `twist` over the scan and ends at T_end.
struct MovingScan {
  Scan scan;
  std::vector<Eigen::Vector3d> in_end_frame;  ///< each point's exact position at the scan's end
};

MovingScan moving_scan(const Vec6d& twist, const SE3& T_end, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-40.0, 40.0), ut(0.0, kDuration_s);
  MovingScan out;
  out.scan.end_stamp_ns = seconds_to_ns(kDuration_s);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d world(u(rng), u(rng), 0.1 * u(rng));
    const double tau = ut(rng);
    const SE3 T_tau = T_end * SE3::exp((tau - kDuration_s) * twist);
    out.scan.points.push_back((T_tau.inverse() * world).cast<float>());
    out.scan.time_s.push_back(static_cast<float>(tau));
    out.in_end_frame.push_back(T_end.inverse() * world);
  }
  return out;
}

}  // namespace

TEST(Preprocess, KeepsTheFirstRawPointOfEachCellUndistorted) {
  Vec6d twist;
  twist << 30.0, 1.0, 0.0, 0.05, -0.1, 2.0;  // m/s and rad/s
  const SE3 T_end = SE3::exp((Vec6d() << 3, 1, 0, 0, 0, 0.3).finished());
  const MovingScan ms = moving_scan(twist, T_end, 60000, 4);
  const auto motion = deskew::ScanMotion::constant_twist(twist.cast<float>(), static_cast<float>(kDuration_s));
  for (const int threads : {1, 2, 3}) {
    Config cfg;
    cfg.num_threads = threads;
    pipeline::CpuScanBackend backend(cfg);
    for (const bool undistort : {false, true}) {
      const std::size_t kept = backend.preprocess(ms.scan, motion, undistort);
      const std::vector<Eigen::Vector3f> frame = backend.frame_points();
      ASSERT_EQ(frame.size(), kept);
      // brute force: cells of the raw positions, the first index of each, in key order
      const preprocess::PreprocessParams pp{preprocess::RangeCrop::from(cfg.preprocess),
                                            deskew::DeskewTable::sample(motion, static_cast<float>(kDuration_s)),
                                            undistort, static_cast<float>(1.0 / map::point_spacing_m(cfg.map))};
      std::map<std::uint64_t, std::size_t> first;
      for (std::size_t i = 0; i < ms.scan.size(); ++i) {
        if (!pp.crop.keeps(ms.scan.points[i])) continue;
        const std::uint64_t key = map::point_key(ms.scan.points[i], pp.inv_cell_m);
        if (key != map::kEmptyKey) first.try_emplace(key, i);
      }
      ASSERT_EQ(frame.size(), first.size()) << threads << " threads";
      std::size_t k = 0;
      double worst_m = 0.0;
      for (const auto& [key, i] : first) {
        const Eigen::Vector3f expected = preprocess::undistorted_point(ms.scan.points[i], ms.scan.time_s[i], pp);
        ASSERT_EQ(frame[k], expected) << "cell " << k;
        worst_m = std::max(worst_m, (frame[k].cast<double>() - ms.in_end_frame[i]).norm());
        ++k;
      }
      if (undistort) {
        EXPECT_LT(worst_m, 2e-3);  // the sensor moved 3 m and turned 0.2 rad over the scan
      } else {
        EXPECT_GT(worst_m, 1.0);
      }
    }
  }
}
