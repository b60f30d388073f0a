// Adaptive submap density (ASMD): the submap's per-voxel limit follows the scan's own density
// close by, within [k, max_points_per_voxel], decays with distance and never falls below k.
#include <gtest/gtest.h>

#include <limits>

#include "farlio/map/adaptive_density.hpp"

using namespace farlio;

namespace {
struct Configs {
  AdaptiveDensityConfig density;
  VoxelMapConfig map;
};
Configs defaults() { return {Config().density, Config().map}; }
}  // namespace

TEST(AdaptiveDensity, TheLimitIsTheScansDensityWithinKAndTheMapsMaximum) {
  const Configs c = defaults();
  const int k = c.map.covariance_neighbors, n_max = c.map.max_points_per_voxel;
  ASSERT_LT(k + 3, n_max);
  const map::PointLimit mid = map::adaptive_point_limit(k + 3.7, c.density, c.map);
  EXPECT_EQ(mid.close_limit, k + 3);  // the density, truncated
  EXPECT_EQ(mid.min_limit, k);
  EXPECT_FLOAT_EQ(mid.close_range_m, static_cast<float>(c.density.close_range_m));
  EXPECT_EQ(map::adaptive_point_limit(1.5, c.density, c.map).close_limit, k);               // a sparse scan: k
  EXPECT_EQ(map::adaptive_point_limit(10.0 * n_max, c.density, c.map).close_limit, n_max);  // a dense one: the cap
  // beyond the close range it decays by the slope, down to k
  const float far = mid.close_range_m + 1.0f / static_cast<float>(c.density.slope_points_per_m);
  EXPECT_EQ(mid.at(mid.close_range_m), k + 3);
  EXPECT_EQ(mid.at(far), k + 2);
  EXPECT_EQ(mid.at(1e6f), k);
}

TEST(AdaptiveDensity, OffOrUnmeasuredIsTheConstantMaximum) {
  Configs c = defaults();
  const int n_max = c.map.max_points_per_voxel;
  for (const double unmeasured : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    const map::PointLimit l = map::adaptive_point_limit(unmeasured, c.density, c.map);
    EXPECT_EQ(l.close_limit, n_max);
    EXPECT_EQ(l.at(1e6f), n_max);
  }
  c.density.enabled = false;
  EXPECT_EQ(map::adaptive_point_limit(5.0, c.density, c.map).at(0.0f), n_max);
}
