#include "farlio/fusion/delay_compensation.hpp"

#include <algorithm>

namespace farlio::fusion {

Eigen::VectorXd shifted_measurement(MeasurementKind kind, const Eigen::VectorXd& z_s, const StateVector& x_s,
                                    const StateVector& x_now) {
  // z_s + (h(x_now) - h(x_s)), the difference taken first so that angles wrap correctly.
  return z_s + measurement_difference(kind, measure(kind, x_now), measure(kind, x_s));
}

ArrivalResidual arrival_residual(MeasurementKind kind, const Eigen::VectorXd& z_s, std::int64_t stamp_ns,
                                 const StateHistory& history, const StateVector& x_now,
                                 const StateVector& current_correction, bool compensate) {
  ArrivalResidual out;
  if (history.empty() || stamp_ns < history.oldest().stamp_ns) {
    out.rejection_reason = "measurement stamp " + std::to_string(stamp_ns) +
                           " ns is older than the state history (oldest " +
                           (history.empty() ? std::string("none") : std::to_string(history.oldest().stamp_ns)) + " ns)";
    return out;
  }
  const Eigen::VectorXd h_now = measure(kind, x_now);
  if (!compensate || stamp_ns >= history.newest().stamp_ns) {
    out.residual = measurement_difference(kind, z_s, h_now);
    return out;
  }
  const StampedState past = *history.entry_at(stamp_ns);
  const StateVector x_s = corrected_since(past, current_correction);
  out.residual = measurement_difference(kind, shifted_measurement(kind, z_s, x_s, x_now), h_now);
  return out;
}

void SpreadMeasurementQueue::add(MeasurementKind kind, const Eigen::VectorXd& z_s, const Eigen::VectorXd& residual,
                                 const Eigen::MatrixXd& R, int injections) {
  const int n = std::max(1, injections);
  pending_.push_back({kind, z_s, residual, R, n, n});
}

int SpreadMeasurementQueue::inject(KinematicEkf& ekf) {
  int applied = 0;
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    Pending& m = pending_[i];
    const StateVector before = ekf.state();
    const Eigen::VectorXd residual =
        compensate_ ? m.remaining_innovation : measurement_difference(m.kind, m.z_s, measure(m.kind, before));
    const Eigen::MatrixXd R_injection = static_cast<double>(m.injections_total) * m.R;
    if (ekf.update(m.kind, residual, R_injection)) {
      ++applied;
      note_correction(before, ekf.state());
    }
    --m.injections_left;
  }
  std::erase_if(pending_, [](const Pending& m) { return m.injections_left <= 0; });
  return applied;
}

void SpreadMeasurementQueue::note_correction(const StateVector& before, const StateVector& after) {
  if (!compensate_) return;
  for (Pending& m : pending_) {
    m.remaining_innovation -= measurement_difference(m.kind, measure(m.kind, after), measure(m.kind, before));
  }
}

}  // namespace farlio::fusion
