#pragma once
// Counter-based random numbers for the simulator. Every draw is a pure function of
// (seed, stream, index, component), so results do not depend on call order or threads and
// are bit-identical across platforms (no std:: distributions, whose output is unspecified).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace farlio::sim {

/// Independent random streams of one sequence. New streams get new numbers, so adding one leaves
/// the draws of the others (and so every existing sequence) unchanged.
enum class Stream : std::uint64_t {
  Layout = 1,
  LidarRange = 2,
  LidarDropout = 3,
  ImuGyro = 4,
  ImuAccel = 5,
  ImuGyroBias = 6,
  ImuAccelBias = 7,
  ImuTurnOnBias = 8,       ///< index 0: gyro, 1: accel
  ImuScaleFactor = 9,      ///< index 0: gyro, 1: accel
  ImuMisalignment = 10,    ///< index 0: gyro, 1: accel; component: matrix entry
  ImuGSensitivity = 11,    ///< component: matrix entry
  ImuVibrationPhase = 12,  ///< index 0: gyro, 1: accel
  ImuGyroVibration = 13,   ///< index: sample
  ImuAccelVibration = 14   ///< index: sample
};

/// SplitMix64 finaliser: a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31U);
}

/// 64 random bits for (seed, stream, index, component).
constexpr std::uint64_t random_bits(std::uint64_t seed, Stream stream, std::uint64_t index,
                                    std::uint64_t component = 0) {
  return mix64(mix64(mix64(mix64(seed) ^ static_cast<std::uint64_t>(stream)) ^ index) ^ component);
}

/// Uniform in (0, 1): never exactly 0, so log() below is finite.
constexpr double to_unit_open(std::uint64_t bits) {
  constexpr double kInv2Pow53 = 1.0 / 9007199254740992.0;
  return (static_cast<double>(bits >> 11U) + 0.5) * kInv2Pow53;
}

inline double uniform01(std::uint64_t seed, Stream stream, std::uint64_t index, std::uint64_t component = 0) {
  return to_unit_open(random_bits(seed, stream, index, component));
}

/// Standard normal by Box-Muller from two counter-based uniforms.
inline double standard_normal(std::uint64_t seed, Stream stream, std::uint64_t index, std::uint64_t component = 0) {
  constexpr std::uint64_t kSecondDraw = 0x5851F42D4C957F2DULL;
  const double u1 = uniform01(seed, stream, index, 2 * component);
  const double u2 = uniform01(seed, stream, index ^ kSecondDraw, 2 * component + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// Three independent standard normals (components 0, 1, 2) of one (seed, stream, index).
inline Eigen::Vector3d standard_normal3(std::uint64_t seed, Stream stream, std::uint64_t index) {
  return {standard_normal(seed, stream, index, 0), standard_normal(seed, stream, index, 1),
          standard_normal(seed, stream, index, 2)};
}

/// A small sequential generator (for laying out scenes) built on the same mixer.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : seed_(seed) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(seed_, Stream::Layout, counter_++); }
  /// True with probability p.
  bool chance(double p) { return uniform(0.0, 1.0) < p; }

 private:
  std::uint64_t seed_;
  std::uint64_t counter_ = 0;
};

}  // namespace farlio::sim
