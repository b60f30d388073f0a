#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "farlio/core/config_fields.hpp"
#include "farlio/io/calibration.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

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

TEST(Config, FusionSubSectionsAreThreeLevelNames) {
  Config c;
  set_config_field(c, "fusion.reference_angles.roll_std_rad", "0.2");
  set_config_field(c, "fusion.bias.estimate", "false");
  set_config_field(c, "fusion.units.accel_samples", "20");
  EXPECT_DOUBLE_EQ(c.fusion.reference_angles.roll_std_rad, 0.2);
  EXPECT_FALSE(c.fusion.bias.estimate);
  EXPECT_EQ(c.fusion.units.accel_samples, 20);
  EXPECT_EQ(get_config_field(c, "fusion.reference_angles.roll_std_rad"), "0.2");
}

TEST(Config, ARenamedFieldIsUnknownAndItsErrorNamesTheNewName) {
  const auto& renamed = renamed_config_fields();
  ASSERT_EQ(renamed.size(), 39u);
  for (const auto& [old_name, new_name] : renamed) {
    Config c;
    EXPECT_NO_THROW(get_config_field(c, std::string(new_name))) << new_name;
    try {
      set_config_field(c, std::string(old_name), "1");
      ADD_FAILURE() << old_name << " was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string expected =
          "unknown config field '" + std::string(old_name) + "' (renamed to " + std::string(new_name) + ")";
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
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

INSTANTIATE_TEST_SUITE_P(Fields, ConfigBadValue,
                         ::testing::Values(BadValue{"fusion.step_s", "0", "in [1e-04, 1]"},
                                           BadValue{"map.voxel_size_m", "-4", "in [0.01, 100]"},
                                           BadValue{"map.voxel_size_m", "inf", "in [0.01, 100]"},
                                           BadValue{"preprocess.min_range_m", "nan", "in [0, 10000]"},
                                           BadValue{"map.covariance_neighbors", "33", "in [1, 32]"},
                                           BadValue{"registration.max_iterations", "0", "in [1, 1e+06]"},
                                           BadValue{"fusion.reference_angles.max_sin", "1.5", "in (0, 1]"},
                                           BadValue{"num_threads", "-2", "in [0, 1024]"},
                                           BadValue{"map.max_voxel_capacity", "0", "in [1, 2147483647]"},
                                           BadValue{"fusion.bias.gyro_init_x_rad_s", "inf", "in [-1, 1]"},
                                           BadValue{"fusion.history_s", "1e12", "in (0, 60]"},
                                           BadValue{"fusion.imu_gate.gap_limit_s", "1e15", "in (0, 60]"},
                                           BadValue{"preprocess.max_range_m", "0", "in (0, 10000] or inf"}));

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
  EXPECT_NE(message_of(c).find("preprocess.min_range_m (300) must be below preprocess.max_range_m (200)"),
            std::string::npos);
  c = Config();
  c.fusion.reference_angles.filter_taps = 10;
  EXPECT_NE(message_of(c).find("fusion.reference_angles.filter_taps must be odd"), std::string::npos);
  c = Config();
  c.map.initial_voxel_capacity = c.map.max_voxel_capacity + 1;
  EXPECT_NE(message_of(c).find("map.initial_voxel_capacity"), std::string::npos);
  c = Config();
  c.map.voxel_size_m = 0.4;  // below auto_min_voxel_size_m while auto scaling is on
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

namespace {

/// The values every numeric field is tried with: zero, negatives, NaN, the infinities, huge
/// values, and each side of its own bounds.
std::vector<double> probe_values(const FieldRange& r) {
  std::vector<double> v{0.0, -1.0, -1e-9, std::nan(""), range::kInf, -range::kInf, 1e300, 1e12, 0.5, 1.0};
  for (double bound : {r.min, r.max}) {
    if (!std::isfinite(bound)) continue;
    v.push_back(bound);
    v.push_back(std::nextafter(bound, range::kInf));
    v.push_back(std::nextafter(bound, -range::kInf));
    v.push_back(bound + 1.0);
    v.push_back(bound - 1.0);
  }
  return v;
}

template <typename T>
bool representable(double v) {
  if constexpr (std::is_same_v<T, double>) {
    return true;
  } else {
    return std::isfinite(v) && v == std::floor(v) && v >= static_cast<double>(std::numeric_limits<T>::min()) &&
           v <= static_cast<double>(std::numeric_limits<T>::max());
  }
}

}  // namespace

TEST(Config, EveryNumericFieldHasAFiniteRangeAndRefusesEveryValueOutsideIt) {
  Config defaults;
  int probed = 0;
  for (const auto& f : config_fields(defaults)) {
    std::visit(
        [&](auto* p) {
          using T = std::remove_pointer_t<decltype(p)>;
          if constexpr (!std::is_same_v<T, bool> && !std::is_same_v<T, Device>) {
            ASSERT_TRUE(f.valid.checked) << f.name;
            EXPECT_TRUE(std::isfinite(f.valid.min)) << f.name << ": no lower bound";
            EXPECT_TRUE(std::isfinite(f.valid.max)) << f.name << ": no upper bound (inf may be allowed explicitly)";
            for (const double v : probe_values(f.valid)) {
              if (!representable<T>(v)) continue;  // an int field cannot hold it (parsing refuses it)
              const bool valid = f.valid.contains(v);
              // through the text form (the CLI's --set, YAML, Python)
              Config c;
              const std::string text = get_config_field(c, f.name);
              std::ostringstream value;
              value.precision(17);
              value << static_cast<T>(v);
              try {
                set_config_field(c, f.name, value.str());
                EXPECT_TRUE(valid) << f.name << " accepted " << value.str();
              } catch (const std::invalid_argument& e) {
                const std::string msg = e.what();
                EXPECT_FALSE(valid) << f.name << " refused " << value.str() << ": " << msg;
                EXPECT_NE(msg.find("'" + f.name + "'"), std::string::npos) << msg;
                EXPECT_NE(msg.find(f.valid.describe()), std::string::npos) << "no allowed range in: " << msg;
                EXPECT_NE(msg.find(", got "), std::string::npos) << "no value in: " << msg;
                EXPECT_EQ(get_config_field(c, f.name), text) << f.name << ": a refused value must not stick";
              }
              // set directly in the struct (C++ users): validate_config and the constructors
              Config direct;
              for (const auto& g : config_fields(direct)) {
                if (g.name == f.name) *std::get<T*>(g.value) = static_cast<T>(v);
              }
              if (!valid) {
                try {
                  validate_config(direct);
                  ADD_FAILURE() << "validate_config accepted " << f.name << " = " << v;
                } catch (const std::invalid_argument& e) {
                  EXPECT_NE(std::string(e.what()).find(f.name), std::string::npos) << e.what();
                }
              }
              ++probed;
            }
          }
        },
        f.value);
  }
  EXPECT_GT(probed, 500);
}

TEST(Gravity, OnlyAMagnitudeNearEarthsIsAccepted) {
  for (const double g : {9.81, 9.80665, 9.78, 9.83}) EXPECT_NO_THROW(validate_gravity(g, "gravity_m_s2")) << g;
  for (const double g : {-9.81, 0.0, 1.0, 98.1, std::nan(""), range::kInf}) {
    try {
      validate_gravity(g, "calib.yaml: key 'gravity'");
      ADD_FAILURE() << "gravity " << g << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("calib.yaml: key 'gravity'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("magnitude of gravity in m/s^2, about 9.8"), std::string::npos) << msg;
    }
  }
}

TEST(Gravity, CalibrationFilesGiveAMagnitude) {
  test::TempDir tmp;
  const auto p = tmp.path() / "calib.yaml";
  const std::string identity = "T_imu_lidar:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n";
  test::write_raw(p, identity + "gravity: [0, 0, -9.81]\n");
  test::expect_input_error(
      [&] { (void)io::read_calibration(p); }, p,
      "key 'gravity': expected the magnitude of gravity in m/s^2 (one number, about 9.8), got a list");
  test::write_raw(p, identity + "gravity: -9.81\n");
  test::expect_input_error([&] { (void)io::read_calibration(p); }, p,
                           "(no sign: the direction comes from the accelerometer)");
  for (const char* g : {"0", "1.0", "981"}) {
    test::write_raw(p, identity + "gravity: " + g + "\n");
    test::expect_input_error([&] { (void)io::read_calibration(p); }, p, "in [9.5, 10.2]");
  }
  test::write_raw(p, identity + "gravity: 9.79\n");
  EXPECT_EQ(io::read_calibration(p).gravity_m_s2, 9.79);
}
