// Scan::remove_non_finite: the points with a NaN/Inf coordinate or time go, the others keep their
// order and their time, intensity and sensor id, wherever the first bad point is (or without one).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "farlio/core/types.hpp"

using namespace farlio;

namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr std::size_t kPoints = 6;

Scan numbered_scan() {
  Scan s;
  for (std::size_t i = 0; i < kPoints; ++i) {
    const auto v = static_cast<float>(i);
    s.points.emplace_back(v, 10 + v, 20 + v);
    s.time_s.push_back(0.01f * v);
    s.intensity.push_back(100 + v);
    s.sensor_id.push_back(static_cast<std::uint8_t>(i));
  }
  return s;
}

/// The ids of the points left; every channel must still belong to the same point.
std::vector<std::size_t> remaining(const Scan& s) {
  std::vector<std::size_t> ids;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const std::size_t id = s.sensor_id[k];
    const auto v = static_cast<float>(id);
    EXPECT_EQ(s.points[k], Vec3f(v, 10 + v, 20 + v));
    EXPECT_EQ(s.time_s[k], 0.01f * v);
    EXPECT_EQ(s.intensity[k], 100 + v);
    ids.push_back(id);
  }
  return ids;
}

}  // namespace

TEST(Scan, RemoveNonFiniteKeepsTheOthersInOrder) {
  Scan all = numbered_scan();
  EXPECT_EQ(all.remove_non_finite(), 0u);
  EXPECT_EQ(remaining(all), (std::vector<std::size_t>{0, 1, 2, 3, 4, 5}));

  for (std::size_t bad : {std::size_t{0}, std::size_t{3}, kPoints - 1}) {
    for (int channel = 0; channel < 4; ++channel) {  // x, y, z, time
      SCOPED_TRACE(testing::Message() << "bad point " << bad << " channel " << channel);
      Scan s = numbered_scan();
      if (channel < 3) {
        s.points[bad][channel] = channel == 1 ? kInf : kNan;
      } else {
        s.time_s[bad] = kNan;
      }
      EXPECT_EQ(s.remove_non_finite(), 1u);
      std::vector<std::size_t> expected;
      for (std::size_t i = 0; i < kPoints; ++i) {
        if (i != bad) expected.push_back(i);
      }
      EXPECT_EQ(remaining(s), expected);
      EXPECT_EQ(s.time_s.size(), s.size());
      EXPECT_EQ(s.intensity.size(), s.size());
    }
  }

  Scan two = numbered_scan();
  two.points[1].x() = kNan;
  two.points[4].z() = -kInf;
  EXPECT_EQ(two.remove_non_finite(), 2u);
  EXPECT_EQ(remaining(two), (std::vector<std::size_t>{0, 2, 3, 5}));

  Scan no_time = numbered_scan();
  no_time.time_s.clear();
  no_time.points[2].y() = kNan;
  EXPECT_EQ(no_time.remove_non_finite(), 1u);
  EXPECT_EQ(no_time.size(), kPoints - 1);
  EXPECT_TRUE(no_time.time_s.empty());
}
