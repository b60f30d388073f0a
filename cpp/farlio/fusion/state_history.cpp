#include "farlio/fusion/state_history.hpp"

#include <Eigen/Geometry>
#include <algorithm>

#include "farlio/fusion/euler.hpp"

namespace farlio::fusion {

StateHistory::StateHistory(std::size_t capacity) : buffer_(std::max<std::size_t>(capacity, 2)) {}

void StateHistory::push(std::int64_t stamp_ns, const StateVector& x, const StateVector& cumulative_correction) {
  while (size_ > 0 && newest().stamp_ns >= stamp_ns) --size_;  // keep stamps increasing
  if (size_ == buffer_.size()) {
    head_ = (head_ + 1) % buffer_.size();
    --size_;
  }
  buffer_[(head_ + size_) % buffer_.size()] = {stamp_ns, x, cumulative_correction};
  ++size_;
}

void StateHistory::clear() {
  head_ = 0;
  size_ = 0;
}

StateVector interpolate_states(const StateVector& a, const StateVector& b, double s) {
  StateVector out = a + s * (b - a);
  const Eigen::Quaterniond qa(rotation_from_euler(a.segment<3>(kAttitudeIndex)));
  const Eigen::Quaterniond qb(rotation_from_euler(b.segment<3>(kAttitudeIndex)));
  out.segment<3>(kAttitudeIndex) = euler_from_rotation(qa.slerp(s, qb).toRotationMatrix());
  return out;
}

std::optional<StateVector> StateHistory::state_at(std::int64_t stamp_ns) const {
  const auto e = entry_at(stamp_ns);
  if (!e) return std::nullopt;
  return e->x;
}

std::optional<StampedState> StateHistory::entry_at(std::int64_t stamp_ns) const {
  if (size_ == 0 || stamp_ns < oldest().stamp_ns || stamp_ns > newest().stamp_ns) return std::nullopt;
  // First entry with stamp >= stamp_ns (binary search over the logical order).
  std::size_t lo = 0, hi = size_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (at(mid).stamp_ns < stamp_ns)
      lo = mid + 1;
    else
      hi = mid;
  }
  const StampedState& b = at(lo);
  if (b.stamp_ns == stamp_ns || lo == 0) return b;
  const StampedState& a = at(lo - 1);
  const double s = static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  return StampedState{stamp_ns, interpolate_states(a.x, b.x, s),
                      a.cumulative_correction + s * (b.cumulative_correction - a.cumulative_correction)};
}

StateVector corrected_since(const StampedState& past, const StateVector& current_correction) {
  return normalized_state(past.x + (current_correction - past.cumulative_correction));
}

}  // namespace farlio::fusion
