#include <gtest/gtest.h>

#include <random>

#include "farlio/io/calibration.hpp"
#include "farlio/io/sequence.hpp"
#include "farlio/io/trajectory_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

constexpr std::int64_t kT0_ns = 1'600'000'000'000'000'000;
constexpr std::int64_t kPeriod_ns = 100'000'000;

std::vector<ImuSample> make_imu(std::size_t n) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<ImuSample> imu;
  for (std::size_t i = 0; i < n; ++i) {
    ImuSample s;
    s.stamp_ns = kT0_ns + static_cast<std::int64_t>(i) * 5'000'000;
    s.gyro_rad_s = Vec3d(g(rng), g(rng), g(rng)) * 0.1;
    s.accel_m_s2 = Vec3d(g(rng), g(rng), 9.81 + g(rng));
    imu.push_back(s);
  }
  return imu;
}

Calibration make_calib() {
  Calibration c;
  c.T_imu_lidar = SE3(so3_exp(Eigen::Vector3d(0.1, -0.2, 0.3)), Eigen::Vector3d(0.5, 0.0, -0.25));
  c.gravity_m_s2 = 9.80665;
  c.imu_rate_hz = 200;
  c.lidar_rate_hz = 10;
  return c;
}

}  // namespace

TEST(Sequence, WriteReadRoundTrip) {
  TempDir tmp;
  const auto dir = tmp.path() / "seq";
  SequenceWriter w(dir);
  const Calibration calib = make_calib();
  w.write_calibration(calib);
  std::vector<Scan> scans;
  Trajectory gt_scans, lidar_poses;
  // Irregular periods: the start stamps must follow the previous end stamp.
  const std::vector<std::int64_t> ends = {kT0_ns, kT0_ns + kPeriod_ns, kT0_ns + 2 * kPeriod_ns + 3,
                                          kT0_ns + 3 * kPeriod_ns};
  for (std::size_t i = 0; i < ends.size(); ++i) {
    Scan s = test::random_scan(300 + i, static_cast<unsigned>(i));
    s.end_stamp_ns = ends[i];
    w.write_scan(s, i % 2 ? PcdEncoding::BinaryCompressed : PcdEncoding::Binary);
    scans.push_back(s);
    const SE3 pose =
        SE3::exp((Vec6d() << 1.0 * static_cast<double>(i), 0, 0, 0, 0, 0.1 * static_cast<double>(i)).finished());
    gt_scans.push_back(ends[i], pose);
    lidar_poses.push_back(ends[i], pose * calib.T_imu_lidar);
  }
  const auto imu = make_imu(100);
  w.write_imu(imu);
  w.write_groundtruth(gt_scans);
  w.write_groundtruth_scans(gt_scans);
  w.write_groundtruth_kitti(lidar_poses);
  w.write_meta({{"profile", "walk: slow"}, {"seed", "42"}});

  SequenceReader r(dir);
  ASSERT_EQ(r.num_scans(), ends.size());
  EXPECT_TRUE(r.warnings().empty());
  for (std::size_t i = 0; i < ends.size(); ++i) {
    EXPECT_EQ(r.scan_end_stamp_ns(i), ends[i]);
    const Scan s = r.read_scan(i);
    EXPECT_EQ(s.end_stamp_ns, ends[i]);
    const std::int64_t period = i == 0 ? ends[1] - ends[0] : ends[i] - ends[i - 1];
    EXPECT_EQ(s.start_stamp_ns, ends[i] - period) << i;
    test::expect_bit_equal(scans[i], s);
  }
  EXPECT_THROW((void)r.read_scan(ends.size()), std::out_of_range);

  ASSERT_TRUE(r.has_imu());
  ASSERT_EQ(r.imu().size(), imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_EQ(r.imu()[i].stamp_ns, imu[i].stamp_ns);
    EXPECT_EQ(r.imu()[i].gyro_rad_s, imu[i].gyro_rad_s);  // shortest round-trip text: exact
    EXPECT_EQ(r.imu()[i].accel_m_s2, imu[i].accel_m_s2);
  }
  const auto& c = r.calibration();
  EXPECT_LT((c.T_imu_lidar.matrix() - calib.T_imu_lidar.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(c.gravity_m_s2, calib.gravity_m_s2);
  EXPECT_EQ(c.imu_rate_hz, 200);
  EXPECT_EQ(c.lidar_rate_hz, 10);

  const auto gt = r.groundtruth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), gt_scans.size());
  for (std::size_t i = 0; i < gt->size(); ++i) EXPECT_EQ((*gt)[i].stamp_ns, ends[i]);
  ASSERT_TRUE(r.groundtruth_scans().has_value());

  const auto kitti = read_kitti(dir / "groundtruth_kitti.txt");
  ASSERT_EQ(kitti.size(), ends.size());
  EXPECT_LT((kitti[0].pose.matrix() - Mat4d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  const SE3 want = lidar_poses[0].pose.inverse() * lidar_poses[3].pose;
  EXPECT_LT((kitti[3].pose.matrix() - want.matrix()).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(Sequence, KittiLayout) {
  TempDir tmp;
  SequenceWriter w(tmp.path());
  const Scan s = test::random_scan(50, 9);
  w.write_kitti_scan(s, 7);
  w.write_kitti_times({kT0_ns, kT0_ns + 100'000'001});
  const Scan r = read_point_cloud(tmp.path() / "velodyne" / "000007.bin");
  ASSERT_EQ(r.size(), s.size());
  EXPECT_EQ(test::read_raw(tmp.path() / "times.txt"), "0.000000000\n0.100000001\n");
}

TEST(Sequence, LoneScanStartUsesMaxTime) {
  TempDir tmp;
  SequenceWriter w(tmp.path());
  Scan s = test::random_scan(100, 3);
  s.time_s.back() = 0.25f;
  s.end_stamp_ns = 5'000'000'000;
  w.write_scan(s);
  SequenceReader r(tmp.path());
  ASSERT_EQ(r.num_scans(), 1u);
  EXPECT_FALSE(r.has_imu());
  EXPECT_FALSE(r.groundtruth().has_value());
  const Scan back = r.read_scan(0);
  EXPECT_EQ(back.start_stamp_ns, 5'000'000'000 - std::llround(0.25f * 1e9));
}

namespace {

/// A sequence folder with calib.yaml and one scan (ending at 100 ns), for the imu.csv beside them.
void write_folder_with_one_scan(const std::filesystem::path& dir) {
  SequenceWriter w(dir);
  w.write_calibration(Calibration{});
  Scan s = test::random_scan(10, 1);
  s.end_stamp_ns = 100;
  w.write_scan(s);
}

}  // namespace

TEST(Sequence, ImuBackwardsSampleDroppedWithWarning) {
  TempDir tmp;
  write_folder_with_one_scan(tmp.path());
  test::write_raw(tmp.path() / "imu.csv",
                  "ax,ay,az,t_ns,gx,gy,gz,temp_c\n"
                  "0,0,9.81,1000,0.1,0.2,0.3,25\n"
                  "0,0,9.81,2000,0.1,0.2,0.3,25\n"
                  "0,0,9.81,1500,0.1,0.2,0.3,25\n"
                  "\n"
                  "1,2,3,3000,4,5,6,25\n");
  SequenceReader r(tmp.path());
  ASSERT_EQ(r.imu().size(), 3u);
  EXPECT_EQ(r.imu()[2].stamp_ns, 3000);
  EXPECT_EQ(r.imu()[2].gyro_rad_s, Vec3d(4, 5, 6));
  EXPECT_EQ(r.imu()[2].accel_m_s2, Vec3d(1, 2, 3));
  const auto warn = r.warnings();
  ASSERT_EQ(warn.size(), 2u);  // the unknown column and the dropped sample
  bool found = false;
  for (const auto& m : warn)
    found = found || (m.find("imu.csv:4") != std::string::npos && m.find("dropped") != std::string::npos);
  EXPECT_TRUE(found);
}

TEST(Sequence, AnImuStampFarAheadCostsOneSample) {
  // one sample stamped 1000 s ahead (a clock glitch) is dropped, not every sample after it; one
  // stamped behind is dropped as well, and so is one that repeats a stamp
  TempDir tmp;
  write_folder_with_one_scan(tmp.path());
  std::string csv = "t_ns,gx,gy,gz,ax,ay,az\n";
  std::vector<std::int64_t> expected;
  for (std::int64_t k = 1; k <= 30; ++k) {
    std::int64_t t = k * 10'000'000;
    if (k == 10) t += 1'000'000'000'000;  // far ahead: dropped
    if (k == 20) t = 5'000'000;           // behind: dropped
    if (k == 25) t = 24 * 10'000'000;     // a repeated stamp: dropped
    if (k != 10 && k != 20 && k != 25) expected.push_back(t);
    csv += std::to_string(t) + ",0,0,0,0,0,9.81\n";
  }
  test::write_raw(tmp.path() / "imu.csv", csv);
  SequenceReader r(tmp.path());
  ASSERT_EQ(r.imu().size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(r.imu()[i].stamp_ns, expected[i]) << i;
  const auto warn = r.warnings();
  ASSERT_EQ(warn.size(), 3u);
  EXPECT_NE(warn[0].find("imu.csv:11: sample at 1000100000000 ns is ahead of the samples after it"), std::string::npos)
      << warn[0];
  EXPECT_NE(warn[1].find("imu.csv:21: sample at 5000000 ns is not after the previous one"), std::string::npos)
      << warn[1];
  EXPECT_NE(warn[2].find("imu.csv:26"), std::string::npos) << warn[2];
}

TEST(Sequence, ImuNonFiniteSamplesDroppedWithWarnings) {
  // a sensor's NaN or inf drops its sample (named), the run goes on; text that is no number stays
  // an error naming the line
  TempDir tmp;
  write_folder_with_one_scan(tmp.path());
  std::string csv = "t_ns,gx,gy,gz,ax,ay,az\n";
  for (int k = 1; k <= 20; ++k) {
    const bool bad = k % 4 == 0 || k > 14;  // 4, 8, 12, 15..20: 9 samples
    csv += std::to_string(k * 1000) + (bad ? ",nan,0,0,0,0,9.81\n" : ",0,0,0,0,0,9.81\n");
  }
  csv += "21000,0,0,0,0,inf,9.81\n22000,0,0,0,0,-INF,9.81\n23000,0,0,0,0,0,9.81\n";
  test::write_raw(tmp.path() / "imu.csv", csv);
  SequenceReader r(tmp.path());
  ASSERT_EQ(r.imu().size(), 12u);  // 23 - 11
  for (const auto& sample : r.imu()) EXPECT_TRUE(sample.accel_m_s2.allFinite() && sample.gyro_rad_s.allFinite());
  const auto warn = r.warnings();
  ASSERT_EQ(warn.size(), 11u);  // 10 named, then the count
  EXPECT_NE(warn[0].find("imu.csv:5: gx 'nan' is not finite; sample dropped"), std::string::npos) << warn[0];
  EXPECT_NE(warn[10].find("11 samples with a nan or inf value dropped"), std::string::npos) << warn[10];

  test::write_raw(tmp.path() / "imu.csv", "t_ns,gx,gy,gz,ax,ay,az\n1000,0,0,abc,0,0,9.81\n");
  test::expect_input_error([&] { SequenceReader bad(tmp.path()); }, tmp.path() / "imu.csv", "gz 'abc' is not a number");
}

TEST(Sequence, BadFoldersThrow) {
  TempDir tmp;
  const auto d = tmp.path();
  test::expect_input_error([&] { SequenceReader r(d); }, d / "lidar", "lidar");

  std::filesystem::create_directories(d / "lidar");
  write_pcd(d / "lidar" / "12ab.pcd", test::random_scan(5, 1));
  test::expect_input_error([&] { SequenceReader r(d); }, d / "lidar" / "12ab.pcd", "not an integer");
  std::filesystem::remove(d / "lidar" / "12ab.pcd");

  write_pcd(d / "lidar" / "100.pcd", test::random_scan(5, 1));
  write_kitti_bin(d / "lidar" / "100.bin", test::random_scan(5, 1));
  test::expect_input_error([&] { SequenceReader r(d); }, d / "lidar" / "100.pcd", "duplicate");
  std::filesystem::remove(d / "lidar" / "100.bin");

  test::write_raw(d / "imu.csv", "t_ns,gx,gy,gz,ax,ay,az\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "missing");

  write_calibration(d / "calib.yaml", Calibration{});
  test::write_raw(d / "imu.csv", "t_ns,gx,gy,ax,ay,az\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "imu.csv", "'gz'");
  test::write_raw(d / "imu.csv", "t_ns,gx,gy,gz,ax,ay,az\n1,0,0,0,0,0,9.8\n2,0,0,zero,0,0,9.8\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "imu.csv", "imu.csv:3");
  test::write_raw(d / "imu.csv", "t_ns,gx,gy,gz,ax,ay,az\n1,0,0,0,0,0\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "imu.csv", "imu.csv:2");
  test::write_raw(d / "imu.csv", "t_ns,gx,gy,gz,ax,ay,az\n");

  test::write_raw(d / "calib.yaml",
                  "T_imu_lidar:\n  - [1, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "T_imu_lidar");
  test::write_raw(d / "calib.yaml",
                  "T_imu_lidar:\n  - [2, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "rotation");
  test::write_raw(d / "calib.yaml", "gravity: 9.81\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "T_imu_lidar");
  test::write_raw(d / "calib.yaml", "T_imu_lidar: [unclosed\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "YAML");
  test::write_raw(
      d / "calib.yaml",
      "T_imu_lidar:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\ngravity: abc\n");
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "gravity");
  test::write_raw(
      d / "calib.yaml",
      "T_imu_lidar:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\nextra: {a: 1}\n");
  SequenceReader ok(d);  // extra keys are ignored
  EXPECT_FALSE(ok.calibration().gravity_m_s2.has_value());
  EXPECT_EQ(ok.calibration().gravity_or_default(), kDefaultGravity_m_s2);
}
