#pragma once
// A small synthetic structured scene (floor, walls, boxes, a pole, a ramp) sampled at random,
// for registration tests with an exactly known transform.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "farlio/core/se3.hpp"
#include "farlio/core/types.hpp"

namespace farlio::test {

inline std::vector<Eigen::Vector3f> sample_scene(std::size_t n, unsigned seed, float noise_m = 0.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(n);
  while (pts.size() < n) {
    const float a = u(rng), b = u(rng);
    Eigen::Vector3f p;
    switch (static_cast<int>(u(rng) * 9.0f)) {
      case 0:
      case 1: p = {-25 + 50 * a, -25 + 50 * b, 0}; break;  // floor
      case 2: p = {-25, -25 + 50 * a, 6 * b}; break;       // walls
      case 3: p = {25, -25 + 50 * a, 6 * b}; break;
      case 4: p = {-25 + 50 * a, 25, 6 * b}; break;
      case 5: p = {-25 + 50 * a, -25, 6 * b}; break;
      case 6: {  // two boxes
        const bool first = u(rng) < 0.5f;
        const Eigen::Vector3f c = first ? Eigen::Vector3f(5, 3, 0) : Eigen::Vector3f(-8, -6, 0);
        const float side = u(rng);
        if (side < 0.25f)
          p = c + Eigen::Vector3f(4 * a, 0, 3 * b);
        else if (side < 0.5f)
          p = c + Eigen::Vector3f(4 * a, 4, 3 * b);
        else if (side < 0.75f)
          p = c + Eigen::Vector3f(0, 4 * a, 3 * b);
        else
          p = c + Eigen::Vector3f(4 * a, 4 * b, 3);
        break;
      }
      case 7: {  // pole
        const float th = 6.2831853f * a;
        p = {12 + 0.3f * std::cos(th), -12 + 0.3f * std::sin(th), 8 * b};
        break;
      }
      default: p = {-20 + 15 * a, 10 + 8 * b, 0.25f * 15 * a}; break;  // ramp
    }
    if (noise_m > 0) p += noise_m * Eigen::Vector3f(g(rng), g(rng), g(rng));
    pts.push_back(p);
  }
  return pts;
}

/// A scan of the scene (n points sampled with `seed`, `noise_m`) seen from `pose`, ending at end_s
/// after period_s; no per-point times.
inline Scan scene_scan(const SE3& pose, double end_s, double period_s, std::size_t n, unsigned seed, float noise_m) {
  const SE3 inv = pose.inverse();
  Scan s;
  s.end_stamp_ns = static_cast<std::int64_t>(std::llround(end_s * 1e9));
  s.start_stamp_ns = s.end_stamp_ns - static_cast<std::int64_t>(std::llround(period_s * 1e9));
  for (const auto& p : sample_scene(n, seed, noise_m)) s.points.push_back((inv * p.cast<double>()).cast<float>());
  return s;
}

}  // namespace farlio::test
