#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>
#include <vector>

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

TEST(Config, TheDefaultsAreValidAndInsideTheirRanges) {
  Config c;
  EXPECT_NO_THROW(validate_config(c));
  for (const auto& f : config_fields(c)) {
    std::visit(
        [&](auto* p) {
          using T = std::remove_pointer_t<decltype(p)>;
          if constexpr (!std::is_same_v<T, bool> && !std::is_same_v<T, Device>) {
            EXPECT_TRUE(f.valid.contains(static_cast<double>(*p))) << f.name << " = " << *p;
            EXPECT_TRUE(f.valid.checked) << f.name << ": a number without a range";
          }
        },
        f.value);
  }
}

TEST(Config, NaNAndValuesBelowTheRangeAreRejectedForEveryNumericField) {
  Config c;
  for (const auto& f : config_fields(c)) {
    const std::string before = get_config_field(c, f.name);
    std::vector<std::string> bad;
    if (std::holds_alternative<double*>(f.value)) bad.push_back("nan");
    if (f.valid.checked && std::isfinite(f.valid.min)) {
      // the bound itself when it is excluded, else the integer just below it
      const double below = f.valid.min_exclusive ? f.valid.min : std::floor(f.valid.min) - 1.0;
      bad.push_back(std::to_string(static_cast<long long>(below)));
    }
    for (const std::string& value : bad) {
      try {
        set_config_field(c, f.name, value);
        ADD_FAILURE() << f.name << " accepted " << value;
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'" + f.name + "'"), std::string::npos) << e.what();
      }
      EXPECT_EQ(get_config_field(c, f.name), before) << f.name << ": a rejected value must not stick";
    }
  }
}

struct BadValue {
  const char* field;
  const char* value;
  const char* expected;  ///< what the message says about the range
};

std::ostream& operator<<(std::ostream& os, const BadValue& b) { return os << b.field << " = " << b.value; }

class ConfigBadValue : public ::testing::TestWithParam<BadValue> {};

TEST_P(ConfigBadValue, IsAnErrorNamingTheFieldAndItsRange) {
  const BadValue& b = GetParam();
  Config c;
  try {
    set_config_field(c, b.field, b.value);
    FAIL() << b.field << " = " << b.value << " was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(b.field), std::string::npos) << msg;
    EXPECT_NE(msg.find(b.expected), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Fields, ConfigBadValue,
    ::testing::Values(BadValue{"fusion.step_s", "0", "in [1e-04, 1]"}, BadValue{"map.voxel_size_m", "-4", "> 0"},
                      BadValue{"map.voxel_size_m", "inf", "> 0"}, BadValue{"preprocess.min_range_m", "nan", ">= 0"},
                      BadValue{"map.covariance_neighbors", "33", "in [1, 32]"},
                      BadValue{"registration.max_iterations", "0", ">= 1"},
                      BadValue{"fusion.reference_max_sin", "1.5", "in (0, 1]"}, BadValue{"num_threads", "-2", ">= 0"},
                      BadValue{"map.max_voxel_capacity", "0", "in [1, 2147483647]"},
                      BadValue{"fusion.gyro_bias_init_x_rad_s", "inf", "finite"}));

TEST(Config, InfinityMeansNoLimitWhereTheRangeSaysSo) {
  Config c;
  set_config_field(c, "map.removal_radius_m", "inf");
  set_config_field(c, "registration.time_budget_factor", "inf");
  set_config_field(c, "preprocess.max_range_m", "inf");
  EXPECT_TRUE(std::isinf(c.map.removal_radius_m));
  EXPECT_NO_THROW(validate_config(c));
  EXPECT_THROW(set_config_field(c, "map.removal_radius_m", "-inf"), std::invalid_argument);
}

TEST(Config, ValidateCatchesFieldsSetDirectlyAndRulesBetweenFields) {
  const auto message_of = [](const Config& c) -> std::string {
    try {
      validate_config(c);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  Config c;
  c.fusion.step_s = 0.0;
  EXPECT_NE(message_of(c).find("fusion.step_s"), std::string::npos);
  c = Config();
  c.map.covariance_epsilon = std::nan("");
  EXPECT_NE(message_of(c).find("map.covariance_epsilon"), std::string::npos);
  c = Config();
  c.preprocess.min_range_m = 300.0;
  EXPECT_NE(message_of(c).find("preprocess.min_range_m must be below preprocess.max_range_m"), std::string::npos);
  c = Config();
  c.fusion.reference_filter_taps = 10;
  EXPECT_NE(message_of(c).find("fusion.reference_filter_taps must be odd"), std::string::npos);
  c = Config();
  c.map.initial_voxel_capacity = c.map.max_voxel_capacity + 1;
  EXPECT_NE(message_of(c).find("map.initial_voxel_capacity"), std::string::npos);
  c = Config();
  c.map.voxel_size_m = 0.5;  // below auto_min_voxel_size_m while auto scaling is on
  EXPECT_NE(message_of(c).find("map.auto_min_voxel_size_m"), std::string::npos);
  c.map.auto_voxel_size = false;
  EXPECT_EQ(message_of(c), "");
}

TEST(Config, ValuesKeepTheirTypes) {
  Config c;
  EXPECT_EQ(std::get<int>(get_config_value(c, "num_threads")), 0);
  EXPECT_EQ(std::get<double>(get_config_value(c, "map.voxel_size_m")), 4.0);
  EXPECT_EQ(std::get<bool>(get_config_value(c, "density.enabled")), true);
  EXPECT_EQ(std::get<std::int64_t>(get_config_value(c, "map.max_voxel_capacity")), 1 << 20);
  EXPECT_EQ(std::get<Device>(get_config_value(c, "device")), Device::Auto);
}
