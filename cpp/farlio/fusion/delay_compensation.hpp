#pragma once
// Delay compensation (paper eq. 10, after Larsen et al.) and upsampling of LiDAR results.
//
// A measurement z_s of the state at stamp s that arrives at step k is shifted to k:
//   z_k = z_s + h(x_{k|k-1}) - h(x_s),
// with x_s interpolated from the state history, so its residual z_k - h(x_{k|k-1}) is the
// innovation the measurement had at its own stamp, z_s - h(x_s).
//
// Upsampling: the measurement is not fused once but in N injections, one per EKF step, each with
// covariance N R. For a static linear system, N updates with N R carry exactly the information
// of one update with R (N (N R)^-1 = R^-1), so the correction is spread over N cycles without
// counting the measurement more than once. Each injection's residual is the remaining innovation:
// the shifted innovation minus what every EKF correction since its arrival already changed in
// h(x) (see note_correction). (The reference implementation re-injects the same measurement
// every step with a covariance inflated by 1 + 10 d and the unreduced innovation: it counts
// the measurement about ten times.)
// Without delay compensation, each injection's residual is z_s - h(x) at the injection step,
// i.e. the measurement is treated as if taken now.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farlio/fusion/kinematic_ekf.hpp"
#include "farlio/fusion/state_history.hpp"

namespace farlio::fusion {

/// eq. 10: the measurement z_s of x_s moved to the state x_now.
Eigen::VectorXd shifted_measurement(MeasurementKind kind, const Eigen::VectorXd& z_s, const StateVector& x_s,
                                    const StateVector& x_now);

/// The residual at arrival of a measurement for stamp_ns: with compensation the shifted
/// innovation (eq. 10), without it z_s - h(x_now). Empty with a reason if the stamp is older than
/// the history (a stamp newer than the history is taken as current: no delay).
/// With compensation, x_s is the history state moved by the corrections applied after s
/// (current_correction - its cumulative correction): the estimate of the past state given all
/// updates so far, as in Larsen's method, so that an update already applied after s (e.g. the
/// last injections of the previous LiDAR result) is not applied again through this innovation.
struct ArrivalResidual {
  std::optional<Eigen::VectorXd> residual;
  std::string rejection_reason;
};
ArrivalResidual arrival_residual(MeasurementKind kind, const Eigen::VectorXd& z_s, std::int64_t stamp_ns,
                                 const StateHistory& history, const StateVector& x_now,
                                 const StateVector& current_correction, bool compensate);

/// Measurements accepted at arrival and fused over the following steps.
class SpreadMeasurementQueue {
 public:
  explicit SpreadMeasurementQueue(bool delay_compensation) : compensate_(delay_compensation) {}

  /// Queues a measurement: residual = its arrival residual, R its covariance, injections = N >= 1.
  void add(MeasurementKind kind, const Eigen::VectorXd& z_s, const Eigen::VectorXd& residual, const Eigen::MatrixXd& R,
           int injections);
  /// Fuses one injection of every queued measurement (call once per EKF step, after the
  /// prediction); returns how many injections were applied.
  int inject(KinematicEkf& ekf);
  /// Every EKF correction (by these injections or any other update) moves the whole recent
  /// trajectory, x_s included: it is subtracted, in measurement space, from the remaining
  /// innovation of every queued measurement, so that no correction is applied twice.
  void note_correction(const StateVector& before, const StateVector& after);
  [[nodiscard]] std::size_t size() const { return pending_.size(); }
  void clear() { pending_.clear(); }

 private:
  struct Pending {
    MeasurementKind kind;
    Eigen::VectorXd z_s;
    Eigen::VectorXd remaining_innovation;
    Eigen::MatrixXd R;
    int injections_total;
    int injections_left;
  };
  bool compensate_;
  std::vector<Pending> pending_;
};

}  // namespace farlio::fusion
