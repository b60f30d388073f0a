// The one check of per-point times (point_times.hpp) and the sequence folder using it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "farlio/io/point_times.hpp"
#include "farlio/io/sequence.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

constexpr double kPeriod_s = 0.1;

Scan scan_with_times(std::vector<float> times, double duration_s = kPeriod_s) {
  Scan s;
  s.time_s = std::move(times);
  s.points.assign(s.time_s.size(), Vec3f(1, 2, 3));
  s.end_stamp_ns = seconds_to_ns(duration_s);
  return s;
}

}  // namespace

TEST(PointTimes, SecondsSinceTheStartPass) {
  EXPECT_EQ(point_time_problem(std::vector<float>{0.0f, 0.05f, 0.1f}, kPeriod_s), "");
  EXPECT_EQ(point_time_problem(std::vector<float>{0.0f, 0.105f}, kPeriod_s), "");  // stamp jitter
  EXPECT_EQ(point_time_problem(std::vector<float>{-0.0005f, 0.05f}, kPeriod_s), "");
  EXPECT_EQ(point_time_problem(std::vector<float>{}, kPeriod_s), "");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(point_time_problem(std::vector<float>{nan, 0.02f}, kPeriod_s), "");  // dropped later
  EXPECT_NO_THROW(check_point_times(scan_with_times({0.0f, 0.099f}), "a.pcd"));
}

TEST(PointTimes, NanosecondsAsSecondsSpanTooLong) {
  const std::string p = point_time_problem(std::vector<float>{0.0f, 5e7f, 9.9e7f}, kPeriod_s);
  EXPECT_NE(p.find("span 9.9e+07 s"), std::string::npos) << p;
  EXPECT_NE(p.find("nanoseconds"), std::string::npos) << p;
  EXPECT_FALSE(point_time_span_plausible(kMaxScanSpan_s * 2));
  EXPECT_FALSE(point_time_span_plausible(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(point_time_span_plausible(kPeriod_s));
}

TEST(PointTimes, NegativeTimesAndTimesPastTheScanAreRejected) {
  std::string p = point_time_problem(std::vector<float>{-0.05f, 0.0f}, kPeriod_s);
  EXPECT_NE(p.find("start at -0.05 s, before the scan start"), std::string::npos) << p;
  p = point_time_problem(std::vector<float>{0.0f, 0.5f}, kPeriod_s);  // 5 scan periods
  EXPECT_NE(p.find("reach 0.5 s but the scan lasts 0.1 s (5 times as long"), std::string::npos) << p;
  try {
    check_point_times(scan_with_times({0.0f, 0.5f}), "lidar/100000000.pcd");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lidar/100000000.pcd: per-point times reach 0.5 s"), std::string::npos)
        << e.what();
  }
  // Without a duration only the span and the sign are checked.
  EXPECT_EQ(point_time_problem(std::vector<float>{0.0f, 0.5f}, 0.0), "");
}

TEST(PointTimes, SequenceFolderChecksEveryScan) {
  TempDir tmp;
  SequenceWriter w(tmp.path());
  constexpr std::int64_t kPeriodNs = 100'000'000;
  for (int k = 1; k <= 3; ++k) {
    Scan s = test::random_scan(50, static_cast<unsigned>(k));  // times in [0, 0.1)
    s.end_stamp_ns = k * kPeriodNs;
    if (k == 2) {
      for (float& t : s.time_s) t *= 1e9f;  // nanoseconds stored as seconds
    }
    if (k == 3) {
      for (float& t : s.time_s) t -= 0.1f;  // relative to the scan end
    }
    w.write_scan(s);
  }
  const SequenceReader r(tmp.path());
  EXPECT_NO_THROW((void)r.read_scan(0));
  test::expect_input_error([&] { (void)r.read_scan(1); }, r.scan_path(1), "their unit is not seconds");
  test::expect_input_error([&] { (void)r.read_scan(2); }, r.scan_path(2), "before the scan start");
}
