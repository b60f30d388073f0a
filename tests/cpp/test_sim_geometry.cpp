// Building blocks of the simulator against exact references.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "farlio/sim/path.hpp"
#include "farlio/sim/primitives.hpp"
#include "farlio/sim/scene.hpp"
#include "farlio/sim/smooth_curve.hpp"

using namespace farlio::sim;

TEST(SimSmoothCurve, DerivativesAndIntegralMatchNumerics) {
  const SmoothCurve c({0.0, 1.0, 2.5, 4.0}, {1.0, 3.0, 3.0, -2.0});
  EXPECT_DOUBLE_EQ(c.value(-1.0), 1.0);
  EXPECT_DOUBLE_EQ(c.value(1.0), 3.0);
  EXPECT_DOUBLE_EQ(c.value(9.0), -2.0);
  constexpr double h = 1e-5;
  double integral = 0.0;
  constexpr int kSteps = 40000;
  for (int i = 0; i < kSteps; ++i) {
    const double x = 4.0 * (i + 0.5) / kSteps;
    integral += c.value(x) * 4.0 / kSteps;
    EXPECT_NEAR(c.derivative(x), (c.value(x + h) - c.value(x - h)) / (2 * h), 1e-6);
    EXPECT_NEAR(c.second_derivative(x), (c.derivative(x + h) - c.derivative(x - h)) / (2 * h), 1e-5);
  }
  EXPECT_NEAR(c.integral(4.0), integral, 1e-8);
  EXPECT_NEAR(c.integral(5.0), integral - 2.0, 1e-8);
  EXPECT_THROW(SmoothCurve({0.0, 0.0}, {1.0, 2.0}), std::invalid_argument);
}

TEST(SimPath, RoundedRectanglePassesNearItsVerticesAndCloses) {
  const std::vector<Eigen::Vector2d> square = {{0, 0}, {100, 0}, {100, 100}, {0, 100}};
  const Path path = Path::from_polyline(square, {10, 10, 10, 10}, true);
  EXPECT_TRUE(path.closed());
  ASSERT_EQ(path.corners().size(), 4U);
  // Starts at the middle of the first edge heading +x, and a lap later is back there.
  EXPECT_LT((path.at(0.0).position_m - Eigen::Vector2d(50, 0)).norm(), 1e-9);
  EXPECT_LT((path.at(path.length_m()).position_m - Eigen::Vector2d(50, 0)).norm(), 1e-6);
  // Straight stretches lie exactly on the polygon edges.
  const PathPoint mid2 = path.at(0.5 * (path.corners()[0].s_end_m + path.corners()[1].s_begin_m));
  EXPECT_NEAR(mid2.position_m.x(), 100.0, 1e-6);
  EXPECT_NEAR(mid2.heading_rad, 0.5 * std::numbers::pi, 1e-9);
  // Shorter than the polygon (corners are cut) but not by more than the rounding can.
  EXPECT_LT(path.length_m(), 400.0);
  EXPECT_GT(path.length_m(), 400.0 - 4 * 2 * 10.0 * 1.5);
  // An edge too short for its corners is rejected.
  EXPECT_THROW(Path::from_polyline({{0, 0}, {10, 0}, {10, 10}, {0, 10}}, {10, 10, 10, 10}, true),
               std::invalid_argument);
}

TEST(SimPrimitives, BoxCylinderGroundAgainstAnalyticHits) {
  const Box box{Eigen::Vector3d(10, 0, 1), Eigen::Vector3d(1, 2, 1), std::numbers::pi / 2, 0.5F};
  // Rotated 90 degrees: its x half-extent 1 now spans y, its y half-extent 2 spans x.
  auto h = box.intersect(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 100.0);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->range_m, 8.0, 1e-12);
  EXPECT_NEAR(std::abs(h->normal.x()), 1.0, 1e-12);
  EXPECT_FALSE(box.intersect(Eigen::Vector3d(0, 1.5, 1), Eigen::Vector3d::UnitX(), 100.0));
  EXPECT_FALSE(box.intersect(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 7.9));

  const Cylinder cyl{Eigen::Vector2d(5, 0), 0.5, 0.0, 3.0, 0.5F};
  h = cyl.intersect(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 100.0);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->range_m, 4.5, 1e-12);
  const Eigen::Vector3d down = Eigen::Vector3d(0, 0, -1);
  h = cyl.intersect(Eigen::Vector3d(5.2, 0, 10), down, 100.0);  // the top cap
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->range_m, 7.0, 1e-12);

  const GroundProfile ground({0.0, 10.0}, {0.0, 5.0}, 0.3F);  // a 50 % ramp between x = 0 and 10
  h = ground.intersect(Eigen::Vector3d(4, 7, 10), down, 100.0);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->range_m, 8.0, 1e-12);
  const Eigen::Vector3d d = Eigen::Vector3d(1, 0, -0.1).normalized();
  h = ground.intersect(Eigen::Vector3d(-20, 0, 2), d, 1000.0);  // flat part: hits at x = 0
  ASSERT_TRUE(h);
  EXPECT_NEAR((Eigen::Vector3d(-20, 0, 2) + h->range_m * d).x(), 0.0, 1e-9);
  // From above the upper plateau, passing over the ramp down to the lower flat part at x = -45.
  const Eigen::Vector3d e = Eigen::Vector3d(-1, 0, -0.1).normalized();
  h = ground.intersect(Eigen::Vector3d(20, 0, 6.5), e, 1000.0);
  ASSERT_TRUE(h);
  const Eigen::Vector3d p = Eigen::Vector3d(20, 0, 6.5) + h->range_m * e;
  EXPECT_NEAR(p.z(), ground.height_m(p.x()), 1e-9);
  EXPECT_NEAR(p.x(), -45.0, 1e-9);
}

TEST(SimPrimitives, AnInclinedBoxIsHitOnItsSlopedTopAndSides) {
  // A ramp 10 m long (x in [0, 10]) rising 1 m (slope 0.1), 0.3 m thick, turned by 30 degrees.
  const double yaw = std::numbers::pi / 6, slope = 0.1;
  Box ramp{Eigen::Vector3d(5, 0, 0.5 - 0.15), Eigen::Vector3d(5, 2, 0.15), 0.0, 0.5F};
  ramp.slope = slope;
  const Eigen::Vector3d down(0, 0, -1);
  for (const double x : {0.5, 3.0, 7.5, 9.9}) {  // straight down onto the top: z = slope * x
    const auto h = ramp.intersect(Eigen::Vector3d(x, 1.0, 5.0), down, 100.0);
    ASSERT_TRUE(h) << x;
    EXPECT_NEAR(5.0 - h->range_m, slope * x, 1e-12) << x;
    EXPECT_NEAR(h->normal.dot(Eigen::Vector3d(-slope, 0, 1).normalized()), 1.0, 1e-12);
  }
  EXPECT_FALSE(ramp.intersect(Eigen::Vector3d(10.5, 0, 5), down, 100.0));      // beyond its end
  const auto under = ramp.intersect(Eigen::Vector3d(8, 0, -3), -down, 100.0);  // the bottom face
  ASSERT_TRUE(under);
  EXPECT_NEAR(-3.0 + under->range_m, slope * 8 - 0.3, 1e-12);
  const auto side = ramp.intersect(Eigen::Vector3d(20, 0, 0.75), -Eigen::Vector3d::UnitX(), 100.0);
  ASSERT_TRUE(side);  // the vertical end at x = 10 spans z in [0.7, 1.0]
  EXPECT_NEAR(side->range_m, 10.0, 1e-12);
  EXPECT_NEAR(ramp.surface_distance_m(Eigen::Vector3d(4, 0, slope * 4 + 0.2)), 0.2 / std::sqrt(1 + slope * slope),
              1e-12);

  // Turned: the same hits in the rotated frame; a level box (slope 0) is the box of before.
  Box turned = ramp;
  turned.yaw_rad = yaw;
  turned.center_m = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * ramp.center_m;
  const Eigen::Vector3d p = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(7.5, 1.0, 5.0);
  const auto h = turned.intersect(p, down, 100.0);
  ASSERT_TRUE(h);
  EXPECT_NEAR(5.0 - h->range_m, slope * 7.5, 1e-12);
  const Box level{Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(5, 2, 0.15), yaw, 0.5F};
  const auto flat = level.intersect(Eigen::Vector3d(5, 0, 5), down, 100.0);
  ASSERT_TRUE(flat);
  EXPECT_NEAR(flat->range_m, 4.85, 1e-12);
}

TEST(SimScene, GridCastEqualsBruteForce) {
  Scene scene;
  std::uint64_t state = 12345;
  auto rnd = [&state](double lo, double hi) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(state >> 11U) / 9007199254740992.0;
  };
  for (int i = 0; i < 300; ++i)
    scene.add(Box{Eigen::Vector3d(rnd(-100, 100), rnd(-100, 100), rnd(0, 5)),
                  Eigen::Vector3d(rnd(0.2, 6), rnd(0.2, 6), rnd(0.5, 4)), rnd(-3, 3), 0.5F,
                  i % 3 == 0 ? rnd(-0.3, 0.3) : 0.0});  // every third one a ramp
  for (int i = 0; i < 200; ++i)
    scene.add(Cylinder{Eigen::Vector2d(rnd(-100, 100), rnd(-100, 100)), rnd(0.1, 2), 0.0, rnd(1, 10), 0.5F});
  scene.build_index(7.0);
  int hits = 0;
  for (int r = 0; r < 3000; ++r) {
    const Eigen::Vector3d o(rnd(-120, 120), rnd(-120, 120), rnd(0.5, 3));
    const Eigen::Vector3d d = Eigen::Vector3d(rnd(-1, 1), rnd(-1, 1), rnd(-0.2, 0.1)).normalized();
    const auto fast = scene.cast(o, d, 150.0);
    std::optional<RayHit> slow = scene.ground().intersect(o, d, 150.0);
    for (const auto& b : scene.boxes())
      if (auto h = b.intersect(o, d, 150.0); h && (!slow || h->range_m < slow->range_m)) slow = h;
    for (const auto& c : scene.cylinders())
      if (auto h = c.intersect(o, d, 150.0); h && (!slow || h->range_m < slow->range_m)) slow = h;
    ASSERT_EQ(fast.has_value(), slow.has_value()) << r;
    if (fast) {
      EXPECT_DOUBLE_EQ(fast->range_m, slow->range_m) << r;
      ++hits;
    }
  }
  EXPECT_GT(hits, 1000);
}
