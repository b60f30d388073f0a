#include "farlio/fusion/imu_gate.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

#include "farlio/fusion/axis_median.hpp"

namespace farlio::fusion {
namespace {

/// The per-axis median of one vector field of the samples.
Eigen::Vector3d median(const std::deque<ImuSample>& samples, Vec3d ImuSample::*field) {
  return axis_median(samples, [field](const ImuSample& s) { return s.*field; });
}

std::string describe(const char* what, const Eigen::Vector3d& v, const char* unit) {
  std::ostringstream os;
  os << what << " (" << v.x() << ", " << v.y() << ", " << v.z() << ") " << unit;
  return os.str();
}

}  // namespace

ImuGate::ImuGate(const FusionConfig& config)
    : max_accel_m_s2_(config.imu_gate.max_accel_m_s2),
      max_gyro_rad_s_(config.imu_gate.max_gyro_rad_s),
      spike_accel_m_s2_(config.imu_gate.spike_accel_m_s2),
      spike_gyro_rad_s_(config.imu_gate.spike_gyro_rad_s),
      window_(static_cast<std::size_t>(std::max(0, config.imu_gate.spike_window_samples))) {}

std::string ImuGate::check(const ImuSample& sample, double accel_scale) {
  ImuSample si = sample;
  si.accel_m_s2 *= accel_scale;
  if (!si.accel_m_s2.allFinite() || !si.gyro_rad_s.allFinite()) {
    return describe("non-finite reading: accel", sample.accel_m_s2, "") + describe(", gyro", sample.gyro_rad_s, "");
  }
  if (si.accel_m_s2.norm() > max_accel_m_s2_) {
    return describe("accelerometer", si.accel_m_s2, "m/s^2") + " is over fusion.imu_gate.max_accel_m_s2";
  }
  if (si.gyro_rad_s.norm() > max_gyro_rad_s_) {
    return describe("gyro", si.gyro_rad_s, "rad/s") + " is over fusion.imu_gate.max_gyro_rad_s";
  }
  std::string why;
  if (window_ > 0 && recent_.size() >= window_) {
    const Eigen::Vector3d da = (si.accel_m_s2 - median(recent_, &ImuSample::accel_m_s2)).cwiseAbs();
    const Eigen::Vector3d dw = (si.gyro_rad_s - median(recent_, &ImuSample::gyro_rad_s)).cwiseAbs();
    if (da.maxCoeff() > spike_accel_m_s2_) {
      why = describe("accelerometer spike", si.accel_m_s2, "m/s^2") + ": off the recent median by more than " +
            "fusion.imu_gate.spike_accel_m_s2";
    } else if (dw.maxCoeff() > spike_gyro_rad_s_) {
      why = describe("gyro spike", si.gyro_rad_s, "rad/s") + ": off the recent median by more than " +
            "fusion.imu_gate.spike_gyro_rad_s";
    }
  }
  if (window_ > 0) {
    recent_.push_back(si);
    if (recent_.size() > window_) recent_.pop_front();
  }
  return why;
}

}  // namespace farlio::fusion
