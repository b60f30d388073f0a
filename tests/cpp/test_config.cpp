#include <gtest/gtest.h>

#include "farlio/core/config_fields.hpp"

using namespace farlio;

TEST(Config, EveryFieldRoundTripsThroughText) {
  Config c;
  for (const auto& f : config_fields(c)) {
    const std::string text = get_config_field(c, f.name);
    Config d;
    set_config_field(d, f.name, text);
    EXPECT_EQ(get_config_field(d, f.name), text) << f.name;
    EXPECT_FALSE(f.doc.empty()) << f.name;
  }
}

TEST(Config, SetChangesTheStructAndNamesUnknownFields) {
  Config c;
  set_config_field(c, "map.voxel_size_m", "2.5");
  set_config_field(c, "density.enabled", "false");
  set_config_field(c, "registration.max_iterations", "7");
  EXPECT_DOUBLE_EQ(c.map.voxel_size_m, 2.5);
  EXPECT_FALSE(c.density.enabled);
  EXPECT_EQ(c.registration.max_iterations, 7);
  try {
    set_config_field(c, "map.voxel_size", "1");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("map.voxel_size_m"), std::string::npos) << e.what();
  }
  EXPECT_THROW(set_config_field(c, "map.voxel_size_m", "abc"), std::invalid_argument);
  EXPECT_THROW(set_config_field(c, "density.enabled", "maybe"), std::invalid_argument);
}
