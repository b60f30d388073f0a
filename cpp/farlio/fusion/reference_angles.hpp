#pragma once
// Roll/pitch reference angles (Tseng et al., Goblirsch et al.; paper eq. 9): gravity in the body
// frame from the kinematic equation, g_body = v_dot - a_m + omega x v, with v_dot the central
// difference of the EKF's body velocity. Then
//   pitch_ref = asin(clamp(g_body.x / g)),  roll_ref = asin(clamp(-g_body.y / (g cos pitch_ref))).
// Low-pass filter: every term (v_dot, a_m and omega x v) is averaged with the same symmetric
// Hann window of `taps` samples around one centre step, so the terms stay time-aligned and the
// filter has no phase lag about that centre; the result refers to the centre stamp, which lies
// (taps - 1) / 2 + 1 steps behind the newest sample (the caller fuses it as a delayed measurement).
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>

namespace farlio::fusion {

struct ReferenceAngles {
  std::int64_t stamp_ns = 0;  ///< the stamp the angles refer to (the window centre)
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  bool saturated = false;  ///< an asin argument hit the clamp (the angle is a lower bound)
};

/// Normalised symmetric Hann weights w_i = sin^2(pi (i + 1) / (taps + 1)), i = 0..taps-1.
Eigen::VectorXd hann_weights(int taps);

/// The angles from one (filtered) body-frame gravity vector; nullopt if not finite.
std::optional<ReferenceAngles> reference_angles_from_gravity(const Eigen::Vector3d& g_body_m_s2, double gravity_m_s2,
                                                             double max_sin);

class ReferenceAngleEstimator {
 public:
  ReferenceAngleEstimator(int taps, double gravity_m_s2, double max_sin);

  /// Adds one filter step (its stamp, the EKF body velocity and the bias-corrected input at that
  /// stamp); returns the angles of the window centre once the window is full.
  std::optional<ReferenceAngles> push(std::int64_t stamp_ns, const Eigen::Vector3d& v_body_m_s,
                                      const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s);
  void reset() { samples_.clear(); }

 private:
  struct Sample {
    std::int64_t stamp_ns;
    Eigen::Vector3d v, a, w;
  };
  Eigen::VectorXd weights_;
  double gravity_m_s2_;
  double max_sin_;
  std::deque<Sample> samples_;
};

}  // namespace farlio::fusion
