#pragma once
// The IMU model: samples the exact body motion (gyro = body angular velocity, accel =
// R_wb^T (a_world - g_world) with g_world = (0, 0, -gravity)) and, unless noise-free, applies the
// error model: response matrices and g-sensitivity (imu_errors.hpp), vibration (vibration.hpp),
// then the bias (initial + turn-on + random walk) and white noise of each sample.
#include <cstdint>
#include <vector>

#include "farlio/core/types.hpp"
#include "farlio/sim/config.hpp"
#include "farlio/sim/motion.hpp"

namespace farlio::sim {

/// The noise-free reading of an ideal IMU in state `s`.
ImuSample ideal_imu_reading(const BodyState& s, double gravity_m_s2);

/// Samples at start_stamp_ns + k / rate for k = 0 .. floor(duration * rate), in time order.
std::vector<ImuSample> generate_imu(const MotionModel& motion, const SimConfig& config);

}  // namespace farlio::sim
