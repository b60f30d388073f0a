#pragma once
// A fixed-capacity ring buffer of (step stamp, EKF state): the filter's recent past, queried by
// interpolation for delay compensation (x_s of eq. 10) and for undistortion poses.
#include <cstdint>
#include <optional>
#include <vector>

#include "farlio/fusion/kinematic_model.hpp"

namespace farlio::fusion {

struct StampedState {
  std::int64_t stamp_ns = 0;
  StateVector x = StateVector::Zero();
  /// Sum of all EKF corrections (x+ - x-, angles wrapped) applied up to this step: the
  /// difference between two entries is what the updates in between moved the estimate.
  StateVector cumulative_correction = StateVector::Zero();
};

class StateHistory {
 public:
  explicit StateHistory(std::size_t capacity);

  /// Appends a state; stamps must increase (an older or equal stamp replaces the history tail).
  void push(std::int64_t stamp_ns, const StateVector& x,
            const StateVector& cumulative_correction = StateVector::Zero());
  void clear();
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  [[nodiscard]] const StampedState& oldest() const { return at(0); }
  [[nodiscard]] const StampedState& newest() const { return at(size_ - 1); }
  /// The state at stamp_ns: positions and velocities interpolated linearly, the attitude
  /// geodesically (quaternion slerp); nullopt outside [oldest, newest].
  [[nodiscard]] std::optional<StateVector> state_at(std::int64_t stamp_ns) const;
  /// The interpolated entry (state as state_at, cumulative correction linearly).
  [[nodiscard]] std::optional<StampedState> entry_at(std::int64_t stamp_ns) const;

 private:
  [[nodiscard]] const StampedState& at(std::size_t i) const { return buffer_[(head_ + i) % buffer_.size()]; }

  std::vector<StampedState> buffer_;
  std::size_t head_ = 0;  ///< index of the oldest entry
  std::size_t size_ = 0;
};

/// Interpolates between two states (s in [0, 1]) as StateHistory::state_at does.
StateVector interpolate_states(const StateVector& a, const StateVector& b, double s);

/// A past entry moved by the corrections applied since it was stored (`current_correction`: the
/// cumulative correction now): where the filter now puts that instant, the x_s of eq. 10.
StateVector corrected_since(const StampedState& past, const StateVector& current_correction);

}  // namespace farlio::fusion
