// The registration's covariance in the body frame, its degeneracy, and the LiDAR measurement the
// fusion builds from it (registration/degeneracy.hpp, fusion/lidar_measurement.hpp), checked
// against brute force: perturbations applied to the poses themselves.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "farlio/core/config.hpp"
#include "farlio/core/se3.hpp"
#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/lidar_measurement.hpp"
#include "farlio/registration/degeneracy.hpp"

namespace farlio {
namespace {

constexpr double kStep = 1e-6;  // finite-difference step (m, rad)

SE3 random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec6d xi;
  for (int i = 0; i < 6; ++i) xi(i) = u(rng);
  return SE3::exp(xi);
}

TEST(Degeneracy, AdjointMovesARightPerturbationThroughAnExtrinsic) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (int c = 0; c < 20; ++c) {
    const SE3 T_world_sensor = random_pose(rng), T_body_sensor = random_pose(rng);
    Vec6d xi;
    for (int i = 0; i < 6; ++i) xi(i) = u(rng);
    // (T_ws exp(xi)) T_sb == (T_ws T_sb) exp(adjoint(T_bs) xi)
    const SE3 T_sb = T_body_sensor.inverse();
    const SE3 moved = T_world_sensor * SE3::exp(xi) * T_sb;
    const SE3 predicted = T_world_sensor * T_sb * SE3::exp(adjoint(T_body_sensor) * xi);
    EXPECT_LT((moved.inverse() * predicted).log().norm(), 1e-12) << c;
  }
}

TEST(Degeneracy, BodyInformationGivesTheSameCostForTheSameMotion) {
  std::mt19937 rng(5);
  const SE3 T_body_sensor = random_pose(rng);
  Mat6d A = Mat6d::Random();
  const Mat6d H_sensor = A * A.transpose() + Mat6d::Identity();
  const double scale = 0.05;
  const Mat6d H_body = registration::body_information(H_sensor, T_body_sensor, scale);
  const Vec6d xi_sensor = Vec6d::Random() * 0.01;
  const Vec6d xi_body = adjoint(T_body_sensor) * xi_sensor;
  EXPECT_NEAR(xi_body.dot(H_body * xi_body), xi_sensor.dot(H_sensor * xi_sensor) / scale,
              1e-9 * xi_sensor.dot(H_sensor * xi_sensor) / scale);
}

TEST(Degeneracy, APlaneLeavesItsInPlaneDirectionsAndNormalRotationFree) {
  // Information of points on the plane z = 0 around the origin: constrains z, roll and pitch only.
  Mat6d H = Mat6d::Zero();
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  for (double x = -5.0; x <= 5.0; x += 1.0) {
    for (double y = -5.0; y <= 5.0; y += 1.0) {
      Eigen::Matrix<double, 1, 6> J;  // d(n . (R p + t)) / d[t; r] at identity, right perturbation
      J << n.transpose(), -(n.transpose() * hat(Eigen::Vector3d(x, y, 0.0)));
      H += J.transpose() * J;
    }
  }
  RegistrationConfig config;
  const Mat6d C = registration::covariance_from_information(registration::body_information(H, SE3(), 1e-3));
  EXPECT_TRUE(C.allFinite());
  const registration::Degeneracy d = registration::analyze_degeneracy(C, 121.0, config);
  EXPECT_EQ(d.degenerate_translations, 2);                          // x and y
  EXPECT_EQ(d.degenerate_rotations, 1);                             // yaw
  EXPECT_NEAR(std::abs(d.translation_axes.col(2).z()), 1.0, 1e-9);  // the best-constrained: the normal
  EXPECT_NEAR(std::abs(d.rotation_axes.col(0).z()), 1.0, 1e-9);     // the free rotation: about the normal
  EXPECT_NEAR(d.translation_std_m(0), registration::kUnconstrainedStd, 1e-6);
  EXPECT_LT(d.translation_std_m(2), config.degenerate_translation_std_m);
}

/// The information of a corridor along x (two walls y = +-w, floor z = 0, ceiling z = h):
/// constrains everything but the translation along x, plus a weak along-track term `weak`.
/// `end_walls`: two walls x = +-20 (40 points) close it: a room, nothing degenerate. Without them
/// it has kCorridorFactors points.
constexpr double kCorridorFactors = 41.0 * 5.0 * 4.0;
Mat6d corridor_information(double weak, bool end_walls = false) {
  Mat6d H = Mat6d::Zero();
  const auto add = [&H](const Eigen::Vector3d& n, const Eigen::Vector3d& p) {
    Eigen::Matrix<double, 1, 6> J;
    J << n.transpose(), -(n.transpose() * hat(p));
    H += J.transpose() * J;
  };
  for (double x = -20.0; x <= 20.0; x += 1.0) {
    for (double s = -2.0; s <= 2.0; s += 1.0) {
      add(Eigen::Vector3d::UnitY(), {x, 5.0, 2.0 + s});
      add(-Eigen::Vector3d::UnitY(), {x, -5.0, 2.0 + s});
      add(Eigen::Vector3d::UnitZ(), {x, 2.0 * s, 0.0});
      add(-Eigen::Vector3d::UnitZ(), {x, 2.0 * s, 5.0});
    }
  }
  if (end_walls) {
    for (double y = -4.0; y <= 4.0; y += 2.0) {
      for (double z = 1.0; z <= 4.0; z += 1.0) {
        add(Eigen::Vector3d::UnitX(), {20.0, y, z});
        add(-Eigen::Vector3d::UnitX(), {-20.0, y, z});
      }
    }
  }
  H(0, 0) += weak;
  return H;
}

TEST(Degeneracy, TheStepHoldsADegenerateDirectionAndSolvesTheOthers) {
  RegistrationConfig config;
  const double scale = 0.05;
  for (const double weak : {0.0, 1e-3, 1e-1}) {  // none, and a weak fake along-track constraint
    const Mat6d H = corridor_information(weak);
    const registration::Degeneracy d = registration::analyze_degeneracy(
        registration::covariance_from_information(H / scale), kCorridorFactors, config);
    ASSERT_EQ(d.degenerate_translations, 1) << weak;
    ASSERT_EQ(d.degenerate_rotations, 0) << weak;
    EXPECT_NEAR(std::abs(d.translation_axes.col(0).x()), 1.0, 1e-9);
    // b of a pose error [0.5 along track, 0.1 across, -0.05 up; small rotation] seen through H
    Vec6d error;
    error << 0.5, 0.1, -0.05, 0.01, -0.02, 0.005;
    const Vec6d b = H * error;  // the gradient at the wrong pose; the full step would be -error
    const Vec6d dx = registration::step_without_degenerate_directions(H, b, d);
    EXPECT_NEAR(dx(0), 0.0, 1e-12) << weak;  // held along the track
    // the other five directions are solved exactly (the corridor decouples x from them)
    EXPECT_LT((dx.tail<5>() + error.tail<5>()).norm(), 1e-9) << weak;
  }
}

// What the fusion is given along a held direction: the scan's own step there. In the corridor with
// a weak along-track term and a pose error along the track, the unconstrained step moves the pose
// back by that error along the axis and by nothing else; through an extrinsic it is the body's
// displacement of the full step (brute force: the poses themselves), projected on the axis.
TEST(Degeneracy, TheDegenerateTranslationStepIsTheScansOwnStepAlongTheAxis) {
  RegistrationConfig config;
  const double scale = 0.05;
  const Mat6d H = corridor_information(1e-1);
  const registration::Degeneracy d =
      registration::analyze_degeneracy(registration::covariance_from_information(H / scale), kCorridorFactors, config);
  ASSERT_EQ(d.degenerate_translations, 1);
  Vec6d error;
  error << 0.3, 0.1, -0.05, 0.01, -0.02, 0.005;
  registration::LinearSystem system;
  system.H = H;
  system.b = H * error;
  const Eigen::Vector3d step = registration::degenerate_translation_step(system, 0.0, SE3(), d);
  EXPECT_NEAR(step.x(), -error(0), 1e-9);
  EXPECT_NEAR(step.tail<2>().norm(), 0.0, 1e-9);

  std::mt19937 rng(5);
  for (int c = 0; c < 10; ++c) {
    const SE3 T_world_sensor = random_pose(rng), T_body_sensor = random_pose(rng);
    system.b = H * (1e-4 * error);  // a small step: the first-order body displacement is exact to 1e-8
    const Vec6d dx = (system.H + config.damping * Mat6d::Identity()).ldlt().solve(-system.b);
    const SE3 body = T_world_sensor * T_body_sensor.inverse();
    const SE3 moved = T_world_sensor * SE3::exp(dx) * T_body_sensor.inverse();
    const Eigen::Vector3d displacement = body.rotation().transpose() * (moved.translation() - body.translation());
    // the axes of a body-frame analysis: the corridor's axis moved into the body
    registration::Degeneracy body_d = d;
    body_d.translation_axes = T_body_sensor.rotation() * d.translation_axes;
    const Eigen::Vector3d axis = body_d.translation_axes.col(0);
    const Eigen::Vector3d got =
        registration::degenerate_translation_step(system, config.damping, T_body_sensor, body_d);
    EXPECT_LT((got - axis * axis.dot(displacement)).norm(), 1e-8) << c;
  }
  registration::Degeneracy none = d;
  none.degenerate_translations = 0;
  EXPECT_EQ(registration::degenerate_translation_step(system, 0.0, SE3(), none), Eigen::Vector3d::Zero());
}

TEST(Degeneracy, ReleasingRotationsKeepsTheTranslations) {
  RegistrationConfig config;
  const Mat6d C = registration::covariance_from_information(corridor_information(1e-3) / 0.05);
  registration::Degeneracy d = registration::analyze_degeneracy(C, kCorridorFactors, config);
  d.degenerate_rotations = 1;  // and one rotation axis
  const Mat6d released = registration::release_degenerate_rotations(C, d);
  EXPECT_LT((released.topLeftCorner<3, 3>() - C.topLeftCorner<3, 3>()).norm(), 1e-12);
  const Eigen::Vector3d axis = d.rotation_axes.col(0);
  EXPECT_GT(axis.dot(released.bottomRightCorner<3, 3>() * axis),
            0.99 * registration::kUnconstrainedStd * registration::kUnconstrainedStd);
}

// The per-point std (degenerate_translation_point_std_m): a room seen by few points is loose in
// every direction without being degenerate in any (its std per point is 1.04 m); a corridor's axis
// stays degenerate however many points see it. Without the per-point limit the std alone flags the
// sparse room.
TEST(Degeneracy, ASparseRoomIsLooseButNotDegenerateAndACorridorIsDegenerateAtAnyDensity) {
  const double scale = 0.05;
  constexpr double kRoomFactors = kCorridorFactors + 40.0;  // + the end walls
  const Mat6d room_per_point = corridor_information(0.0, true) / kRoomFactors;
  const Mat6d corridor_per_point = corridor_information(1e-3) / kCorridorFactors;
  for (const double point_std_m : {0.0, 2.5}) {
    RegistrationConfig config;
    config.degenerate_translation_point_std_m = point_std_m;
    for (const double points : {100.0, 2000.0}) {
      const registration::Degeneracy r = registration::analyze_degeneracy(
          registration::covariance_from_information(points * room_per_point / scale), points, config);
      const bool loose = r.translation_std_m(0) > config.degenerate_translation_std_m;
      ASSERT_EQ(loose, points < 1000.0) << "the sparse room is loose by its std, the dense one is not";
      ASSERT_LT(r.translation_std_m(0) * std::sqrt(points), 2.5);
      EXPECT_EQ(r.degenerate_translations, loose && point_std_m == 0.0 ? 1 : 0) << points << " " << point_std_m;
      const registration::Degeneracy c = registration::analyze_degeneracy(
          registration::covariance_from_information(points * corridor_per_point / scale), points, config);
      EXPECT_EQ(c.degenerate_translations, 1) << points << " " << point_std_m;
      EXPECT_NEAR(std::abs(c.translation_axes.col(0).x()), 1.0, 1e-9);
    }
  }
}

TEST(Degeneracy, WithoutDegenerateDirectionsTheStepIsThePlainSolve) {
  Mat6d A = Mat6d::Random();
  const Mat6d H = A * A.transpose() + 100.0 * Mat6d::Identity();
  const Vec6d b = Vec6d::Random();
  const registration::Degeneracy none;
  EXPECT_LT((registration::step_without_degenerate_directions(H, b, none) - H.ldlt().solve(-b)).norm(), 1e-12);
}

TEST(Degeneracy, ReleasedDirectionsBecomeUnconstrainedAndTheRestIsKept) {
  RegistrationConfig config;
  const Mat6d C = registration::covariance_from_information(corridor_information(1e-3) / 0.05);
  const registration::Degeneracy d = registration::analyze_degeneracy(C, kCorridorFactors, config);
  const Mat6d released = registration::release_degenerate_directions(C, d);
  EXPECT_GT(released(0, 0), 0.99 * registration::kUnconstrainedStd * registration::kUnconstrainedStd);
  EXPECT_LT((released.bottomRightCorner<5, 5>() - C.bottomRightCorner<5, 5>()).norm(), 1e-9);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6d>(released).eigenvalues().minCoeff(), 0.0);  // still a covariance
}

TEST(Degeneracy, PoseMeasurementCovarianceIsTheBodyCovarianceInStateCoordinates) {
  // Brute force: the Jacobian of z = [p; angles] of T exp([t; r]) against the one the
  // covariance is propagated with.
  std::mt19937 rng(11);
  FusionConfig config;
  for (int c = 0; c < 10; ++c) {
    SE3 pose = random_pose(rng);
    Mat6d J = Mat6d::Zero();
    for (int i = 0; i < 6; ++i) {
      Vec6d d = Vec6d::Zero();
      d(i) = kStep;
      const SE3 plus = pose * SE3::exp(d), minus = pose * SE3::exp(-d);
      J.block<3, 1>(0, i) = (plus.translation() - minus.translation()) / (2 * kStep);
      const Eigen::Vector3d a_plus = fusion::euler_from_rotation(plus.rotation());
      const Eigen::Vector3d a_minus = fusion::euler_from_rotation(minus.rotation());
      for (int k = 0; k < 3; ++k) J(3 + k, i) = fusion::wrap_angle(a_plus(k) - a_minus(k)) / (2 * kStep);
    }
    Mat6d A = Mat6d::Random();
    const Mat6d C = A * A.transpose() * 1e-4;
    Mat6d expected = J * C * J.transpose();
    expected.diagonal().head<3>().array() += config.lidar_min_position_std_m * config.lidar_min_position_std_m;
    expected.diagonal().tail<3>().array() += config.lidar_min_attitude_std_rad * config.lidar_min_attitude_std_rad;
    const Mat6d R = fusion::pose_measurement_covariance(C, pose, config);
    EXPECT_LT((R - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff()) << c;
  }
}

TEST(Degeneracy, VelocityCovarianceGrowsWithThePoseCovariancesOverDt) {
  FusionConfig config;
  Mat6d C = Mat6d::Zero();
  C(0, 0) = 0.04;  // 0.2 m along x in both poses
  const Eigen::Matrix3d V = fusion::velocity_measurement_covariance(C, C, 0.1, config);
  const double floor = config.lidar_velocity_std_m_s * config.lidar_velocity_std_m_s;
  EXPECT_NEAR(V(0, 0), 2 * 0.04 / 0.01 + floor, 1e-12);
  EXPECT_NEAR(V(1, 1), floor, 1e-12);
}

}  // namespace
}  // namespace farlio
