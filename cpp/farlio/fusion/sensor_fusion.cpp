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
/// In motion, the LiDAR results the alignment needs at least (two equations a pair, six unknowns
/// a pose: three poses make it overdetermined).
constexpr std::size_t kMinPosesInMotion = 3;
/// The LiDAR poses of a body at rest move by up to this between two scans (registration noise):
/// a window whose results move less shows rest whatever the scan rate.
constexpr double kRestPositionJitter_m = 0.02;
/// The zero-velocity prior of a window that shows the body at rest (m/s): tight, so that gravity
/// follows from the specific force as in levelling.
constexpr double kRestVelocityStd_m_s = 0.01;
/// The std of the world frame's tilt after an initialisation in motion (rad): the alignment's
/// error over fusion.init.window_s, which the tilt state then refines.
constexpr double kInMotionTiltStd_rad = 0.05;
/// A window whose free gravity estimate is further than this (relative) from the known
/// magnitude does not initialise the filter: its poses or IMU disagree (a failing registration).
constexpr double kMaxGravityNormError = 0.1;

double square(double v) { return v * v; }

/// The input noise over one step: the configured stds, or the IMU's measured noise where larger.
InputVector input_variance(const FusionConfig& c, const std::optional<ImuNoise>& measured = std::nullopt) {
  Eigen::Vector3d accel = Eigen::Vector3d::Constant(c.accel_input_std_m_s2);
  Eigen::Vector3d gyro = Eigen::Vector3d::Constant(c.gyro_input_std_rad_s);
  if (measured) {
    accel = accel.cwiseMax(measured->accel_step_std_m_s2(c.step_s));
    gyro = gyro.cwiseMax(measured->gyro_step_std_rad_s(c.step_s));
  }
  InputVector q;
  q << accel.cwiseAbs2(), gyro.cwiseAbs2();
  return q;
}

/// Per second: the bias random walks, zero unless the biases are estimated.
InputVector bias_walk_variance(const FusionConfig& c) {
  InputVector q = InputVector::Zero();
  if (c.bias.estimate) {
    q << Eigen::Vector3d::Constant(square(c.bias.accel_walk_m_s3_sqrt_hz)),
        Eigen::Vector3d::Constant(square(c.bias.gyro_walk_rad_s2_sqrt_hz));
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

SensorFusion::SensorFusion(const FusionConfig& config, double gravity_m_s2, MapFrameKnowledge known)
    : config_(validated(config)),
      gravity_m_s2_(gravity_m_s2),
      step_ns_(seconds_to_ns(config.step_s)),
      ekf_(gravity_m_s2, input_variance(config), bias_walk_variance(config)),
      imu_(config.imu_gate.gap_limit_s, config.history_s),
      imu_gate_(config),
      accel_unit_(config.units.accel_detection, config.units.accel_samples, gravity_m_s2),
      bias_(config, gravity_m_s2),
      reference_(config.reference_angles.filter_taps, gravity_m_s2, config.reference_angles.max_sin),
      history_(static_cast<std::size_t>(std::ceil(config.history_s / config.step_s)) + kExtraHistoryEntries),
      queue_(config.delay.compensation),
      accel_bias_m_s2_(config.bias.accel_init_x_m_s2, config.bias.accel_init_y_m_s2, config.bias.accel_init_z_m_s2),
      window_(std::move(known.window)),
      known_tilt_std_rad_(known.tilt_std_rad) {
  if (known.gravity_map_m_s2) level_from_map_ = level_from_map(*known.gravity_map_m_s2);
}

MapFrameKnowledge SensorFusion::map_frame_knowledge() const {
  MapFrameKnowledge k;
  k.window = window_;
  if (!level_from_map_) return k;
  if (!initialized()) {
    k.gravity_map_m_s2 = map_from_level() * Eigen::Vector3d(0.0, 0.0, -gravity_m_s2_);
    k.tilt_std_rad = known_tilt_std_rad_;
    return k;
  }
  k.gravity_map_m_s2 = map_from_level() * world_gravity(ekf_.state(), gravity_m_s2_);
  k.tilt_std_rad = std::sqrt(ekf_.covariance().block<2, 2>(kTiltIndex, kTiltIndex).diagonal().maxCoeff());
  return k;
}

void SensorFusion::warn(std::string message) { stats_.last_warning = std::move(message); }

void SensorFusion::record_correction(const StateVector& before) {
  StateVector d = ekf_.state() - before;
  for (int i = 0; i < 3; ++i) d(kAttitudeIndex + i) = wrap_angle(d(kAttitudeIndex + i));
  cumulative_correction_ += d;
}

void SensorFusion::record_innovation(MeasurementKind kind, int dim, double nis) {
  const std::string group = kind_name(kind);
  auto& all = stats_.lidar_innovation;
  auto it = std::find_if(all.begin(), all.end(), [&](const InnovationStats& s) { return s.group == group; });
  if (it == all.end()) it = all.insert(all.end(), InnovationStats{.group = group, .dim = dim});
  it->add(nis);
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
  imu_noise_.add(sample.stamp_ns, sample.gyro_rad_s, accel_unit_.scale() * sample.accel_m_s2);
  if (imu_noise_.updated()) ekf_.set_input_variance(input_variance(config_, imu_noise_.noise()));
  if (config_.standstill.gyro_bias && initialized() && accel_unit_.decided()) {
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
  if (config_.reference_angles.enabled) fuse_reference_angles(t1);
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
      Eigen::Vector2d(square(config_.reference_angles.roll_std_rad), square(config_.reference_angles.pitch_std_rad))
          .asDiagonal();
  const ArrivalResidual r = arrival_residual(MeasurementKind::kRollPitch, z, angles->stamp_ns, history_, x,
                                             cumulative_correction_, config_.delay.compensation);
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

void SensorFusion::initialize(std::int64_t stamp_ns, const SE3& level_pose, const Eigen::Vector3d& velocity_body_m_s,
                              double velocity_std_m_s, double tilt_std_rad) {
  accel_unit_.decide();
  // a re-initialisation keeps the bias estimates and their uncertainty
  const bool keep_biases = ekf_.initialized();
  const StateVector previous = ekf_.state();
  const StateMatrix previous_P = ekf_.covariance();
  StateVector x = StateVector::Zero();
  x.segment<3>(kPositionIndex) = level_pose.translation();
  x.segment<3>(kAttitudeIndex) = euler_from_rotation(level_pose.rotation());
  x.segment<3>(kVelocityIndex) = velocity_body_m_s;
  StateVector variance = StateVector::Zero();
  variance.segment<3>(kPositionIndex).setConstant(square(config_.init.position_std_m));
  variance.segment<3>(kAttitudeIndex).setConstant(square(config_.init.attitude_std_rad));
  variance.segment<3>(kVelocityIndex).setConstant(square(velocity_std_m_s));
  if (config_.bias.estimate) {
    variance.segment<3>(kGyroBiasIndex).setConstant(square(config_.bias.gyro_std_rad_s));
    variance.segment<3>(kAccelBiasIndex).setConstant(square(config_.bias.accel_std_m_s2));
  }
  variance.segment<2>(kTiltIndex).setConstant(square(tilt_std_rad));
  StateMatrix P = variance.asDiagonal();
  if (keep_biases) {  // and the tilt
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

void SensorFusion::initialize_known(std::int64_t stamp_ns, const SE3& body_pose,
                                    const Eigen::Vector3d& velocity_body_m_s) {
  level_from_map_ = Eigen::Matrix3d::Identity();
  initialize(stamp_ns, body_pose, velocity_body_m_s, config_.lidar_velocity_std_m_s, 0.0);
  last_lidar_ns_ = stamp_ns;
  add_to_window(stamp_ns, body_pose, {});
  InitializationReport& report = stats_.initialization;
  report = InitializationReport{};
  report.initialized = true;
  report.mode = "given";
  report.stamp_ns = stamp_ns;
  report.speed_m_s = velocity_body_m_s.norm();
}

Eigen::Matrix3d SensorFusion::map_from_level() const {
  return level_from_map_ ? Eigen::Matrix3d(level_from_map_->transpose()) : Eigen::Matrix3d::Identity();
}

SE3 SensorFusion::to_level(const SE3& map_pose) const {
  const Eigen::Matrix3d R = map_from_level().transpose();
  return {R * map_pose.rotation(), R * map_pose.translation()};
}

SE3 SensorFusion::to_map(const SE3& level_pose) const {
  const Eigen::Matrix3d R = map_from_level();
  return {R * level_pose.rotation(), R * level_pose.translation()};
}

void SensorFusion::add_to_window(std::int64_t stamp_ns, const SE3& body_pose, const RestJitter& rest_jitter) {
  if (!window_.empty() && stamp_ns <= window_.back().stamp_ns) return;
  const auto span_s = [&](const WindowPose& from) { return ns_to_seconds(stamp_ns - from.stamp_ns); };
  if (!window_.empty() && span_s(window_.back()) > config_.init.window_s) window_.clear();  // an outage
  window_.push_back({stamp_ns, body_pose, rest_jitter});
  // the shortest run of the newest results that spans fusion.init.window_s
  while (window_.size() > 2 && span_s(window_[1]) >= config_.init.window_s) window_.erase(window_.begin());
}

std::optional<ImuMean> SensorFusion::imu_mean(std::int64_t start_ns, std::int64_t end_ns) const {
  // before the oldest sample kept the signal is unknown; beyond the newest it is held up to the
  // gap limit (ImuBuffer flags it as a gap after that)
  if (imu_.empty() || start_ns < imu_.oldest().stamp_ns) return std::nullopt;
  const ImuReading r = imu_.mean(start_ns, end_ns);
  if (r.in_gap) return std::nullopt;
  const InputVector u = initialized() ? corrected_input(ekf_.state(), input_of(r)) : input_of(r);
  return ImuMean{u.segment<3>(kAccelIndex), u.segment<3>(kGyroIndex)};
}

std::optional<Eigen::Matrix3d> SensorFusion::imu_rotation(std::int64_t start_ns, std::int64_t end_ns) const {
  const auto increment =
      integrate_imu([this](std::int64_t t0, std::int64_t t1) { return imu_mean(t0, t1); }, start_ns, end_ns, step_ns_);
  if (!increment) return std::nullopt;
  return increment->rotation;
}

bool moved_within_rest(const SE3& motion, double dt_s, const FusionConfig& config, const RestJitter& jitter) {
  const double jitter_m = std::max(kRestPositionJitter_m, jitter.translation_m);
  return motion.translation().norm() <= std::max(config.standstill.max_speed_m_s * dt_s, jitter_m) &&
         motion.angle_rad() <= std::max(config.standstill.max_gyro_rad_s * dt_s, jitter.rotation_rad);
}

bool SensorFusion::window_at_rest() const {
  for (std::size_t k = 1; k < window_.size(); ++k) {
    const WindowPose& a = window_[k - 1];
    const WindowPose& b = window_[k];
    const RestJitter jitter{std::max(a.rest_jitter.translation_m, b.rest_jitter.translation_m),
                            std::max(a.rest_jitter.rotation_rad, b.rest_jitter.rotation_rad)};
    if (!moved_within_rest(a.body_pose.inverse() * b.body_pose, ns_to_seconds(b.stamp_ns - a.stamp_ns), config_,
                           jitter))
      return false;
  }
  return window_.size() >= 2;
}

bool SensorFusion::initialize_from_window() {
  if (window_.size() < 2) return false;
  accel_unit_.decide();  // the alignment reads the accelerometer in m/s^2
  AlignmentOptions options;
  options.gravity_m_s2 = gravity_m_s2_;
  options.step_ns = step_ns_;
  if (level_from_map_) options.gravity_map_m_s2 = map_from_level() * Eigen::Vector3d(0.0, 0.0, -gravity_m_s2_);
  const bool at_rest = window_at_rest();
  const double span_s = ns_to_seconds(window_.back().stamp_ns - window_.front().stamp_ns);
  if (at_rest) {  // gravity is the mean specific force, the velocity zero: two results suffice
    options.zero_velocity_std_m_s = kRestVelocityStd_m_s;
  } else if (!level_from_map_ && (window_.size() < kMinPosesInMotion || span_s < config_.init.window_s)) {
    return false;  // in motion, gravity is found over the whole window
  }
  const auto alignment = align_window(
      window_, [this](std::int64_t t0, std::int64_t t1) { return imu_mean(t0, t1); }, options);
  if (!alignment) return false;
  const bool first = !level_from_map_;
  if (first) {
    if (alignment->gravity_norm_error > kMaxGravityNormError) return false;  // the window disagrees: wait
    level_from_map_ = level_from_map(alignment->gravity_map_m_s2);
  }
  const WindowPose& last = window_.back();
  const Eigen::Vector3d velocity_body = last.body_pose.rotation().transpose() * alignment->velocity_map_m_s;
  // levelled at rest, gravity is off by the accelerometer's bias (held, as the paper's 9-state
  // filter holds its level, when the biases are not estimated); in motion, by the alignment's error
  const double levelled_tilt_std_rad = config_.bias.estimate ? config_.bias.accel_std_m_s2 / gravity_m_s2_ : 0.0;
  const double tilt_std_rad = first ? (at_rest ? levelled_tilt_std_rad : kInMotionTiltStd_rad) : known_tilt_std_rad_;
  initialize(last.stamp_ns, to_level(last.body_pose), velocity_body, config_.lidar_velocity_std_m_s, tilt_std_rad);
  InitializationReport& report = stats_.initialization;
  if (!report.initialized) {
    report.initialized = true;
    report.mode = at_rest ? "standstill" : "in motion";
    report.stamp_ns = last.stamp_ns;
    report.window_poses = static_cast<int>(window_.size());
    report.window_s = span_s;
    report.speed_m_s = alignment->velocity_map_m_s.norm();
    report.gravity_norm_error = alignment->gravity_norm_error;
    report.up_map = map_from_level() * Eigen::Vector3d::UnitZ();
    report.map_tilt_deg = std::acos(std::clamp(report.up_map.z(), -1.0, 1.0)) * 180.0 / M_PI;
  }
  return true;
}

int SensorFusion::spread_steps(std::int64_t measured_at_ns) const {
  if (config_.delay.spread_steps > 0) return config_.delay.spread_steps;
  if (!last_lidar_ns_ || measured_at_ns <= *last_lidar_ns_) return 1;
  const auto n = std::llround(static_cast<double>(measured_at_ns - *last_lidar_ns_) / static_cast<double>(step_ns_));
  return static_cast<int>(std::clamp<long long>(n, 1, std::max(1, config_.delay.max_spread_steps)));
}

LidarUpdateResult SensorFusion::add_lidar(std::int64_t measured_at_ns, const SE3& map_pose,
                                          const Eigen::Vector3d& body_velocity_m_s, bool use_velocity,
                                          const std::optional<Mat6d>& body_covariance,
                                          const std::optional<Eigen::Matrix3d>& velocity_covariance,
                                          const RestJitter& rest_jitter) {
  LidarUpdateResult result;
  add_to_window(measured_at_ns, map_pose, rest_jitter);
  if (!initialized()) {
    result.initialized_filter = initialize_from_window();
    last_lidar_ns_ = measured_at_ns;
    return result;
  }
  const SE3 body_pose = to_level(map_pose);
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
                                         config_.delay.compensation);
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
    const double nis = ekf_.mahalanobis_squared(g.kind, residuals[i], g.R);
    const bool accepted = limit <= 0.0 || nis <= limit;
    record_innovation(g.kind, static_cast<int>(g.z.size()), nis);
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
         " times in a row: re-initialising from the LiDAR results of the last fusion.init.window_s");
    if (!initialize_from_window()) {  // the window too short (an outage): the eq. (6) velocity
      const Eigen::Vector3d velocity =
          use_velocity ? body_velocity_m_s : Eigen::Vector3d(ekf_.state().segment<3>(kVelocityIndex));
      initialize(measured_at_ns, body_pose, velocity, config_.lidar_velocity_std_m_s, 0.0);
    }
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
  e.pose = to_map(pose_of(x));
  e.velocity_body_m_s = x.segment<3>(kVelocityIndex);
  return e;
}

std::optional<SE3> SensorFusion::pose_at(std::int64_t stamp_ns) const {
  if (!initialized() || history_.empty()) return std::nullopt;
  // the corrections applied since that step move the past as they moved the present (the x_s of
  // delay compensation, eq. 10): a scan that starts after a later result was fused gets it too
  if (const auto entry = history_.entry_at(stamp_ns))
    return to_map(pose_of(corrected_since(*entry, cumulative_correction_)));
  const StampedState& newest = history_.newest();
  const double ahead_s = ns_to_seconds(stamp_ns - newest.stamp_ns);
  if (ahead_s <= 0.0 || ahead_s > config_.max_extrapolation_s) return std::nullopt;
  const StateVector x = corrected_since(newest, cumulative_correction_);
  return to_map(pose_of(integrate_step(x, last_input_, last_input_, last_input_, ahead_s, gravity_m_s2_)));
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
  if (const auto& noise = imu_noise_.noise()) {
    s.measured_gyro_step_std_rad_s = noise->gyro_step_std_rad_s(config_.step_s).maxCoeff();
    s.measured_accel_step_std_m_s2 = noise->accel_step_std_m_s2(config_.step_s).maxCoeff();
    s.imu_rate_hz = noise->sample_period_s > 0.0 ? 1.0 / noise->sample_period_s : 0.0;
  }
  if (initialized())
    s.up_map = map_from_level() * level_from_world(ekf_.state()).transpose() * Eigen::Vector3d::UnitZ();
  return s;
}

}  // namespace farlio::fusion
