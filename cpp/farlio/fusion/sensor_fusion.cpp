#include "farlio/fusion/sensor_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/time.hpp"
#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/lidar_measurement.hpp"

namespace farlio::fusion {
namespace {
constexpr std::size_t kExtraHistoryEntries = 2;  ///< both ends of the history span

double square(double v) { return v * v; }

InputVector input_variance(const FusionConfig& c) {
  InputVector q;
  q << Eigen::Vector3d::Constant(square(c.accel_input_std_m_s2)),
      Eigen::Vector3d::Constant(square(c.gyro_input_std_rad_s));
  return q;
}

/// Per second: the bias random walks, zero unless the biases are estimated.
InputVector bias_walk_variance(const FusionConfig& c) {
  InputVector q = InputVector::Zero();
  if (c.estimate_imu_bias) {
    q << Eigen::Vector3d::Constant(square(c.accel_bias_walk_m_s3_sqrt_hz)),
        Eigen::Vector3d::Constant(square(c.gyro_bias_walk_rad_s2_sqrt_hz));
  }
  return q;
}

SE3 pose_of(const StateVector& x) {
  return {rotation_from_euler(x.segment<3>(kAttitudeIndex)), Eigen::Vector3d(x.segment<3>(kPositionIndex))};
}

struct LidarGroup {
  MeasurementKind kind;
  Eigen::VectorXd z;
  Eigen::MatrixXd R;
};
}  // namespace

SensorFusion::SensorFusion(const FusionConfig& config, double gravity_m_s2)
    : config_(validated(config)),
      gravity_m_s2_(gravity_m_s2),
      step_ns_(seconds_to_ns(config.step_s)),
      ekf_(gravity_m_s2, input_variance(config), bias_walk_variance(config)),
      imu_(config.imu_gap_limit_s, config.history_s),
      imu_gate_(config),
      accel_unit_(config.accel_unit_detection, config.accel_unit_detection_samples, gravity_m_s2),
      bias_(config, gravity_m_s2),
      reference_(config.reference_filter_taps, gravity_m_s2, config.reference_max_sin),
      history_(static_cast<std::size_t>(std::ceil(config.history_s / config.step_s)) + kExtraHistoryEntries),
      queue_(config.delay_compensation),
      accel_bias_m_s2_(config.accel_bias_x_m_s2, config.accel_bias_y_m_s2, config.accel_bias_z_m_s2) {}

void SensorFusion::warn(std::string message) { stats_.last_warning = std::move(message); }

void SensorFusion::record_correction(const StateVector& before) {
  StateVector d = ekf_.state() - before;
  for (int i = 0; i < 3; ++i) d(kAttitudeIndex + i) = wrap_angle(d(kAttitudeIndex + i));
  cumulative_correction_ += d;
}

double SensorFusion::gate(int dim) const {
  if (!config_.outlier_rejection) return 0.0;
  if (dim == 2) return config_.outlier_chi2_2dof;
  return dim == 6 ? config_.outlier_chi2_6dof : config_.outlier_chi2_3dof;
}

void SensorFusion::add_imu(const ImuSample& sample) {
  if (const std::string why = imu_gate_.check(sample, accel_unit_.scale()); !why.empty()) {
    ++stats_.imu_samples_rejected;
    warn("IMU sample at " + std::to_string(sample.stamp_ns) + " ns rejected: " + why);
    return;
  }
  if (!imu_.push(sample)) {
    ++stats_.imu_samples_dropped;
    warn("IMU sample at " + std::to_string(sample.stamp_ns) + " ns is older than the newest one: dropped");
    return;
  }
  accel_unit_.add(sample.accel_m_s2);
  if (config_.standstill_bias && initialized() && accel_unit_.decided()) {
    const double speed_m_s = ekf_.state().segment<3>(kVelocityIndex).norm();
    bias_.add(sample.gyro_rad_s, accel_unit_.scale() * sample.accel_m_s2, speed_m_s);
  }
}

InputVector SensorFusion::input_of(const ImuReading& r) const {
  return make_input(accel_unit_.scale() * r.accel - accel_bias_m_s2_, r.gyro_rad_s - bias_.bias_rad_s());
}

void SensorFusion::advance_to(std::int64_t stamp_ns) {
  clock_ns_ = clock_set_ ? std::max(clock_ns_, stamp_ns) : stamp_ns;
  clock_set_ = true;
  if (!initialized()) {
    imu_.discard_before(clock_ns_);
    return;
  }
  while (time_ns_ + step_ns_ <= clock_ns_) step();
}

void SensorFusion::step() {
  accel_unit_.decide();  // the unit must be fixed before the first input is used
  const std::int64_t t0 = time_ns_, t1 = time_ns_ + step_ns_;
  const ImuReading r0 = imu_.at(t0), rm = imu_.mean(t0, t1), r1 = imu_.at(t1);
  InputVector u0 = input_of(r0), um = input_of(rm), u1 = input_of(r1);
  if (r0.in_gap || rm.in_gap || r1.in_gap) {
    if (!in_gap_) {
      ++stats_.imu_gaps;
      warn("IMU gap at " + std::to_string(t0) + " ns: predicting with the last input");
    }
    in_gap_ = true;
    const InputVector held = stats_.steps > 0 ? last_input_ : u0;
    u0 = um = u1 = held;
  } else {
    in_gap_ = false;
  }
  ekf_.predict(u0, um, u1, ns_to_seconds(step_ns_));
  time_ns_ = t1;
  const StateVector before_injections = ekf_.state();
  queue_.inject(ekf_);
  record_correction(before_injections);
  last_input_ = u1;
  if (config_.reference_angles) fuse_reference_angles(t1);
  history_.push(t1, ekf_.state(), cumulative_correction_);
  ++stats_.steps;
  imu_.discard_before(t1);
}

void SensorFusion::fuse_reference_angles(std::int64_t stamp_ns) {
  const StateVector& x = ekf_.state();
  const InputVector u = corrected_last_input();
  const auto angles =
      reference_.push(stamp_ns, x.segment<3>(kVelocityIndex), u.segment<3>(kAccelIndex), u.segment<3>(kGyroIndex));
  if (!angles) return;
  if (angles->saturated) {  // a clamped asin is only a bound on the angle: not fused
    ++stats_.reference_angles_rejected;
    return;
  }
  const Eigen::Vector2d z(angles->roll_rad, angles->pitch_rad);
  const Eigen::Matrix2d R =
      Eigen::Vector2d(square(config_.reference_roll_std_rad), square(config_.reference_pitch_std_rad)).asDiagonal();
  const ArrivalResidual r = arrival_residual(MeasurementKind::kRollPitch, z, angles->stamp_ns, history_, x,
                                             cumulative_correction_, config_.delay_compensation);
  if (!r.residual) return;
  const StateVector before = x;
  if (ekf_.update(MeasurementKind::kRollPitch, *r.residual, R, gate(2))) {
    ++stats_.reference_angles_accepted;
    queue_.note_correction(before, ekf_.state());
    record_correction(before);
  } else {
    ++stats_.reference_angles_rejected;
  }
}

void SensorFusion::initialize(std::int64_t stamp_ns, const SE3& pose, const Eigen::Vector3d& velocity,
                              bool velocity_known) {
  accel_unit_.decide();
  // a re-initialisation keeps the bias estimates and their uncertainty
  const bool keep_biases = ekf_.initialized();
  const StateVector previous = ekf_.state();
  const StateMatrix previous_P = ekf_.covariance();
  StateVector x = StateVector::Zero();
  x.segment<3>(kPositionIndex) = pose.translation();
  x.segment<3>(kAttitudeIndex) = euler_from_rotation(pose.rotation());
  if (velocity_known) x.segment<3>(kVelocityIndex) = velocity;
  StateVector variance = StateVector::Zero();
  variance.segment<3>(kPositionIndex).setConstant(square(config_.initial_position_std_m));
  variance.segment<3>(kAttitudeIndex).setConstant(square(config_.initial_attitude_std_rad));
  variance.segment<3>(kVelocityIndex)
      .setConstant(square(velocity_known ? config_.lidar_velocity_std_m_s : config_.initial_velocity_std_m_s));
  if (config_.estimate_imu_bias) {
    variance.segment<3>(kGyroBiasIndex).setConstant(square(config_.gyro_bias_std_rad_s));
    variance.segment<3>(kAccelBiasIndex).setConstant(square(config_.accel_bias_std_m_s2));
  }
  StateMatrix P = variance.asDiagonal();
  if (keep_biases) {
    constexpr int kBiasStates = kStateDim - kGyroBiasIndex;
    x.tail<kBiasStates>() = previous.tail<kBiasStates>();
    P.bottomRightCorner<kBiasStates, kBiasStates>() = previous_P.bottomRightCorner<kBiasStates, kBiasStates>();
  }
  ekf_.initialize(x, P);
  time_ns_ = stamp_ns;
  history_.clear();
  cumulative_correction_.setZero();
  history_.push(stamp_ns, ekf_.state(), cumulative_correction_);
  queue_.clear();
  reference_.reset();
  in_gap_ = false;
  consecutive_rejections_ = 0;
  while (clock_set_ && time_ns_ + step_ns_ <= clock_ns_) step();
}

int SensorFusion::spread_steps(std::int64_t measured_at_ns) const {
  if (config_.update_spread_steps > 0) return config_.update_spread_steps;
  if (!last_lidar_ns_ || measured_at_ns <= *last_lidar_ns_) return 1;
  const auto n = std::llround(static_cast<double>(measured_at_ns - *last_lidar_ns_) / static_cast<double>(step_ns_));
  return static_cast<int>(std::clamp<long long>(n, 1, std::max(1, config_.max_update_spread_steps)));
}

LidarUpdateResult SensorFusion::add_lidar(std::int64_t measured_at_ns, const SE3& body_pose,
                                          const Eigen::Vector3d& body_velocity_m_s, bool use_velocity,
                                          const std::optional<Mat6d>& body_covariance,
                                          const std::optional<Eigen::Matrix3d>& velocity_covariance) {
  LidarUpdateResult result;
  if (!initialized()) {
    initialize(measured_at_ns, body_pose, body_velocity_m_s, use_velocity);
    last_lidar_ns_ = measured_at_ns;
    result.initialized_filter = true;
    return result;
  }
  std::vector<LidarGroup> groups;
  const Eigen::Vector3d angles = euler_from_rotation(body_pose.rotation());
  const bool registration_covariance = body_covariance && config_.lidar_information_from_registration;
  if (registration_covariance) {
    Vec6d z;
    z << body_pose.translation(), angles;
    groups.push_back({MeasurementKind::kPose, z, pose_measurement_covariance(*body_covariance, body_pose, config_)});
  } else {  // the paper's fixed noise, position and orientation gated separately
    const Mat6d R = fixed_pose_covariance(config_);
    groups.push_back({MeasurementKind::kPosition, body_pose.translation(), R.topLeftCorner<3, 3>()});
    groups.push_back({MeasurementKind::kOrientation, angles, R.bottomRightCorner<3, 3>()});
  }
  if (use_velocity) {
    groups.push_back({MeasurementKind::kVelocity, body_velocity_m_s,
                      registration_covariance && velocity_covariance
                          ? *velocity_covariance
                          : Eigen::Matrix3d(Eigen::Matrix3d::Identity() * square(config_.lidar_velocity_std_m_s))});
  }
  const int injections = spread_steps(measured_at_ns);
  last_lidar_ns_ = measured_at_ns;
  const StateVector x_now = ekf_.state();
  std::vector<Eigen::VectorXd> residuals;
  for (const LidarGroup& g : groups) {
    ArrivalResidual r = arrival_residual(g.kind, g.z, measured_at_ns, history_, x_now, cumulative_correction_,
                                         config_.delay_compensation);
    if (!r.residual) {
      ++stats_.lidar_too_old;
      result.rejection_reason = r.rejection_reason;
      warn("LiDAR result rejected: " + r.rejection_reason);
      return result;
    }
    residuals.push_back(*r.residual);
  }
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const LidarGroup& g = groups[i];
    const double limit = gate(static_cast<int>(g.z.size()));
    const bool accepted = limit <= 0.0 || ekf_.mahalanobis_squared(g.kind, residuals[i], g.R) <= limit;
    if (accepted) {
      queue_.add(g.kind, g.z, residuals[i], g.R, injections);
      ++stats_.lidar_groups_accepted;
    } else {
      ++stats_.lidar_groups_rejected;
      warn(std::string("LiDAR ") + kind_name(g.kind) + " rejected as an outlier at " + std::to_string(measured_at_ns) +
           " ns");
    }
    if (g.kind == MeasurementKind::kPosition || g.kind == MeasurementKind::kPose) result.position_accepted = accepted;
    if (g.kind == MeasurementKind::kOrientation || g.kind == MeasurementKind::kPose) {
      result.orientation_accepted = accepted;
    }
    if (g.kind == MeasurementKind::kVelocity) result.velocity_accepted = accepted;
  }
  consecutive_rejections_ = result.position_accepted ? 0 : consecutive_rejections_ + 1;
  if (consecutive_rejections_ >= std::max(1, config_.max_consecutive_rejections)) {
    ++stats_.reinitializations;
    warn("LiDAR positions rejected " + std::to_string(consecutive_rejections_) +
         " times in a row: re-initialising from the LiDAR result");
    initialize(measured_at_ns, body_pose, body_velocity_m_s, use_velocity);
    result.initialized_filter = true;
  }
  return result;
}

BodyEstimate SensorFusion::estimate() const {
  BodyEstimate e;
  if (!initialized()) return e;
  const StateVector& x = ekf_.state();
  e.valid = true;
  e.stamp_ns = time_ns_;
  e.pose = pose_of(x);
  e.velocity_body_m_s = x.segment<3>(kVelocityIndex);
  return e;
}

std::optional<SE3> SensorFusion::pose_at(std::int64_t stamp_ns) const {
  if (!initialized() || history_.empty()) return std::nullopt;
  // the corrections applied since that step move the past as they moved the present (the x_s of
  // delay compensation, eq. 10): a scan that starts after a later result was fused gets it too
  if (const auto entry = history_.entry_at(stamp_ns)) return pose_of(corrected_since(*entry, cumulative_correction_));
  const StampedState& newest = history_.newest();
  const double ahead_s = ns_to_seconds(stamp_ns - newest.stamp_ns);
  if (ahead_s <= 0.0 || ahead_s > config_.max_extrapolation_s) return std::nullopt;
  const StateVector x = corrected_since(newest, cumulative_correction_);
  return pose_of(integrate_step(x, last_input_, last_input_, last_input_, ahead_s, gravity_m_s2_));
}

FusionStats SensorFusion::stats() const {
  FusionStats s = stats_;
  s.accel_in_g = accel_unit_.in_g();
  s.accel_unit_message = accel_unit_.message();
  s.gyro_bias_rad_s = bias_.bias_rad_s();
  s.accel_bias_m_s2 = accel_bias_m_s2_;
  if (initialized()) {
    s.gyro_bias_rad_s += ekf_.state().segment<3>(kGyroBiasIndex);
    s.accel_bias_m_s2 += ekf_.state().segment<3>(kAccelBiasIndex);
  }
  s.bias_samples = static_cast<std::int64_t>(bias_.sample_count());
  return s;
}

}  // namespace farlio::fusion
