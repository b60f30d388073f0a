// The IMU error model against its parameters: turn-on bias, bias random walk, white noise density,
// scale factor, misalignment and g-sensitivity (recovered by regression), speed-dependent
// vibration at the wheel frequency, grades, and that the existing random streams are unchanged.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "farlio/sim/imu_errors.hpp"
#include "farlio/sim/imu_grade.hpp"
#include "farlio/sim/sequence_generator.hpp"

using namespace farlio;
using namespace farlio::sim;

namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

/// A profile's config with no IMU error at all (the LiDAR noise stays).
SimConfig quiet(Profile profile, double duration_s) {
  SimConfig c = default_config(profile);
  c.duration_s = duration_s;
  apply_imu_grade(c, ImuGrade::Ideal);
  return c;
}

struct Errors {
  std::vector<Eigen::Vector3d> gyro, accel;  // reading - ideal reading
  std::vector<ImuSample> ideal;
};

Errors errors_of(const SimConfig& config) {
  SimConfig exact = config;
  exact.noise_free = true;
  const auto noisy = SequenceGenerator(config).imu();
  Errors e;
  e.ideal = SequenceGenerator(exact).imu();
  for (std::size_t k = 0; k < noisy.size(); ++k) {
    e.gyro.push_back(noisy[k].gyro_rad_s - e.ideal[k].gyro_rad_s);
    e.accel.push_back(noisy[k].accel_m_s2 - e.ideal[k].accel_m_s2);
  }
  return e;
}

/// Sample variance of all components of values[k + lag] - values[k] over non-overlapping windows.
double increment_variance(const std::vector<Eigen::Vector3d>& values, std::size_t lag) {
  double sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k + lag < values.size(); k += lag, n += 3)
    sum_sq += (values[k + lag] - values[k]).squaredNorm();
  return sum_sq / static_cast<double>(n);
}

double component_std(const std::vector<Eigen::Vector3d>& values) {
  double sum = 0.0, sum_sq = 0.0;
  for (const auto& v : values) {
    sum += v.sum();
    sum_sq += v.squaredNorm();
  }
  const double n = 3.0 * static_cast<double>(values.size());
  return std::sqrt(sum_sq / n - (sum / n) * (sum / n));
}

/// Least-squares M with y = M x over all samples.
template <int Cols>
Eigen::Matrix<double, 3, Cols> regress(const std::vector<Eigen::Vector3d>& y,
                                       const std::vector<Eigen::Matrix<double, Cols, 1>>& x) {
  Eigen::Matrix<double, Cols, Cols> xx = Eigen::Matrix<double, Cols, Cols>::Zero();
  Eigen::Matrix<double, 3, Cols> yx = Eigen::Matrix<double, 3, Cols>::Zero();
  for (std::size_t k = 0; k < y.size(); ++k) {
    xx += x[k] * x[k].transpose();
    yx += y[k] * x[k].transpose();
  }
  return xx.ldlt().solve(yx.transpose()).transpose();
}
}  // namespace

TEST(SimImuErrors, TurnOnBiasIsConstantPerRunAndHasTheConfiguredSpread) {
  SimConfig c = quiet(Profile::Handheld, 2.0);
  c.imu_errors.gyro_turn_on_bias_std_rad_s = 0.01;
  c.imu_errors.accel_turn_on_bias_std_m_s2 = 0.2;
  const ImuErrorDraw draw = draw_imu_errors(c.imu_errors, c.seed);
  const Errors e = errors_of(c);
  for (std::size_t k = 0; k < e.gyro.size(); ++k) {
    ASSERT_LT((e.gyro[k] - draw.gyro_turn_on_bias_rad_s).norm(), 1e-12) << k;
    ASSERT_LT((e.accel[k] - draw.accel_turn_on_bias_m_s2).norm(), 1e-12) << k;
  }
  // Over many seeds: zero mean, the configured standard deviation per axis.
  constexpr int kSeeds = 3000;
  std::vector<Eigen::Vector3d> gyro, accel;
  for (int s = 1; s <= kSeeds; ++s) {
    const ImuErrorDraw d = draw_imu_errors(c.imu_errors, static_cast<std::uint64_t>(s));
    gyro.push_back(d.gyro_turn_on_bias_rad_s);
    accel.push_back(d.accel_turn_on_bias_m_s2);
  }
  EXPECT_NEAR(component_std(gyro), 0.01, 0.05 * 0.01);
  EXPECT_NEAR(component_std(accel), 0.2, 0.05 * 0.2);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& g : gyro) mean += g / kSeeds;
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 4.0 * 0.01 / std::sqrt(kSeeds));
}

TEST(SimImuErrors, BiasRandomWalkVarianceGrowsLinearlyWithTime) {
  constexpr double kGyroWalk = 1e-3, kAccelWalk = 1e-2;
  for (const double rate_hz : {100.0, 400.0}) {
    SimConfig c = quiet(Profile::Urban, 100.0);
    c.imu_rate_hz = rate_hz;
    c.noise.gyro_bias_walk_rad_s2_sqrt_hz = kGyroWalk;
    c.noise.accel_bias_walk_m_s3_sqrt_hz = kAccelWalk;
    const Errors e = errors_of(c);
    // One sample: var = K^2 dt (the sqrt(dt) scaling), within 5 % (~10'000 increments per axis).
    EXPECT_NEAR(increment_variance(e.gyro, 1), kGyroWalk * kGyroWalk / rate_hz, 0.05 * kGyroWalk * kGyroWalk / rate_hz);
    EXPECT_NEAR(increment_variance(e.accel, 1), kAccelWalk * kAccelWalk / rate_hz,
                0.05 * kAccelWalk * kAccelWalk / rate_hz);
    // One second: var = K^2 * 1 s (independent increments: a random walk, not a bounded process);
    // 300 increments, so within 30 %.
    const auto lag = static_cast<std::size_t>(rate_hz);
    EXPECT_NEAR(increment_variance(e.gyro, lag), kGyroWalk * kGyroWalk, 0.3 * kGyroWalk * kGyroWalk) << rate_hz;
    EXPECT_NEAR(increment_variance(e.accel, lag), kAccelWalk * kAccelWalk, 0.3 * kAccelWalk * kAccelWalk) << rate_hz;
  }
}

TEST(SimImuErrors, WhiteNoisePerSampleIsDensityTimesSqrtRate) {
  const ImuDatasheet d = imu_datasheet(ImuGrade::Consumer);
  const double gyro_density_rad_s_sqrt_hz = d.gyro_noise_density_deg_s_sqrt_hz * kRadPerDeg;
  const double accel_density_m_s2_sqrt_hz = d.accel_noise_density_ug_sqrt_hz * 1e-6 * 9.80665;
  for (const double rate_hz : {100.0, 800.0}) {
    SimConfig c = default_config(Profile::Urban);
    c.duration_s = 20.0;
    c.imu_rate_hz = rate_hz;
    apply_imu_grade(c, ImuGrade::Consumer);
    c.imu_errors = ImuErrorConfig{};  // white noise and the (negligible) bias walk only
    c.noise.gyro_bias_walk_rad_s2_sqrt_hz = c.noise.accel_bias_walk_m_s3_sqrt_hz = 0.0;
    const Errors e = errors_of(c);
    const double gyro_std = gyro_density_rad_s_sqrt_hz * std::sqrt(rate_hz);
    const double accel_std = accel_density_m_s2_sqrt_hz * std::sqrt(rate_hz);
    EXPECT_NEAR(component_std(e.gyro), gyro_std, 0.05 * gyro_std) << rate_hz;
    EXPECT_NEAR(component_std(e.accel), accel_std, 0.05 * accel_std) << rate_hz;
  }
}

TEST(SimImuErrors, ScaleFactorMisalignmentAndGSensitivityAreRecoveredByRegression) {
  SimConfig c = quiet(Profile::Handheld, 30.0);  // look-arounds and sway: rotation about every axis
  c.imu_errors.gyro_scale_factor_std_ppm = 5000.0;
  c.imu_errors.accel_scale_factor_std_ppm = 3000.0;
  c.imu_errors.gyro_misalignment_std_mrad = 5.0;
  c.imu_errors.accel_misalignment_std_mrad = 2.0;
  c.imu_errors.gyro_g_sensitivity_std_rad_s_per_m_s2 = 2e-4;
  const ImuErrorDraw draw = draw_imu_errors(c.imu_errors, c.seed);
  const auto readings = SequenceGenerator(c).imu();
  const Errors e = errors_of(c);
  std::vector<Eigen::Vector3d> gyro, accel, f;
  std::vector<Eigen::Matrix<double, 6, 1>> w_and_f;
  for (std::size_t k = 0; k < readings.size(); ++k) {
    gyro.push_back(readings[k].gyro_rad_s);
    accel.push_back(readings[k].accel_m_s2);
    f.push_back(e.ideal[k].accel_m_s2);
    Eigen::Matrix<double, 6, 1> x;
    x << e.ideal[k].gyro_rad_s, e.ideal[k].accel_m_s2;
    w_and_f.push_back(x);
  }
  const Eigen::Matrix<double, 3, 6> gyro_fit = regress<6>(gyro, w_and_f);
  const Eigen::Matrix3d accel_fit = regress<3>(accel, f);
  // 1e-8 is far below the errors themselves (>= ~1e-4 in ppm or mrad terms).
  EXPECT_LT((gyro_fit.leftCols<3>() - draw.gyro_response).cwiseAbs().maxCoeff(), 1e-8) << gyro_fit;
  EXPECT_LT((gyro_fit.rightCols<3>() - draw.gyro_g_sensitivity_rad_s_per_m_s2).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((accel_fit - draw.accel_response).cwiseAbs().maxCoeff(), 1e-8) << accel_fit;
  // And the response really is off identity by the drawn errors.
  EXPECT_GT((draw.gyro_response - Mat3d::Identity()).cwiseAbs().maxCoeff(), 1e-3);

  // The drawn constants over many seeds: the configured spread in ppm, mrad and rad/s per m/s^2.
  constexpr int kSeeds = 2000;
  double scale_sq = 0.0, misalignment_sq = 0.0, g_sq = 0.0;
  for (int s = 1; s <= kSeeds; ++s) {
    const ImuErrorDraw d = draw_imu_errors(c.imu_errors, static_cast<std::uint64_t>(s));
    const Mat3d m = d.gyro_response - Mat3d::Identity();
    scale_sq += m.diagonal().squaredNorm();
    misalignment_sq += m.squaredNorm() - m.diagonal().squaredNorm();
    g_sq += d.gyro_g_sensitivity_rad_s_per_m_s2.squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(scale_sq / (3 * kSeeds)) * 1e6, 5000.0, 0.05 * 5000.0);
  EXPECT_NEAR(std::sqrt(misalignment_sq / (6 * kSeeds)) * 1e3, 5.0, 0.05 * 5.0);
  EXPECT_NEAR(std::sqrt(g_sq / (9 * kSeeds)), 2e-4, 0.05 * 2e-4);
}

TEST(SimImuErrors, WheelVibrationGrowsWithSpeedAtTheWheelFrequency) {
  SimConfig c = quiet(Profile::Urban, 40.0);
  const VibrationConfig car = platform_vibration(Profile::Urban);
  c.imu_errors.vibration.wheel_radius_m = car.wheel_radius_m;
  c.imu_errors.vibration.accel_wheel_amplitude_m_s2_per_m_s = car.accel_wheel_amplitude_m_s2_per_m_s;
  const SequenceGenerator gen(c);
  const Errors e = errors_of(c);
  const double amplitude_z = car.accel_wheel_amplitude_m_s2_per_m_s.z();
  int crossings = 0;
  double distance_m = 0.0, peak_ratio = 0.0;
  for (std::size_t k = 0; k < e.accel.size(); ++k) {
    const BodyState s = gen.state(e.ideal[k].stamp_ns);
    const double v = s.velocity_world_m_s.norm();
    ASSERT_LE(std::abs(e.accel[k].z()), amplitude_z * v + 1e-9) << k;  // bounded by amplitude x speed
    EXPECT_EQ(e.gyro[k], Eigen::Vector3d::Zero());
    if (v > 1.0) peak_ratio = std::max(peak_ratio, std::abs(e.accel[k].z()) / (amplitude_z * v));
    if (k == 0) continue;
    distance_m +=
        (s.pose_world_body.translation() - gen.state(e.ideal[k - 1].stamp_ns).pose_world_body.translation()).norm();
    crossings += (e.accel[k].z() > 0.0) != (e.accel[k - 1].z() > 0.0) ? 1 : 0;
  }
  EXPECT_GT(peak_ratio, 0.99);  // and it reaches the amplitude
  EXPECT_GT(distance_m, 100.0);
  // A sinusoid of the wheel angle distance / r crosses zero twice per turn: distance / (pi r).
  const double expected = distance_m / (std::numbers::pi * car.wheel_radius_m);
  EXPECT_NEAR(crossings, expected, 0.01 * expected + 2.0);
}

TEST(SimImuErrors, BroadbandVibrationStdIsProportionalToSpeed) {
  SimConfig c = quiet(Profile::Urban, 40.0);
  c.imu_errors.vibration.accel_noise_std_m_s2_per_m_s = {0.01, 0.02, 0.03};
  c.imu_errors.vibration.gyro_noise_std_rad_s_per_m_s = {1e-3, 2e-3, 3e-3};
  const SequenceGenerator gen(c);
  const Errors e = errors_of(c);
  std::vector<Eigen::Vector3d> accel_per_speed, gyro_per_speed;
  for (std::size_t k = 0; k < e.accel.size(); ++k) {
    const double v = gen.state(e.ideal[k].stamp_ns).velocity_world_m_s.norm();
    if (v == 0.0) {
      EXPECT_EQ(e.accel[k], Eigen::Vector3d::Zero()) << "no vibration at rest";
      continue;
    }
    accel_per_speed.push_back(e.accel[k] / v);
    gyro_per_speed.push_back(e.gyro[k] / v);
  }
  ASSERT_GT(accel_per_speed.size(), 3000U);
  for (int a = 0; a < 3; ++a) {
    double sa = 0.0, sg = 0.0;
    for (std::size_t k = 0; k < accel_per_speed.size(); ++k) {
      sa += accel_per_speed[k][a] * accel_per_speed[k][a];
      sg += gyro_per_speed[k][a] * gyro_per_speed[k][a];
    }
    const auto n = static_cast<double>(accel_per_speed.size());
    EXPECT_NEAR(std::sqrt(sa / n), c.imu_errors.vibration.accel_noise_std_m_s2_per_m_s[a],
                0.05 * c.imu_errors.vibration.accel_noise_std_m_s2_per_m_s[a]);
    EXPECT_NEAR(std::sqrt(sg / n), c.imu_errors.vibration.gyro_noise_std_rad_s_per_m_s[a],
                0.05 * c.imu_errors.vibration.gyro_noise_std_rad_s_per_m_s[a]);
  }
}

TEST(SimImuErrors, NewErrorsLeaveTheExistingRandomStreamsUnchanged) {
  SimConfig base = default_config(Profile::Urban);
  base.duration_s = 3.0;
  SimConfig profile_grade = base;
  apply_imu_grade(profile_grade, ImuGrade::Profile);
  SimConfig turn_on = base;
  turn_on.imu_errors.gyro_turn_on_bias_std_rad_s = 0.01;
  turn_on.imu_errors.accel_turn_on_bias_std_m_s2 = 0.1;
  const ImuErrorDraw draw = draw_imu_errors(turn_on.imu_errors, turn_on.seed);
  const auto a = SequenceGenerator(base).imu(), b = SequenceGenerator(profile_grade).imu(),
             c = SequenceGenerator(turn_on).imu();
  ASSERT_EQ(a.size(), c.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_TRUE(a[k].gyro_rad_s == b[k].gyro_rad_s && a[k].accel_m_s2 == b[k].accel_m_s2) << k;
    // Same white noise and bias walk; only the turn-on bias is added.
    ASSERT_LT((c[k].gyro_rad_s - a[k].gyro_rad_s - draw.gyro_turn_on_bias_rad_s).norm(), 1e-12) << k;
    ASSERT_LT((c[k].accel_m_s2 - a[k].accel_m_s2 - draw.accel_turn_on_bias_m_s2).norm(), 1e-12) << k;
  }
  // The meta data of the default IMU does not mention the error model.
  EXPECT_EQ(SequenceGenerator(base).description().count("gyro_scale_factor_std_ppm"), 0U);
  EXPECT_EQ(SequenceGenerator(turn_on).description().count("gyro_scale_factor_std_ppm"), 1U);
}

TEST(SimImuErrors, GradedImuIsDeterministicPerSeed) {
  SimConfig c = default_config(Profile::Racetrack);
  c.duration_s = 12.0;  // into the launch: the vibration is on
  apply_imu_grade(c, ImuGrade::Consumer);
  const auto a = SequenceGenerator(c).imu(), b = SequenceGenerator(c).imu();
  c.seed = 2;
  const auto other = SequenceGenerator(c).imu();
  ASSERT_EQ(a.size(), b.size());
  bool differs = false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_TRUE(a[k].gyro_rad_s == b[k].gyro_rad_s && a[k].accel_m_s2 == b[k].accel_m_s2) << k;
    differs |= a[k].accel_m_s2 != other[k].accel_m_s2;
  }
  EXPECT_TRUE(differs);
}

TEST(SimImuErrors, IdealGradeIsTheNoiseFreeImu) {
  SimConfig ideal = default_config(Profile::Handheld);
  ideal.duration_s = 3.0;
  SimConfig exact = ideal;
  exact.noise_free = true;
  apply_imu_grade(ideal, ImuGrade::Ideal);
  EXPECT_GT(ideal.noise.range_noise_std_m, 0.0);  // the LiDAR keeps its noise
  const auto a = SequenceGenerator(ideal).imu(), b = SequenceGenerator(exact).imu();
  for (std::size_t k = 0; k < a.size(); ++k)
    ASSERT_TRUE(a[k].gyro_rad_s == b[k].gyro_rad_s && a[k].accel_m_s2 == b[k].accel_m_s2) << k;
}

TEST(SimImuErrors, GradesParseConvertAndAreOrdered) {
  for (const ImuGrade g :
       {ImuGrade::Profile, ImuGrade::Ideal, ImuGrade::Consumer, ImuGrade::Industrial, ImuGrade::Tactical})
    EXPECT_EQ(parse_imu_grade(imu_grade_name(g)), g);
  EXPECT_THROW(parse_imu_grade("navigation"), std::invalid_argument);
  EXPECT_THROW(imu_datasheet(ImuGrade::Profile), std::invalid_argument);
  // Every figure: consumer >= industrial >= tactical > 0.
  const ImuDatasheet grades[] = {imu_datasheet(ImuGrade::Consumer), imu_datasheet(ImuGrade::Industrial),
                                 imu_datasheet(ImuGrade::Tactical)};
  const auto fields = [](const ImuDatasheet& d) {
    return std::vector<double>{d.gyro_noise_density_deg_s_sqrt_hz,
                               d.gyro_bias_instability_deg_h,
                               d.gyro_turn_on_bias_deg_s,
                               d.gyro_scale_factor_ppm,
                               d.gyro_misalignment_mrad,
                               d.gyro_g_sensitivity_deg_s_g,
                               d.accel_noise_density_ug_sqrt_hz,
                               d.accel_bias_instability_ug,
                               d.accel_turn_on_bias_mg,
                               d.accel_scale_factor_ppm,
                               d.accel_misalignment_mrad};
  };
  for (std::size_t i = 0; i < fields(grades[0]).size(); ++i) {
    EXPECT_GE(fields(grades[0])[i], fields(grades[1])[i]) << i;
    EXPECT_GE(fields(grades[1])[i], fields(grades[2])[i]) << i;
    EXPECT_GT(fields(grades[2])[i], 0.0) << i;
  }
  // The conversions into the generator's units at the profile's rate.
  SimConfig c = default_config(Profile::Racetrack);
  apply_imu_grade(c, ImuGrade::Tactical, /*vibration=*/false);
  const ImuDatasheet& t = grades[2];
  EXPECT_NEAR(c.noise.gyro_noise_std_rad_s, t.gyro_noise_density_deg_s_sqrt_hz * kRadPerDeg * std::sqrt(800.0), 1e-15);
  EXPECT_NEAR(c.noise.gyro_bias_walk_rad_s2_sqrt_hz * std::sqrt(kBiasInstabilityTime_s / 3.0),
              t.gyro_bias_instability_deg_h * kRadPerDeg / 3600.0, 1e-15);
  EXPECT_NEAR(c.imu_errors.accel_turn_on_bias_std_m_s2, t.accel_turn_on_bias_mg * 1e-3 * 9.80665, 1e-15);
  EXPECT_FALSE(c.imu_errors.vibration.any());
  apply_imu_grade(c, ImuGrade::Tactical);
  EXPECT_TRUE(c.imu_errors.vibration.any());
}

TEST(SimImuErrors, InvalidParametersAreRejected) {
  SimConfig c = quiet(Profile::Urban, 1.0);
  c.imu_errors.gyro_scale_factor_std_ppm = -1.0;
  EXPECT_THROW(SequenceGenerator{c}, std::invalid_argument);
  c = quiet(Profile::Urban, 1.0);
  c.imu_errors.vibration.wheel_radius_m = 0.0;
  EXPECT_THROW(SequenceGenerator{c}, std::invalid_argument);
}
