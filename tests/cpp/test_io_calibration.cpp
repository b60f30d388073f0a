// calib.yaml: the single and the several-LiDAR (mapping) forms, gravity stated or not, the
// rigidity check shared with the Python dataloaders, and bad input named by file and key.
#include <gtest/gtest.h>

#include <limits>

#include "farlio/io/calibration.hpp"
#include "farlio/io/rigid_transform.hpp"
#include "farlio/io/sequence.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

constexpr double kExact = 1e-12;
const std::string kIdentityRows = "    - [1, 0, 0, 0]\n    - [0, 1, 0, 0]\n    - [0, 0, 1, 0]\n    - [0, 0, 0, 1]\n";

SE3 pose(double x, double yaw) { return SE3(so3_exp(Eigen::Vector3d(0.1, -0.2, yaw)), Eigen::Vector3d(x, 0.5, -0.25)); }

void expect_same(const SE3& a, const SE3& b) { EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), kExact); }

}  // namespace

TEST(Calibration, SingleFormRoundTripWithGravityAndRates) {
  TempDir tmp;
  Calibration c;
  c.T_imu_lidar = pose(0.5, 0.3);
  c.gravity_m_s2 = 9.80665;
  c.imu_rate_hz = 200;
  c.lidar_rate_hz = 10;
  const auto p = tmp.path() / "calib.yaml";
  write_calibration(p, c);
  const Calibration back = read_calibration(p);
  expect_same(back.T_imu_lidar, c.T_imu_lidar);
  EXPECT_TRUE(back.T_imu_lidar_by_name.empty());
  EXPECT_EQ(back.gravity_m_s2, c.gravity_m_s2);
  EXPECT_EQ(back.imu_rate_hz, 200);
  EXPECT_EQ(back.lidar_rate_hz, 10);
  EXPECT_EQ(back.source, p);
}

TEST(Calibration, GravityNotStatedStaysUnstated) {
  TempDir tmp;
  const auto p = tmp.path() / "calib.yaml";
  write_calibration(p, Calibration{});
  const Calibration back = read_calibration(p);
  EXPECT_FALSE(back.gravity_m_s2.has_value());
  EXPECT_EQ(back.gravity_or_default(), kDefaultGravity_m_s2);
  Calibration stated;
  stated.gravity_m_s2 = 9.7;
  EXPECT_EQ(stated.gravity_or_default(), 9.7);
}

TEST(Calibration, MappingFormReadsEveryLidar) {
  TempDir tmp;
  const auto p = tmp.path() / "calib.yaml";
  test::write_raw(p, "T_imu_lidar:\n  /front:\n" + kIdentityRows +
                         "  rear_frame: [[1, 0, 0, 1.5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n");
  const Calibration c = read_calibration(p);
  ASSERT_EQ(c.T_imu_lidar_by_name.size(), 2u);
  expect_same(c.T_imu_lidar_by_name.at("/front"), SE3());
  EXPECT_EQ(c.T_imu_lidar_by_name.at("rear_frame").translation(), Eigen::Vector3d(1.5, 0, 0));
  EXPECT_FALSE(c.gravity_m_s2.has_value());
  // the first name found wins: topic first, then frame id
  EXPECT_EQ(c.lidar_extrinsic({"/rear", "rear_frame"}).translation().x(), 1.5);
  EXPECT_EQ(c.lidar_extrinsic({"/front", "rear_frame"}).translation().x(), 0.0);
}

TEST(Calibration, MappingFormRoundTripKeepsAwkwardNames) {
  TempDir tmp;
  Calibration c;
  c.T_imu_lidar_by_name = {
      {"/front", pose(1, 0.1)}, {"rear: 2 # not a comment", pose(-1, 2.0)}, {"\"q\"", pose(3, -1)}};
  c.gravity_m_s2 = 9.81;
  const auto p = tmp.path() / "calib.yaml";
  write_calibration(p, c);
  const Calibration back = read_calibration(p);
  ASSERT_EQ(back.T_imu_lidar_by_name.size(), c.T_imu_lidar_by_name.size());
  for (const auto& [name, T] : c.T_imu_lidar_by_name) expect_same(back.T_imu_lidar_by_name.at(name), T);
  EXPECT_EQ(back.gravity_m_s2, 9.81);
}

TEST(Calibration, SingleFormServesEveryName) {
  Calibration c;
  c.T_imu_lidar = pose(2, 0.4);
  expect_same(c.lidar_extrinsic({"/anything"}), c.T_imu_lidar);
  expect_same(c.lidar_extrinsic({}), c.T_imu_lidar);
}

TEST(Calibration, UnknownLidarNamesTheFileAndTheEntries) {
  TempDir tmp;
  const auto p = tmp.path() / "multi.yaml";
  test::write_raw(p, "T_imu_lidar:\n  /front:\n" + kIdentityRows + "  /rear:\n" + kIdentityRows);
  const Calibration c = read_calibration(p);
  test::expect_input_error(
      [&] {
        (void)c.lidar_extrinsic({"/top", "top_frame"});
      },
      p, "no entry for '/top' or 'top_frame' (entries: /front, /rear)");
}

TEST(Calibration, BadInputNamesFileAndKey) {
  TempDir tmp;
  const auto p = tmp.path() / "bad.yaml";
  auto expect_error = [&](const std::string& text, const std::string& fragment) {
    test::write_raw(p, text);
    test::expect_input_error([&] { (void)read_calibration(p); }, p, fragment);
  };
  expect_error("gravity: 9.81\n", "missing key 'T_imu_lidar'");
  expect_error("T_imu_lidar: [unclosed\n", "not valid YAML");
  expect_error("- 1\n- 2\n", "mapping at the top level");
  expect_error("T_imu_lidar: 3\n", "expected a 4x4 matrix");
  expect_error("T_imu_lidar:\n  - [1, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n", "row 0");
  expect_error("T_imu_lidar:\n  - [2, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n", "rotation");
  expect_error("T_imu_lidar:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 1, 1]\n", "last row");
  expect_error("T_imu_lidar:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, x]\n  - [0, 0, 0, 1]\n",
               "T_imu_lidar[2][3]' is not a number");
  expect_error("T_imu_lidar:\n" + kIdentityRows + "gravity: abc\n", "gravity");
  expect_error("T_imu_lidar:\n" + kIdentityRows + "imu: {rate_hz: .nan}\n", "imu.rate_hz");
  expect_error("T_imu_lidar: {}\n", "no entry");
  expect_error("T_imu_lidar:\n  /front: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]\n",
               "key 'T_imu_lidar[/front]': expected a 4x4 matrix");
  expect_error("T_imu_lidar:\n  /front: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
               "key 'T_imu_lidar[/front]': not a rigid transform");
  expect_error("T_imu_lidar:\n  /front:\n" + kIdentityRows +
                   "  /rear: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], "
                   "[0, 0, 0, y]]\n",
               "T_imu_lidar[/rear][3][3]");
  expect_error("T_imu_lidar:\n  ? [a, b]\n  : [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
               "not a LiDAR topic or frame id");
  test::expect_input_error([&] { (void)read_calibration(tmp.path() / "none.yaml"); }, tmp.path() / "none.yaml",
                           "no such file");
}

TEST(RigidTransform, AcceptsRigidAndNamesWhatIsNot) {
  const SE3 T = pose(1.0, 2.5);
  expect_same(rigid_transform_from_matrix(T.matrix(), "x"), T);
  Mat4d near = T.matrix();
  near(0, 0) += 0.5 * kRigidTolerance;
  EXPECT_NO_THROW((void)rigid_transform_from_matrix(near, "x"));
  auto expect_error = [](const Mat4d& m, const std::string& fragment) {
    try {
      (void)rigid_transform_from_matrix(m, "/a/calib.txt");
      ADD_FAILURE() << "accepted " << m;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("/a/calib.txt: not a rigid transform", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  Mat4d scaled = T.matrix();
  scaled.topLeftCorner<3, 3>() *= 1.01;
  expect_error(scaled, "rotation block");
  Mat4d mirrored = T.matrix();
  mirrored.col(2) *= -1.0;  // orthonormal, determinant -1
  expect_error(mirrored, "rotation block");
  Mat4d projective = T.matrix();
  projective(3, 0) = 0.01;
  expect_error(projective, "last row");
  Mat4d nan = T.matrix();
  nan(1, 3) = std::numeric_limits<double>::quiet_NaN();
  expect_error(nan, "non-finite");
}

TEST(Calibration, SequenceFolderRejectsTheMappingForm) {
  TempDir tmp;
  const auto d = tmp.path() / "seq";
  std::filesystem::create_directories(d / "lidar");
  write_pcd(d / "lidar" / "100.pcd", test::random_scan(5, 1));
  test::write_raw(d / "calib.yaml", "T_imu_lidar:\n  /front:\n" + kIdentityRows);
  test::expect_input_error([&] { SequenceReader r(d); }, d / "calib.yaml", "several LiDARs");
}
