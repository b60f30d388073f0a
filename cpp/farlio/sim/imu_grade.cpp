#include "farlio/sim/imu_grade.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace farlio::sim {
namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kSecondsPerHour = 3600.0;
/// Standard gravity, the g of datasheets (mg, ug, deg/s/g).
constexpr double kStandardGravity_m_s2 = 9.80665;
constexpr double kPerMilli = 1e-3;
constexpr double kPerMicro = 1e-6;

// Typical 1-sigma figures of each class (docs/simulation.md, "IMU grades"), in the order of
// ImuDatasheet: gyro noise density, bias instability, turn-on bias, scale factor, misalignment,
// g-sensitivity; accel noise density, bias instability, turn-on bias, scale factor, misalignment.
constexpr ImuDatasheet kConsumer{0.01, 10.0, 0.5, 5000.0, 5.0, 0.1, 150.0, 100.0, 20.0, 5000.0, 5.0};
constexpr ImuDatasheet kIndustrial{0.007, 5.0, 0.1, 1000.0, 1.0, 0.01, 60.0, 20.0, 2.0, 1000.0, 1.0};
constexpr ImuDatasheet kTactical{0.0007, 0.3, 0.002, 300.0, 0.3, 3e-4, 50.0, 10.0, 1.0, 300.0, 0.3};

struct NamedGrade {
  ImuGrade grade;
  const char* name;
};
constexpr NamedGrade kGrades[] = {{ImuGrade::Profile, "profile"},
                                  {ImuGrade::Ideal, "ideal"},
                                  {ImuGrade::Consumer, "consumer"},
                                  {ImuGrade::Industrial, "industrial"},
                                  {ImuGrade::Tactical, "tactical"}};

void remove_imu_noise(NoiseConfig& n) {
  n.gyro_noise_std_rad_s = 0.0;
  n.accel_noise_std_m_s2 = 0.0;
  n.gyro_bias_walk_rad_s2_sqrt_hz = 0.0;
  n.accel_bias_walk_m_s3_sqrt_hz = 0.0;
  n.gyro_bias_initial_rad_s.setZero();
  n.accel_bias_initial_m_s2.setZero();
}
}  // namespace

ImuGrade parse_imu_grade(const std::string& name) {
  for (const NamedGrade& g : kGrades)
    if (name == g.name) return g.grade;
  throw std::invalid_argument("unknown IMU grade '" + name +
                              "' (valid: profile, ideal, consumer, industrial, tactical)");
}

std::string imu_grade_name(ImuGrade grade) {
  for (const NamedGrade& g : kGrades)
    if (grade == g.grade) return g.name;
  throw std::invalid_argument("unknown IMU grade");
}

ImuDatasheet imu_datasheet(ImuGrade grade) {
  switch (grade) {
    case ImuGrade::Consumer: return kConsumer;
    case ImuGrade::Industrial: return kIndustrial;
    case ImuGrade::Tactical: return kTactical;
    default: throw std::invalid_argument("imu_datasheet: '" + imu_grade_name(grade) + "' is not a datasheet class");
  }
}

VibrationConfig platform_vibration(Profile profile) {
  VibrationConfig v;
  switch (profile) {
    case Profile::Urban:   // a passenger car on city streets, <= 14 m/s
    case Profile::Tunnel:  // the same car on a motorway, <= 28 m/s
    case Profile::Garage:  // and in a parking garage, <= 6 m/s
      v.wheel_radius_m = 0.32;
      v.accel_wheel_amplitude_m_s2_per_m_s = {0.005, 0.005, 0.015};
      v.gyro_wheel_amplitude_rad_s_per_m_s = {2e-4, 2e-4, 1e-4};
      v.accel_noise_std_m_s2_per_m_s = {0.01, 0.01, 0.02};
      v.gyro_noise_std_rad_s_per_m_s = {3e-4, 3e-4, 2e-4};
      return v;
    case Profile::Racetrack:  // stiff race car suspension, <= 70 m/s
      v.wheel_radius_m = 0.33;
      v.accel_wheel_amplitude_m_s2_per_m_s = {0.01, 0.01, 0.03};
      v.gyro_wheel_amplitude_rad_s_per_m_s = {2e-4, 2e-4, 1e-4};
      v.accel_noise_std_m_s2_per_m_s = {0.01, 0.01, 0.02};
      v.gyro_noise_std_rad_s_per_m_s = {2e-4, 2e-4, 1e-4};
      return v;
    case Profile::Handheld:  // footsteps: broadband only, no wheel
      v.accel_noise_std_m_s2_per_m_s = {0.05, 0.05, 0.1};
      v.gyro_noise_std_rad_s_per_m_s = {0.005, 0.005, 0.005};
      return v;
  }
  throw std::invalid_argument("unknown profile");
}

double white_noise_std_per_sample(double noise_density_per_sqrt_hz, double rate_hz) {
  return noise_density_per_sqrt_hz * std::sqrt(rate_hz);
}

double bias_walk_from_instability(double bias_instability) {
  return bias_instability * std::sqrt(3.0 / kBiasInstabilityTime_s);
}

void apply_imu_grade(SimConfig& config, ImuGrade grade, bool vibration) {
  if (grade == ImuGrade::Profile) return;
  remove_imu_noise(config.noise);
  config.imu_errors = ImuErrorConfig{};
  if (grade == ImuGrade::Ideal) return;
  const ImuDatasheet d = imu_datasheet(grade);
  const double g = kStandardGravity_m_s2;
  NoiseConfig& n = config.noise;
  n.gyro_noise_std_rad_s =
      white_noise_std_per_sample(kRadPerDeg * d.gyro_noise_density_deg_s_sqrt_hz, config.imu_rate_hz);
  n.accel_noise_std_m_s2 =
      white_noise_std_per_sample(kPerMicro * g * d.accel_noise_density_ug_sqrt_hz, config.imu_rate_hz);
  n.gyro_bias_walk_rad_s2_sqrt_hz =
      bias_walk_from_instability(kRadPerDeg * d.gyro_bias_instability_deg_h / kSecondsPerHour);
  n.accel_bias_walk_m_s3_sqrt_hz = bias_walk_from_instability(kPerMicro * g * d.accel_bias_instability_ug);
  ImuErrorConfig& e = config.imu_errors;
  e.gyro_turn_on_bias_std_rad_s = kRadPerDeg * d.gyro_turn_on_bias_deg_s;
  e.accel_turn_on_bias_std_m_s2 = kPerMilli * g * d.accel_turn_on_bias_mg;
  e.gyro_scale_factor_std_ppm = d.gyro_scale_factor_ppm;
  e.accel_scale_factor_std_ppm = d.accel_scale_factor_ppm;
  e.gyro_misalignment_std_mrad = d.gyro_misalignment_mrad;
  e.accel_misalignment_std_mrad = d.accel_misalignment_mrad;
  e.gyro_g_sensitivity_std_rad_s_per_m_s2 = kRadPerDeg * d.gyro_g_sensitivity_deg_s_g / g;
  if (vibration) e.vibration = platform_vibration(config.profile);
}

}  // namespace farlio::sim
