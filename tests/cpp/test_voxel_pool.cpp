// The map-update decisions that the host VoxelMap and the CUDA DeviceVoxelMap share
// (voxel_pool.hpp): cases with a known answer, and the slot order against a plain free list.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "farlio/core/error.hpp"
#include "farlio/map/voxel_pool.hpp"
#include "farlio/map/voxel_update.hpp"

using namespace farlio;
using namespace farlio::map;

namespace {

constexpr std::size_t kCapacity = 1000;
const std::string kParameter = "map.max_voxel_capacity";

PoolCounts pool(std::size_t high_water, std::size_t free_voxels, std::size_t used_slots) {
  return {high_water, free_voxels, high_water - free_voxels, used_slots, table_capacity_for(kCapacity)};
}

struct PlanCase {
  const char* what;
  PoolCounts counts;
  std::size_t new_voxels;
  std::size_t from_free_list, high_water;
  bool rehash;
};

std::ostream& operator<<(std::ostream& os, const PlanCase& c) { return os << c.what; }

class InsertionPlanCase : public ::testing::TestWithParam<PlanCase> {};

}  // namespace

TEST_P(InsertionPlanCase, ReusesFreedVoxelsThenTheHighWaterMark) {
  const PlanCase& c = GetParam();
  const InsertionPlan plan = plan_insertion(c.counts, c.new_voxels, kCapacity, kParameter);
  EXPECT_EQ(plan.from_free_list, c.from_free_list) << c.what;
  EXPECT_EQ(plan.high_water, c.high_water) << c.what;
  EXPECT_EQ(plan.high_water, voxels_needed(c.counts, c.new_voxels)) << c.what;
  // a rehash keeps the table's size: it is kSlotsPerVoxel x the pool already
  EXPECT_EQ(plan.rehash_slots, c.rehash ? c.counts.table_slots : 0u) << c.what;
}

// table_capacity_for(1000) = 2048 slots: more than 1024 used (erased included) forces a rehash
INSTANTIATE_TEST_SUITE_P(
    Cases, InsertionPlanCase,
    ::testing::Values(PlanCase{"empty pool", pool(0, 0, 0), 10, 0, 10, false},
                      PlanCase{"all from the free list", pool(100, 30, 70), 20, 20, 100, false},
                      PlanCase{"free list first, then new slots", pool(100, 30, 70), 50, 30, 120, false},
                      PlanCase{"erased slots fill the table", pool(600, 100, 1000), 50, 50, 600, true},
                      PlanCase{"exactly half full is fine", pool(500, 0, 1000), 24, 0, 524, false},
                      PlanCase{"one more is not", pool(500, 0, 1000), 25, 0, 525, true}));

TEST(InsertionPlan, APoolBeyondItsCapacityIsAnErrorNamingTheParameter) {
  try {
    plan_insertion(pool(990, 5, 985), 20, kCapacity, kParameter);
    FAIL() << "expected CapacityError";
  } catch (const CapacityError& e) {
    EXPECT_NE(std::string(e.what()).find(kParameter), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1005 voxels needed"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(plan_insertion(pool(990, 5, 985), 15, kCapacity, kParameter));
}

TEST(InsertionPlan, AGrownPoolGrowsTheTable) {
  PoolCounts c = pool(10, 0, 10);
  c.table_slots = table_capacity_for(16);
  const InsertionPlan plan = plan_insertion(c, 40, 64, kParameter);
  EXPECT_EQ(plan.rehash_slots, table_capacity_for(64));
}

TEST(PoolCapacity, DoublesUpToTheLimit) {
  EXPECT_EQ(grown_pool_capacity(10, 16, 100, kParameter), 16u);  // fits
  EXPECT_EQ(grown_pool_capacity(17, 16, 100, kParameter), 32u);  // doubles
  EXPECT_EQ(grown_pool_capacity(40, 16, 100, kParameter), 40u);  // more than double is needed
  EXPECT_EQ(grown_pool_capacity(60, 64, 100, kParameter), 64u);
  EXPECT_EQ(grown_pool_capacity(65, 64, 100, kParameter), 100u);  // capped at the limit
  EXPECT_THROW(grown_pool_capacity(101, 64, 100, kParameter), CapacityError);
}

TEST(TableCapacity, IsAPowerOfTwoWithTwoSlotsPerVoxel) {
  for (const std::size_t voxels : {1u, 7u, 8u, 9u, 1000u, 1u << 20}) {
    const std::size_t slots = table_capacity_for(voxels);
    EXPECT_EQ(slots & (slots - 1), 0u) << voxels;
    EXPECT_GE(slots, kSlotsPerVoxel * voxels) << voxels;
    EXPECT_LT(slots, 2 * kSlotsPerVoxel * voxels + 16) << voxels;
  }
}

TEST(Removal, RehashesWhenErasedSlotsExceedAQuarterOfTheTable) {
  PoolCounts c = pool(600, 0, 600);
  c.live_voxels = 600 - 512;  // 512 of 2048 slots erased: exactly a quarter
  EXPECT_FALSE(rehash_after_removal(c));
  c.live_voxels -= 1;
  EXPECT_TRUE(rehash_after_removal(c));
}

TEST(Removal, AppliesWithAFiniteRadiusToAUsedPool) {
  VoxelMapConfig config;
  EXPECT_TRUE(removal_applies(config, 1));
  EXPECT_FALSE(removal_applies(config, 0));
  config.removal_radius_m = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(removal_applies(config, 1));
  // the per-voxel test: only live voxels whose centre is beyond the radius
  const std::uint64_t key = pack_key(VoxelCoord(10, 0, 0));  // centre at x = 10.5 with 1 m voxels
  EXPECT_TRUE(voxel_is_far(key, Eigen::Vector3d::Zero(), 10.0 * 10.0, 1.0));
  EXPECT_FALSE(voxel_is_far(key, Eigen::Vector3d::Zero(), 11.0 * 11.0, 1.0));
  EXPECT_FALSE(voxel_is_far(kEmptyKey, Eigen::Vector3d::Zero(), 0.0, 1.0));
}

TEST(NewVoxelSlot, EqualsPoppingTheFreeListThenTheHighWaterMark) {
  const std::vector<std::int32_t> free_list{7, 3, 12, 5};
  for (std::size_t new_voxels : {0u, 2u, 4u, 9u}) {
    // reference: a stack popped from the back, then fresh slots
    std::vector<std::int32_t> stack = free_list;
    std::int32_t high_water = 20;
    std::vector<std::int32_t> expected;
    for (std::size_t i = 0; i < new_voxels; ++i) {
      if (!stack.empty()) {
        expected.push_back(stack.back());
        stack.pop_back();
      } else {
        expected.push_back(high_water++);
      }
    }
    const std::size_t reused = std::min(new_voxels, free_list.size());
    for (std::size_t r = 0; r < new_voxels; ++r) {
      EXPECT_EQ(new_voxel_slot(static_cast<std::int32_t>(r), free_list.data(), free_list.size(), reused, 20),
                expected[r])
          << "rank " << r << " of " << new_voxels;
    }
  }
}

TEST(CovariancePoints, NewPointsOrTheWholeChangedVoxel) {
  EXPECT_EQ(covariance_points(5, 5, true).size(), 0);  // unchanged voxel: nothing, even refreshing
  EXPECT_EQ(covariance_points(5, 5, false).size(), 0);
  const PointRange fresh = covariance_points(8, 5, false);
  EXPECT_EQ(fresh.begin, 5);
  EXPECT_EQ(fresh.end, 8);
  const PointRange all = covariance_points(8, 5, true);
  EXPECT_EQ(all.begin, 0);
  EXPECT_EQ(all.end, 8);
}
