#pragma once
// The rotation rate that undistorts a scan, from its two estimates: the gyro's over the scan and
// the LiDAR's constant twist (the rate between the two previous scan poses). Their errors differ
// in kind. The gyro's is its white noise averaged over the scan, std N / sqrt(D) for a noise
// density N and a scan of D seconds, whatever the motion: 0.0031 rad/s for the simulator's
// racetrack IMU over a 50 ms scan, 0.013 rad/s for a vibrating race car's (3e-3 rad/s/sqrt(Hz)).
// The constant twist's is how far the rate changes from one scan interval to the next, whatever
// the IMU: about 0.01 rad/s in yaw on the racetrack, a few rad/s as a walker looks around.
//
// Per axis, w gyro + (1 - w) twist with w = s_t^2 / (s_t^2 + s_g^2) has the least expected error
// of any blend when the two errors are independent. s_g^2 comes from the IMU's noise measured on its
// samples (fusion/imu_noise.hpp); s_t^2 from the data: the running mean of (gyro - twist)^2 is
// s_t^2 + s_g^2. A disagreement beyond kChangeRatio times that running RMS is a change of motion the
// constant twist could not foresee (a sudden turn): that scan takes the gyro's rate. With a quiet IMU
// on a quick motion w is close to 1 (the gyro, as the paper undistorts); with a race car's noisy gyro
// the smooth axes lean on the twist (docs/fusion.md, "The undistortion's rotation").
#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace farlio::deskew {

class RotationRateBlend {
 public:
  /// The blended rate (rad/s, the frame of both inputs). `gyro_variance`: of gyro_rate's error per
  /// axis, nullopt while the IMU's noise is not yet measured (the gyro's rate is returned).
  /// stamp_ns: the scan's, for the running mean's memory.
  Eigen::Vector3d blend(const Eigen::Vector3d& gyro_rate, const Eigen::Vector3d& twist_rate,
                        const std::optional<Eigen::Vector3d>& gyro_variance, std::int64_t stamp_ns);
  /// The weight of the gyro's rate in the last blend, per axis (1 before the first).
  [[nodiscard]] const Eigen::Vector3d& gyro_weight() const { return gyro_weight_; }

  /// The running mean of (gyro - twist)^2 forgets with this time constant (s): about a hundred
  /// scans, whose mean is good to 15 %, and a few corners of a racetrack.
  static constexpr double kMemory_s = 5.0;
  /// A disagreement beyond this many running RMS takes the gyro's rate. A normal one exceeds 5 in
  /// 6e-7 of scans; at 3 (0.3 %) the rule took the gyro just when its noise was largest, and the
  /// blend of a noisy gyro on a smooth motion erred 50 % more (tests/cpp/test_rotation_rate_blend.cpp).
  static constexpr double kChangeRatio = 5.0;

 private:
  std::optional<Eigen::Vector3d> disagreement_variance_;  ///< running mean of (gyro - twist)^2
  Eigen::Vector3d gyro_weight_ = Eigen::Vector3d::Ones();
  std::int64_t last_stamp_ns_ = 0;
};

}  // namespace farlio::deskew
