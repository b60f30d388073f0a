#include "farlio/pipeline/fusion_driver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/time.hpp"
#include "farlio/deskew/motion_fit.hpp"
#include "farlio/fusion/euler.hpp"
#include "farlio/fusion/lidar_measurement.hpp"

namespace farlio::pipeline {
namespace {

// Poses sampled over a scan for the motion regression.
constexpr int kMotionSamples = 11;
/// While the gyro's unit is undecided, the gyro turns the guess before the filter only when it
/// turned no more than this many times as far as the LiDAR between the last two scans (the
/// midpoint between rad/s and deg/s, sqrt(180/pi)), give or take this much (rotations of the
/// order of the LiDAR's noise, which a deg/s gyro's noise also reaches at rest).
constexpr double kRotationAgreementRatio = 7.57;
constexpr double kRotationAgreementFloor_rad = 0.01;
/// ... and the gyro turns the filter's guess of a turning scan once both it and the LiDAR turned at
/// least this far over an interval (a degenerate scan's rotation errs by up to 0.023 rad: the Avia
/// facing a wall) and within this ratio of each other (a deg/s gyro reads 57 times the turn).
constexpr double kTurnConfirmation_rad = 0.05;
constexpr double kTurnConfirmationRatio = 2.0;
/// A gyro whose unit is not decided after this much time comparing it with the LiDAR gets a warning.
constexpr double kUndecidedGyroWarning_s = 10.0;
/// Degenerate scans that have kept the filter from starting for this long get a warning.
constexpr double kDegenerateStartWarning_s = 2.0;
/// A scan stands (FusionDriver::scan_stands) when the IMU's mean over its interval is within the rest
/// bounds widened by this many stds of that mean's noise.
constexpr double kRestNoiseSigmas = 3.0;
/// Warnings kept between two take_warnings calls; later ones are left out (a last one says so).
constexpr std::size_t kMaxPendingWarnings = 100;

std::optional<deskew::ScanMotion> motion_from_fusion(const fusion::SensorFusion& fusion, const Scan& scan,
                                                     const SE3& end_pose, const SE3& T_imu_lidar) {
  if (!scan.has_time() || scan.duration_s() <= 0.0) return std::nullopt;
  std::vector<std::pair<double, SE3>> samples;
  for (int i = 0; i < kMotionSamples; ++i) {
    const double tau = scan.duration_s() * i / (kMotionSamples - 1);
    const auto body = fusion.pose_at(scan.start_stamp_ns + seconds_to_ns(tau));
    if (body) samples.emplace_back(tau, *body * T_imu_lidar);
  }
  if (samples.size() < 2) return std::nullopt;
  return deskew::fit_scan_motion(samples, end_pose);
}

/// The gyro's rotation over the scan as a line in the undistortion's tangent space (LiDAR frame),
/// before the filter runs: offset and rate of the least-squares line through the integrated gyro
/// at kMotionSamples instants, as motion_from_fusion fits the fusion's poses (a line through the
/// scan's end points alone errs more where the rotation accelerates: a walker looking around).
struct RotationLine {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();
};
std::optional<RotationLine> gyro_rotation_line(const fusion::SensorFusion& fusion, const Scan& scan,
                                               const Mat3d& R_il) {
  if (!scan.has_time() || scan.duration_s() <= 0.0) return std::nullopt;
  std::vector<std::pair<double, SE3>> samples{{0.0, SE3()}};
  Mat3d body = Mat3d::Identity();  // the gyro's rotation since the scan's start, one instant to the next
  std::int64_t previous_ns = scan.start_stamp_ns;
  for (int i = 1; i < kMotionSamples; ++i) {
    const double tau = scan.duration_s() * i / (kMotionSamples - 1);
    const std::int64_t stamp_ns = scan.start_stamp_ns + seconds_to_ns(tau);
    const auto step = fusion.imu_rotation(previous_ns, stamp_ns);
    if (!step) return std::nullopt;
    body = body * *step;
    previous_ns = stamp_ns;
    samples.emplace_back(tau, SE3(R_il.transpose() * body * R_il, Eigen::Vector3d::Zero()));
  }
  const deskew::ScanMotion line = deskew::fit_scan_motion(samples, samples.back().second);
  return RotationLine{line.offset.tail<3>().cast<double>(), line.rate.tail<3>().cast<double>()};
}

/// A mean specific force within max_accel_deviation of gravity and a mean rate within max_gyro: at
/// rest or at a constant velocity.
bool reads_gravity_alone(const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s, double gravity_m_s2,
                         double max_accel_deviation_m_s2, double max_gyro_rad_s) {
  return std::abs(accel_m_s2.norm() - gravity_m_s2) <= max_accel_deviation_m_s2 && gyro_rad_s.norm() <= max_gyro_rad_s;
}

bool in_gravity_window(const ImuSample& first, const ImuSample& s) {
  return s.stamp_ns - first.stamp_ns <= seconds_to_ns(kGravityAlignmentWindow_s);
}

}  // namespace

void register_from_prior(ScanPipeline& pipeline, const Scan& scan, const ScanPrior& prior, const SE3& T_lidar_imu,
                         OdometryFrame& out) {
  out.guess_from_fusion = prior.guess.has_value() && prior.fused;
  out.guess_turned_by_gyro = prior.guess.has_value();  // every guess the driver gives turns with the gyro
  out.scan = pipeline.process(scan, prior.guess, prior.motion, prior.fused, prior.confirmed);
  out.processed = true;
  out.body_pose = out.scan.pose * T_lidar_imu;
}

SE3 gravity_aligned_start(const std::vector<ImuSample>& imu, std::int64_t until_ns, double gravity_m_s2,
                          double max_gyro_rad_s) {
  if (imu.empty() || imu.front().stamp_ns > until_ns) return SE3();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), mean_gyro = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : imu) {
    if (s.stamp_ns > until_ns || !in_gravity_window(imu.front(), s)) break;
    mean += s.accel_m_s2;
    mean_gyro += s.gyro_rad_s;
    ++n;
  }
  mean /= n;
  mean_gyro /= n;
  if (mean.norm() <= 0.0 || !mean.allFinite()) return SE3();
  // accelerating or turning, the specific force is not gravity: the body's own attitude is as good
  // a guess (a car's roll and pitch are small), and the filter finds gravity in motion
  if (!reads_gravity_alone(mean, mean_gyro, gravity_m_s2, kLevelledStartMaxAccelDeviation_m_s2, max_gyro_rad_s))
    return SE3();
  const double roll = std::atan2(mean.y(), mean.z());
  const double pitch = std::atan2(-mean.x(), std::hypot(mean.y(), mean.z()));
  const Eigen::Quaterniond q =
      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return SE3(q, Eigen::Vector3d::Zero());
}

std::string drop_reason(const FrameResult& result, bool map_started) {
  if (!result.failure.empty()) {
    return result.map_restarted ? result.failure + "; the map restarted from this scan" : result.failure;
  }
  if (!result.registered && map_started) return "nothing to register against";
  return {};
}

FusionDriver::FusionDriver(const Config& config, double gravity_m_s2, const SE3& T_imu_lidar, bool inertial)
    : registration_config_(validated(config).registration),
      fusion_config_(config.fusion),
      gravity_m_s2_(gravity_m_s2),
      max_bridged_gap_ns_(seconds_to_ns(config.fusion.imu_gate.max_bridged_gap_s)),
      T_imu_lidar_(T_imu_lidar),
      gyro_unit_(config.fusion.units.gyro_detection, config.fusion.units.gyro_min_rotation_rad,
                 config.fusion.standstill.max_gyro_rad_s) {
  validate_gravity(gravity_m_s2, "gravity_m_s2");
  if (inertial) fusion_.emplace(fusion_config_, gravity_m_s2_);
}

void FusionDriver::warn(std::string message) {
  if (warnings_.size() < kMaxPendingWarnings) {
    warnings_.push_back(std::move(message));
  } else if (warnings_.size() == kMaxPendingWarnings) {
    warnings_.emplace_back("more warnings were left out");
  }
}

void FusionDriver::emit_step(Samples& out) {
  fusion_->advance_to(next_output_ns_);
  const fusion::BodyEstimate e = fusion_->estimate();
  // the filter's grid starts at its initialisation: an output instant before its first step
  // would repeat the initial state's stamp
  if (e.valid && (!last_output_ns_ || e.stamp_ns > *last_output_ns_)) {
    out.push_back({e.stamp_ns, e.pose, e.velocity_body_m_s});
    last_output_ns_ = e.stamp_ns;
  }
  next_output_ns_ += fusion_->step_ns();
}

ImuSample FusionDriver::in_si_units(const ImuSample& sample) const {
  ImuSample s = sample;
  s.gyro_rad_s *= gyro_unit_.scale();
  return s;
}

void FusionDriver::restart_fusion(const std::deque<ImuSample>& samples, bool regrid) {
  // the map frame is the same: its gravity carries over; the window too, unless the IMU clock
  // jumped (its results lie on the old clock)
  fusion::MapFrameKnowledge known = fusion_ ? fusion_->map_frame_knowledge() : fusion::MapFrameKnowledge{};
  if (regrid) known.window.clear();
  fusion_.emplace(fusion_config_, gravity_m_s2_, std::move(known));
  if (regrid) {
    next_output_ns_ = 0;
    last_output_ns_.reset();
  }
  for (const ImuSample& s : samples) fusion_->add_imu(in_si_units(s));
  if (!samples.empty()) fusion_->advance_to(samples.back().stamp_ns);
}

double FusionDriver::after_newest_imu_s(std::int64_t stamp_ns) const {
  // in seconds: the difference of two arbitrary int64 stamps may not fit an int64
  return newest_imu_ns_ ? ns_to_seconds(stamp_ns) - ns_to_seconds(*newest_imu_ns_) : 0.0;
}

bool FusionDriver::admit(const ImuSample& sample) {
  if (sample.stamp_ns < newest_imu_ns_.value_or(sample.stamp_ns)) {
    fusion_->add_imu(sample);  // older than the newest: the fusion drops and counts it
    return false;
  }
  newest_imu_ns_ = sample.stamp_ns;
  if (first_accels_.size() < static_cast<std::size_t>(fusion_config_.units.accel_samples)) {
    first_accels_.push_back(sample.accel_m_s2);
    if (first_accels_.size() == static_cast<std::size_t>(fusion_config_.units.accel_samples)) {
      if (std::string silent = fusion::silent_accelerometer(first_accels_); !silent.empty()) {
        warn(std::move(silent));
        fusion_.reset();
        return false;
      }
    }
  }
  return true;
}

void FusionDriver::jump_clock(const ImuSample& sample) {
  warn("IMU stamp " + seconds_text(ns_to_seconds(sample.stamp_ns)) + " s jumps by " +
       seconds_text(after_newest_imu_s(sample.stamp_ns)) + " s from the newest (" +
       seconds_text(ns_to_seconds(*newest_imu_ns_)) + " s), beyond fusion.imu_gate.max_bridged_gap_s (" +
       seconds_text(fusion_config_.imu_gate.max_bridged_gap_s) +
       " s), and the samples after it follow it: the fusion is reset and starts again from the next LiDAR results");
  recent_imu_.clear();
  pending_.clear();  // stamped on the old clock
  pending_rotations_.clear();
  gyro_unit_.forget_samples();
  restart_fusion(recent_imu_, /*regrid=*/true);
  clock_ns_ = sample.stamp_ns;
  newest_imu_ns_.reset();
}

void FusionDriver::add_imu(const ImuSample& sample, Samples& out) {
  if (!fusion_) return;
  // A sample beyond fusion.imu_gate.max_bridged_gap_s from the newest waits for the next one: when that
  // follows it, the clock jumped (the fusion starts again there); when it follows the newest, the
  // held sample alone was stamped wrong and is dropped (one bad stamp costs one sample).
  if (held_jump_) {
    const ImuSample held = *std::exchange(held_jump_, std::nullopt);
    const double from_held_s = ns_to_seconds(sample.stamp_ns) - ns_to_seconds(held.stamp_ns);
    if (from_held_s >= 0.0 && from_held_s <= fusion_config_.imu_gate.max_bridged_gap_s) {
      jump_clock(held);
      feed_imu(held, out);
    } else {
      warn("IMU sample stamped " + seconds_text(ns_to_seconds(held.stamp_ns)) + " s jumps by " +
           seconds_text(after_newest_imu_s(held.stamp_ns)) + " s from the samples around it: dropped");
    }
  }
  if (!fusion_) return;
  if (std::abs(after_newest_imu_s(sample.stamp_ns)) > fusion_config_.imu_gate.max_bridged_gap_s) {
    held_jump_ = sample;
    return;
  }
  feed_imu(sample, out);
}

void FusionDriver::feed_imu(const ImuSample& sample, Samples& out) {
  if (!fusion_ || !admit(sample)) return;
  if (!gyro_unit_.decided()) {
    gyro_unit_.add_imu(sample);
    recent_imu_.push_back(sample);
    while (recent_imu_.front().stamp_ns < sample.stamp_ns - seconds_to_ns(fusion_config_.history_s)) {
      recent_imu_.pop_front();
    }
  }
  const ImuSample si = in_si_units(sample);
  if (startup_imu_.empty() || in_gravity_window(startup_imu_.front(), si)) startup_imu_.push_back(si);
  // the output grid: whole multiples of the step, the first after the first sample
  const std::int64_t step_ns = fusion_->step_ns();
  if (next_output_ns_ == 0) next_output_ns_ = (sample.stamp_ns / step_ns + 1) * step_ns;
  fusion_->add_imu(si);
  advance_to(sample.stamp_ns, out);
  compare_covered_rotations();
}

bool FusionDriver::beyond_bridged_gap(std::int64_t stamp_ns) const {
  return newest_imu_ns_ && after_newest_imu_s(stamp_ns) > fusion_config_.imu_gate.max_bridged_gap_s;
}

std::int64_t FusionDriver::fusion_horizon(std::int64_t stamp_ns) const {
  if (!newest_imu_ns_ || stamp_ns <= *newest_imu_ns_) return stamp_ns;
  if (after_newest_imu_s(stamp_ns) <= fusion_config_.imu_gate.gap_limit_s) return *newest_imu_ns_;  // next one due
  // a gap: the fusion predicts with its last input, at most the bridged gap beyond the newest sample
  if (*newest_imu_ns_ >= std::numeric_limits<std::int64_t>::max() - max_bridged_gap_ns_) return stamp_ns;
  return std::min(stamp_ns, *newest_imu_ns_ + max_bridged_gap_ns_);
}

void FusionDriver::advance_to(std::int64_t stamp_ns, Samples& out) {
  if (!fusion_) return;
  clock_ns_ = std::max(clock_ns_, stamp_ns);
  const std::int64_t horizon_ns = fusion_horizon(stamp_ns);
  while (next_output_ns_ != 0 && next_output_ns_ <= horizon_ns) {
    const std::int64_t instant_ns = next_output_ns_;
    emit_step(out);
    fuse_covered(instant_ns);
  }
  fusion_->advance_to(horizon_ns);
  fuse_covered(horizon_ns);
}

void FusionDriver::fuse_when_covered(PendingResult result) {
  pending_.push_back(std::move(result));
  fuse_covered(fusion_horizon(clock_ns_));
}

void FusionDriver::fuse_covered(std::int64_t horizon_ns) {
  // an initialised filter takes a result once it has stepped past its stamp (delay compensation)
  while (fusion_ && !pending_.empty() && pending_.front().stamp_ns <= horizon_ns &&
         (!fusion_->initialized() || pending_.front().stamp_ns <= fusion_->time_ns())) {
    const PendingResult r = std::move(pending_.front());
    pending_.pop_front();
    fusion_->add_lidar(r.stamp_ns, r.body_pose, r.velocity_m_s, r.has_velocity, r.covariance, r.velocity_covariance,
                       r.rest_jitter);
  }
}

void FusionDriver::apply_gyro_unit() {
  switch (gyro_unit_.unit()) {
    case fusion::GyroUnit::kDegreesPerSecond:
      warn(gyro_unit_.message());
      restart_fusion(recent_imu_, /*regrid=*/false);
      fusion_->advance_to(fusion_horizon(clock_ns_));
      break;
    case fusion::GyroUnit::kStuck:
      warn(gyro_unit_.message());
      fusion_.reset();
      break;
    default: break;
  }
  recent_imu_.clear();
}

SE3 FusionDriver::start_pose(std::int64_t first_scan_end_ns, const std::optional<SE3>& requested) const {
  if (!fusion_) return requested.value_or(SE3());
  const SE3 level =
      gravity_aligned_start(startup_imu_, first_scan_end_ns, gravity_m_s2_, fusion_config_.standstill.max_gyro_rad_s);
  if (!requested) return level;
  Eigen::Vector3d rpy = fusion::euler_from_rotation(level.rotation());
  rpy.z() = fusion::euler_from_rotation(requested->rotation()).z();
  return SE3(fusion::rotation_from_euler(rpy), requested->translation());
}

ScanPrior FusionDriver::prior(const Scan& scan, const registration::Vec6d& lidar_twist, bool twist_measured) {
  ScanPrior prior;
  if (!fusion_) return prior;
  if (fusion_->initialized()) {
    // while the gyro's unit is undecided, a scan during which it turns is registered by the LiDAR
    // alone (a deg/s gyro would turn the guess 57 times too far, and the registration would
    // follow), unless a clear turn confirmed the gyro (compare_gyro_turn: a narrow field of view
    // facing a wall as the body looks around; its scans do not constrain every direction, the unit
    // is not judged on them, and the LiDAR alone slides along the wall)
    if (gyro_unit_.turning(scan.start_stamp_ns, scan.end_stamp_ns) && !gyro_turn_confirmed_) return prior;
    if (const auto body = fusion_->pose_at(scan.end_stamp_ns)) {
      prior.guess = *body * T_imu_lidar_;
      prior.motion = motion_from_fusion(*fusion_, scan, *prior.guess, T_imu_lidar_);
      if (prior.motion && twist_measured) blend_rotation_rate(scan, lidar_twist, *prior.motion);
      prior.fused = true;
      prior.confirmed = gyro_unit_.decided() && gyro_unit_.unit() != fusion::GyroUnit::kStuck;
    }
    return prior;
  }
  // before the filter: the constant-velocity translation, turned as the gyro turned (while its unit
  // is undecided, as long as it turned as the LiDAR did between the last two scans)
  if (!(gyro_unit_.decided() || gyro_follows_lidar_) || !last_body_ || scan.end_stamp_ns <= last_body_->stamp_ns)
    return prior;
  const auto since_last = fusion_->imu_rotation(last_body_->stamp_ns, scan.end_stamp_ns);
  const auto during_scan = fusion_->imu_rotation(scan.start_stamp_ns, scan.end_stamp_ns);
  if (!since_last || !during_scan) return prior;
  const Mat3d R_il = T_imu_lidar_.rotation();
  const auto lidar_rotation_vector = [&](const Mat3d& body_rotation) {
    return so3_log(R_il.transpose() * body_rotation * R_il);
  };
  registration::Vec6d step;
  step << lidar_twist.head<3>() * ns_to_seconds(scan.end_stamp_ns - last_body_->stamp_ns),
      lidar_rotation_vector(*since_last);
  prior.guess = last_body_->pose * T_imu_lidar_ * SE3::exp(step);
  if (scan.has_time() && scan.duration_s() > 0.0) {
    registration::Vec6d twist;
    twist << lidar_twist.head<3>(), lidar_rotation_vector(*during_scan) / scan.duration_s();
    prior.motion = deskew::ScanMotion::constant_twist(twist.cast<float>(), static_cast<float>(scan.duration_s()));
    // the gyro's chord over the scan stays where the blend cannot fit the gyro's line (an IMU gap)
    if (twist_measured) blend_rotation_rate(scan, lidar_twist, *prior.motion);
  }
  return prior;
}

void FusionDriver::blend_rotation_rate(const Scan& scan, const registration::Vec6d& lidar_twist,
                                       deskew::ScanMotion& motion) {
  // the gyro's side: the fusion's motion over the scan once the filter runs; before, the gyro's line
  RotationLine gyro{motion.offset.tail<3>().cast<double>(), motion.rate.tail<3>().cast<double>()};
  if (!fusion_->initialized()) {
    const auto line = gyro_rotation_line(*fusion_, scan, T_imu_lidar_.rotation());
    if (!line) return;
    gyro = *line;
  }
  // the gyro's error over the scan in the LiDAR frame (per axis: the diagonal of R^T S R)
  std::optional<Eigen::Vector3d> gyro_variance;
  if (const auto& noise = fusion_->measured_imu_noise()) {
    const Mat3d R_il = T_imu_lidar_.rotation();
    const Eigen::Vector3d body = noise->gyro_step_std_rad_s(scan.duration_s()).cwiseAbs2();
    gyro_variance = (R_il.transpose() * body.asDiagonal() * R_il).diagonal();
  }
  const Eigen::Vector3d twist_rate = lidar_twist.tail<3>();
  const Eigen::Vector3d rate = rotation_rate_blend_.blend(gyro.rate, twist_rate, gyro_variance, scan.end_stamp_ns);
  const Eigen::Vector3d w = rotation_rate_blend_.gyro_weight();
  // the lines xi(tau) = offset + rate tau blended as a whole: the constant twist's offset is -D w
  const Eigen::Vector3d offset =
      w.cwiseProduct(gyro.offset) + (Eigen::Vector3d::Ones() - w).cwiseProduct(-scan.duration_s() * twist_rate);
  motion.rate.tail<3>() = rate.cast<float>();
  motion.offset.tail<3>() = offset.cast<float>();
  gyro_weight_sum_ += w;
  ++blended_scans_;
}

bool FusionDriver::held_at_prior(const OdometryFrame& frame) const {
  return registration_config_.hold_degenerate_directions && frame.guess_from_fusion && frame.degeneracy &&
         frame.degeneracy->degenerate();
}

std::optional<Mat6d> FusionDriver::registration_covariance(OdometryFrame& frame) const {
  if (!frame.scan.registered || frame.scan.registration.system.inliers <= 0) return std::nullopt;
  Mat6d covariance = registration::covariance_from_information(registration::body_information(
      frame.scan.registration.system.H, T_imu_lidar_, registration_config_.covariance_scale));
  frame.degeneracy = registration::analyze_degeneracy(
      covariance, static_cast<double>(frame.scan.registration.system.inliers), registration_config_);
  if (held_at_prior(frame)) {
    // the registration held its degenerate directions at the fusion's prior. A degenerate rotation
    // axis says nothing; along a degenerate translation the fusion gets the scan's own step
    // (measured_body_pose) at its covariance
    covariance = registration::release_degenerate_rotations(covariance, *frame.degeneracy);
  }
  return covariance;
}

SE3 FusionDriver::measured_body_pose(const OdometryFrame& frame) const {
  if (!held_at_prior(frame) || frame.degeneracy->degenerate_translations == 0) return frame.body_pose;
  // the registration's step along a degenerate translation, the pose held there returned plus
  // what the scan's weak constraint adds: on a sparse LiDAR at speed (16-32 beams on a
  // racetrack) it is what keeps the IMU's drift along the track in check
  Vec6d xi = Vec6d::Zero();
  xi.head<3>() = registration::degenerate_translation_step(frame.scan.registration.system, registration_config_.damping,
                                                           T_imu_lidar_, *frame.degeneracy);
  return frame.body_pose * SE3::exp(xi);
}

void FusionDriver::compare_gyro_unit(std::int64_t stamp_ns, const OdometryFrame& frame) {
  // the gyro's unit is judged against scans that constrain every direction: the rotations of a
  // degenerate scan (a narrow field of view sliding along the track) carry errors that add up to a
  // turn the gyro did not make. Whether the gyro may turn a turning scan's guess is judged on every
  // scan (compare_gyro_turn): a degenerate one still tells a turn from one 57 times as far.
  const bool constrained = !frame.degeneracy || !frame.degeneracy->degenerate();
  if (!frame.drop_reason.empty() || !fusion_ || !has_imu() || gyro_unit_.decided() || !last_body_ ||
      stamp_ns <= last_body_->stamp_ns || beyond_bridged_gap(stamp_ns))
    return;
  pending_rotations_.push_back({last_body_->stamp_ns, stamp_ns,
                                so3_log((last_body_->pose.inverse() * frame.body_pose).rotation()), constrained,
                                !frame.guess_turned_by_gyro});
  compare_covered_rotations();
}

void FusionDriver::compare_covered_rotations() {
  // the gyro's rotation over an interval once the IMU covers it (a 10 Hz IMU's next sample may come
  // after the scan's result)
  while (fusion_ && !gyro_unit_.decided() && !pending_rotations_.empty() && newest_imu_ns_ &&
         pending_rotations_.front().end_ns <= *newest_imu_ns_) {
    const PendingRotation r = pending_rotations_.front();
    pending_rotations_.pop_front();
    const auto gyro_rotation = fusion_->imu_rotation(r.start_ns, r.end_ns);
    compare_gyro_turn(gyro_rotation, r);
    if (!r.constrained) continue;
    gyro_unit_.add_lidar_rotation(r.start_ns, r.end_ns, r.lidar_rotation);
    if (gyro_unit_.decided()) apply_gyro_unit();
    warn_undecided_gyro(r.end_ns);
  }
  if (gyro_unit_.decided()) pending_rotations_.clear();
}

void FusionDriver::compare_gyro_turn(const std::optional<Eigen::Matrix3d>& gyro_rotation, const PendingRotation& r) {
  // gyro_follows_lidar_ (the guess before the filter) is judged on scans that constrain every
  // direction: the gyro turned no more than kRotationAgreementRatio times as far as the LiDAR, give
  // or take the floor. gyro_turn_confirmed_ (the filter's guess of a turning scan) is judged on
  // every scan: refuted the same way, confirmed only by a clear turn of both that the LiDAR found
  // from a guess the gyro did not turn (a degenerate scan registered from the gyro's guess follows
  // it: the Avia facing a wall with a deg/s gyro confirmed it that way and ran 128 m off)
  const double gyro_rad = gyro_rotation ? so3_log(*gyro_rotation).norm() : 0.0;
  const double lidar_rad = r.lidar_rotation.norm();
  const bool within = gyro_rotation && gyro_rad <= kRotationAgreementRatio * lidar_rad + kRotationAgreementFloor_rad;
  if (r.constrained) gyro_follows_lidar_ = within;
  const bool clear_turn = std::min(gyro_rad, lidar_rad) >= kTurnConfirmation_rad &&
                          std::max(gyro_rad, lidar_rad) <= kTurnConfirmationRatio * std::min(gyro_rad, lidar_rad);
  if (!within)
    gyro_turn_confirmed_ = false;
  else if (clear_turn && r.lidar_own_guess)
    gyro_turn_confirmed_ = true;
}

void FusionDriver::warn_undecided_gyro(std::int64_t stamp_ns) {
  if (!first_compared_ns_) first_compared_ns_ = stamp_ns;
  if (!gyro_unit_.decided() && !warned_undecided_gyro_ &&
      ns_to_seconds(stamp_ns - *first_compared_ns_) > kUndecidedGyroWarning_s) {
    warn("the gyro's unit (rad/s or deg/s) is not decided after " + seconds_text(kUndecidedGyroWarning_s) +
         " s of scans: the LiDAR has hardly turned. Until it turns, a gyro in deg/s would turn the fused "
         "orientation 57 times too far (fusion.units.gyro_detection)");
    warned_undecided_gyro_ = true;
  }
}

bool FusionDriver::scan_stands(std::int64_t stamp_ns, const SE3& measured, const fusion::RestJitter& own_stds) const {
  // the scan moved within its own stds and the IMU read gravity alone, unturned: at rest, or (a
  // degenerate scan) at a constant velocity along the direction it does not constrain
  if (!last_body_ || stamp_ns <= last_body_->stamp_ns) return false;
  const double dt_s = ns_to_seconds(stamp_ns - last_body_->stamp_ns);
  if (!fusion::moved_within_rest(last_body_->pose.inverse() * measured, dt_s, fusion_config_, own_stds)) return false;
  const auto mean = fusion_->imu_mean(last_body_->stamp_ns, stamp_ns);
  if (!mean) return false;
  double accel_std = 0.0, gyro_std = 0.0;  // of the mean over the interval, once measured
  if (const auto& noise = fusion_->measured_imu_noise()) {
    accel_std = noise->accel_step_std_m_s2(dt_s).norm();
    gyro_std = noise->gyro_step_std_rad_s(dt_s).norm();
  }
  return reads_gravity_alone(mean->accel_m_s2, mean->gyro_rad_s, gravity_m_s2_,
                             kLevelledStartMaxAccelDeviation_m_s2 + kRestNoiseSigmas * accel_std,
                             fusion_config_.standstill.max_gyro_rad_s + kRestNoiseSigmas * gyro_std);
}

bool FusionDriver::imu_within_configured_noise() const {
  const auto& noise = fusion_->measured_imu_noise();
  const double step_s = ns_to_seconds(fusion_->step_ns());
  return noise && noise->gyro_step_std_rad_s(step_s).maxCoeff() <= fusion_config_.gyro_input_std_rad_s &&
         noise->accel_step_std_m_s2(step_s).maxCoeff() <= fusion_config_.accel_input_std_m_s2;
}

void FusionDriver::hold_start_at_degenerate_scan(std::int64_t stamp_ns, const SE3& measured, OdometryFrame& frame,
                                                 fusion::RestJitter& rest_jitter) {
  if (!frame.drop_reason.empty() || !fusion_ || !has_imu() || fusion_->initialized() || !frame.degeneracy) {
    rest_seen_by_constrained_scan_ = false;
    return;
  }
  // a degenerate scan standing enters the window once a scan that constrains every direction has
  // shown the body at rest, and no scan since has moved or felt more than rest (coasting along
  // parallel walls, every scan degenerate, reads as rest to every sensor on board: held)
  const fusion::RestJitter own_stds{frame.degeneracy->translation_std_m.maxCoeff(),
                                    frame.degeneracy->rotation_std_rad.maxCoeff()};
  const bool stands = scan_stands(stamp_ns, measured, own_stds);
  if (frame.degeneracy->degenerate_translations == 0) {
    rest_seen_by_constrained_scan_ = stands;
    return;
  }
  if (!stands) rest_seen_by_constrained_scan_ = false;
  // a filter started there carries the unconstrained direction on the accelerometer: only an IMU
  // measured within the filter's configured input noise (not a vibrating race car's) may start it
  if (rest_seen_by_constrained_scan_ && imu_within_configured_noise()) {
    rest_jitter = own_stds;  // the jitter scan_stands allowed
    return;
  }
  // a pose that stands still along a direction the scan does not constrain says nothing of the
  // velocity there (a sparse LiDAR at speed between parallel walls registers as standing): the
  // filter starts from a run of scans that constrain every direction
  fusion_->restart_window();
  frame.drop_reason = "not fused: the filter is not initialised from a scan with a degenerate direction";
  if (!first_degenerate_start_ns_) first_degenerate_start_ns_ = stamp_ns;
  if (!warned_degenerate_start_ && ns_to_seconds(stamp_ns - *first_degenerate_start_ns_) > kDegenerateStartWarning_s) {
    warn("the filter has not started after " + seconds_text(kDegenerateStartWarning_s) +
         " s of scans that do not constrain every direction (degenerate: a narrow field of view, a corridor, "
         "a sparse LiDAR at speed): the odometry is LiDAR-only, without the 100 Hz output, until the scans "
         "constrain every direction");
    warned_degenerate_start_ = true;
  }
}

void FusionDriver::link(const Scan& scan, OdometryFrame& frame) {
  frame.drop_reason = drop_reason(frame.scan, last_body_.has_value());
  if (fusion_ && (frame.scan.map_restarted || frame.scan.map_started_here)) fusion_->restart_window();
  const std::optional<Mat6d> covariance = registration_covariance(frame);
  const std::int64_t stamp_ns = scan.end_stamp_ns;
  const SE3 measured = measured_body_pose(frame);
  if (frame.drop_reason.empty() && fusion_ && !has_imu()) {
    frame.drop_reason = "not fused: no IMU sample yet (LiDAR-only until the first one arrives)";
    if (!warned_no_imu_) {
      warn("the scan ending at " + seconds_text(ns_to_seconds(stamp_ns)) +
           " s came before the first IMU sample: scans are registered LiDAR-only until the IMU starts");
      warned_no_imu_ = true;
    }
  }
  compare_gyro_unit(stamp_ns, frame);
  if (frame.drop_reason.empty() && fusion_ && has_imu() && !fusion_->initialized() &&
      ns_to_seconds(clock_ns_) - ns_to_seconds(stamp_ns) > fusion_config_.imu_gate.max_bridged_gap_s) {
    frame.drop_reason =
        "not fused: the scan ends " + seconds_text(ns_to_seconds(clock_ns_) - ns_to_seconds(stamp_ns)) +
        " s before the IMU clock, beyond fusion.imu_gate.max_bridged_gap_s (do the IMU and LiDAR clocks differ?)";
  }
  fusion::RestJitter rest_jitter;
  hold_start_at_degenerate_scan(stamp_ns, measured, frame, rest_jitter);
  if (frame.drop_reason.empty() && fusion_ && has_imu() && beyond_bridged_gap(stamp_ns)) {
    frame.drop_reason =
        "not fused: the scan ends " + seconds_text(after_newest_imu_s(stamp_ns)) +
        " s after the newest IMU sample, beyond fusion.imu_gate.max_bridged_gap_s (has the IMU stopped?)";
  }
  if (frame.drop_reason.empty() && fusion_ && has_imu()) {
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    std::optional<Eigen::Matrix3d> velocity_covariance;
    const bool has_velocity = last_body_.has_value() && stamp_ns > last_body_->stamp_ns;
    if (has_velocity) {  // eq. (6) on the body poses
      const double dt_s = ns_to_seconds(stamp_ns - last_body_->stamp_ns);
      velocity = velocity_from_poses(last_body_->pose, measured, dt_s);
      if (covariance && last_covariance_) {
        velocity_covariance =
            fusion::velocity_measurement_covariance(*covariance, *last_covariance_, dt_s, fusion_->config());
      }
    }
    fuse_when_covered({stamp_ns, measured, velocity, has_velocity, covariance, velocity_covariance, rest_jitter});
    frame.fused = true;
  }
  last_body_ = StampedPose{scan.end_stamp_ns, measured};
  last_covariance_ = covariance;
}

std::optional<fusion::FusionStats> FusionDriver::stats() const {
  if (!fusion_) return std::nullopt;
  fusion::FusionStats s = fusion_->stats();
  if (blended_scans_ > 0) s.deskew_gyro_weight = gyro_weight_sum_ / static_cast<double>(blended_scans_);
  return s;
}

}  // namespace farlio::pipeline
