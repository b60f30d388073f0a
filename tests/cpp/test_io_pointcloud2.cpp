// The PointCloud2 decoder: every datatype in both byte orders, padding inside points and after
// rows, points at the origin and NaN points, the time field as relative or absolute times, and a
// clear error for each bad layout. (tests/python/test_pointcloud2.py checks it, through
// farlio.datasets.pointcloud2.decode, against the numpy decoder it replaced.)
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "farlio/core/error.hpp"
#include "farlio/io/pointcloud2.hpp"
#include "io_test_util.hpp"

using namespace farlio;
using namespace farlio::io;

namespace {

constexpr std::int64_t kHeaderNs = 1'700'000'000'123'456'789;
constexpr double kAbsoluteTimeMinS = 1e6;  // as farlio.datasets.pointcloud2.ABSOLUTE_TIME_MIN_S
constexpr std::int64_t kNsPerUs = 1000;
const std::string kWhere = "/lidar msg 3";

std::size_t bytes_of(PointFieldType t) {
  switch (t) {
    case PointFieldType::Int8:
    case PointFieldType::Uint8: return 1;
    case PointFieldType::Int16:
    case PointFieldType::Uint16: return 2;
    case PointFieldType::Float64: return 8;
    default: return 4;
  }
}

/// Writes `v` as `type` at p, in big or little endian.
void store(std::uint8_t* p, PointFieldType type, double v, bool big_endian) {
  std::uint8_t buf[8];
  const auto put = [&](auto x) {
    std::memcpy(buf, &x, sizeof(x));
    if (big_endian != (std::endian::native == std::endian::big)) std::reverse(buf, buf + sizeof(x));
    std::memcpy(p, buf, sizeof(x));
  };
  switch (type) {
    case PointFieldType::Int8: return put(static_cast<std::int8_t>(v));
    case PointFieldType::Uint8: return put(static_cast<std::uint8_t>(v));
    case PointFieldType::Int16: return put(static_cast<std::int16_t>(v));
    case PointFieldType::Uint16: return put(static_cast<std::uint16_t>(v));
    case PointFieldType::Int32: return put(static_cast<std::int32_t>(v));
    case PointFieldType::Uint32: return put(static_cast<std::uint32_t>(v));
    case PointFieldType::Float32: return put(static_cast<float>(v));
    case PointFieldType::Float64: return put(v);
  }
}

using Fields = std::vector<std::pair<std::string, PointFieldType>>;

/// float32 x, y, z, then `more`.
Fields xyz_and(const Fields& more = {}) {
  Fields f = {{"x", PointFieldType::Float32}, {"y", PointFieldType::Float32}, {"z", PointFieldType::Float32}};
  f.insert(f.end(), more.begin(), more.end());
  return f;
}

/// A cloud of `width` x `height` points: fields one after the other, `padding` bytes after each
/// point, `row_padding` bytes (0xAB) after each row.
struct Cloud {
  PointCloud2Layout layout;
  std::vector<std::uint8_t> data;

  Cloud(const Fields& fields, std::int64_t width, std::int64_t height = 1, bool big_endian = false,
        std::int64_t padding = 0, std::int64_t row_padding = 0) {
    std::int64_t offset = 0;
    for (const auto& [name, type] : fields) {
      layout.fields.push_back({name, offset, static_cast<std::int64_t>(type), 1});
      offset += static_cast<std::int64_t>(bytes_of(type));
    }
    layout.width = width;
    layout.height = height;
    layout.point_step = offset + padding;
    layout.row_step = width * layout.point_step + row_padding;
    layout.big_endian = big_endian;
    data.assign(static_cast<std::size_t>(layout.row_step * height), 0xAB);
  }
  /// Sets field `name` of point i (row-major index).
  void set(std::int64_t i, const std::string& name, double v) {
    const auto& f = *std::find_if(layout.fields.begin(), layout.fields.end(), [&](auto& x) { return x.name == name; });
    const std::int64_t row = i / layout.width, col = i % layout.width;
    store(data.data() + row * layout.row_step + col * layout.point_step + f.offset,
          static_cast<PointFieldType>(f.datatype), v, layout.big_endian);
  }
  void set_xyz(std::int64_t i, double x, double y, double z) {
    set(i, "x", x);
    set(i, "y", y);
    set(i, "z", z);
  }
  [[nodiscard]] PointCloud2Points decode(const PointCloud2Request& r = {}) const {
    return decode_pointcloud2(layout, data, r, kWhere);
  }
};

PointCloud2Request time_request(const std::string& field, std::int64_t ns_per_unit) {
  PointCloud2Request r;
  r.time_field = field;
  r.time_ns_per_unit = ns_per_unit;
  r.header_ns = kHeaderNs;
  r.header_s = static_cast<double>(kHeaderNs) / kNsPerS;
  r.absolute_time_min_s = kAbsoluteTimeMinS;
  return r;
}

void expect_decode_error(const Cloud& c, const std::string& fragment, const PointCloud2Request& r = {}) {
  test::expect_input_error([&] { (void)c.decode(r); }, kWhere, fragment);
}

constexpr PointFieldType kAllTypes[] = {PointFieldType::Int8,    PointFieldType::Uint8,  PointFieldType::Int16,
                                        PointFieldType::Uint16,  PointFieldType::Int32,  PointFieldType::Uint32,
                                        PointFieldType::Float32, PointFieldType::Float64};

}  // namespace

TEST(PointCloud2, EveryDatatypeInBothByteOrdersWithPaddingAndRowPadding) {
  for (const PointFieldType xyz : kAllTypes) {
    const bool is_signed =
        xyz != PointFieldType::Uint8 && xyz != PointFieldType::Uint16 && xyz != PointFieldType::Uint32;
    const double y_sign = is_signed ? -1.0 : 1.0;
    for (const PointFieldType inten : kAllTypes) {
      for (const bool big : {false, true}) {
        SCOPED_TRACE(testing::Message() << "xyz " << int(xyz) << " intensity " << int(inten) << " big " << big);
        Cloud c({{"x", xyz}, {"y", xyz}, {"z", xyz}, {"intensity", inten}}, 5, 3, big, 3, 7);
        for (int i = 0; i < 15; ++i) {
          c.set_xyz(i, i + 1, y_sign * (i % 4 + 1), 2 * i + 1);  // small integers: exact in every type
          c.set(i, "intensity", 100 + i);
        }
        PointCloud2Request r;
        r.intensity_field = "intensity";
        const auto d = c.decode(r);
        ASSERT_EQ(d.points.size(), 15u);
        ASSERT_EQ(d.intensity.size(), 15u);
        EXPECT_FALSE(d.has_time);
        EXPECT_TRUE(d.offset_s.empty());
        for (int i = 0; i < 15; ++i) {
          EXPECT_EQ(d.points[i], Vec3f(i + 1, y_sign * (i % 4 + 1), 2 * i + 1)) << i;
          EXPECT_EQ(d.intensity[i], 100.0f + i) << i;
        }
      }
    }
  }
}

TEST(PointCloud2, CoordinatesOfDifferentTypes) {
  Cloud c({{"z", PointFieldType::Int16},
           {"pad", PointFieldType::Uint8},
           {"x", PointFieldType::Float64},
           {"y", PointFieldType::Float32}},
          4);
  c.set_xyz(0, 1.25, -2.5, 7);
  c.set_xyz(1, 0, 0, 0);  // no return
  c.set_xyz(2, 1e-3, 3.5, -4);
  c.set_xyz(3, 0, 0, 1);
  const auto d = c.decode();
  ASSERT_EQ(d.points.size(), 3u);
  EXPECT_EQ(d.points[0], Vec3f(1.25f, -2.5f, 7.0f));
  EXPECT_EQ(d.points[1], Vec3f(static_cast<float>(1e-3), 3.5f, -4.0f));  // double rounded to float
  EXPECT_EQ(d.points[2], Vec3f(0.0f, 0.0f, 1.0f));
}

TEST(PointCloud2, PointsAtTheOriginAreDroppedNanPointsKept) {
  Cloud c({{"x", PointFieldType::Float32},
           {"y", PointFieldType::Float32},
           {"z", PointFieldType::Float32},
           {"intensity", PointFieldType::Uint16},
           {"t", PointFieldType::Uint32}},
          6);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double xs[] = {1, 0, nan, 0, -0.0, 5};
  for (int i = 0; i < 6; ++i) {
    c.set_xyz(i, xs[i], 0, 0);
    c.set(i, "intensity", 10 * i);
    c.set(i, "t", 1000 * i);
  }
  auto r = time_request("t", 1);
  r.intensity_field = "intensity";
  const auto d = c.decode(r);
  ASSERT_EQ(d.points.size(), 3u);  // 1, NaN, 5; 0 and -0 dropped
  EXPECT_EQ(d.points[0].x(), 1.0f);
  EXPECT_TRUE(std::isnan(d.points[1].x()));
  EXPECT_EQ(d.points[2].x(), 5.0f);
  EXPECT_EQ(d.intensity, (std::vector<float>{0, 20, 50}));
  const double s_per_ns = 1.0 / kNsPerS;  // value x (ns per unit / ns per s), as numpy did
  EXPECT_EQ(d.offset_s, (std::vector<double>{0.0, 2000 * s_per_ns, 5000 * s_per_ns}));
  EXPECT_EQ(d.time_min, 0.0);  // over the kept points only
  EXPECT_EQ(d.time_max, 5000.0);
}

TEST(PointCloud2, RelativeTimesInTheirUnit) {
  struct Case {
    PointFieldType type;
    std::int64_t ns_per_unit;
    double scale;  // raw value per s
  };
  for (const Case k : {Case{PointFieldType::Uint32, 1, 1e9}, Case{PointFieldType::Uint32, kNsPerUs, 1e6},
                       Case{PointFieldType::Float32, 1'000'000'000, 1.0}, Case{PointFieldType::Float64, 1'000'000, 1e3},
                       Case{PointFieldType::Int32, 1, 1e9}}) {
    for (const bool big : {false, true}) {
      SCOPED_TRACE(testing::Message() << "type " << int(k.type) << " big " << big);
      Cloud c(xyz_and({{"time", k.type}}), 4, 1, big, 2);
      const double t_s[] = {-0.05, 0.0, 0.03125, 0.0625};  // binary fractions: exact where the type allows
      for (int i = 0; i < 4; ++i) {
        c.set_xyz(i, 1, 2, 3);
        c.set(i, "time", k.type == PointFieldType::Uint32 ? (t_s[i] + 0.05) * k.scale : t_s[i] * k.scale);
      }
      const auto d = c.decode(time_request("time", k.ns_per_unit));
      ASSERT_TRUE(d.has_time);
      EXPECT_FALSE(d.absolute_time);
      ASSERT_EQ(d.offset_s.size(), 4u);
      const double shift = k.type == PointFieldType::Uint32 ? 0.05 : 0.0;
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(d.offset_s[i], t_s[i] + shift, 1e-9) << i;
      EXPECT_NEAR(d.offset_min_s, t_s[0] + shift, 1e-9);
      EXPECT_NEAR(d.offset_max_s, t_s[3] + shift, 1e-9);
    }
  }
}

TEST(PointCloud2, AbsoluteTimesBecomeOffsetsFromTheHeader) {
  // float64 Unix seconds (Hesai, Robosense): ~0.2 us resolution
  Cloud f(xyz_and({{"timestamp", PointFieldType::Float64}}), 3);
  const double header_s = static_cast<double>(kHeaderNs) / kNsPerS;
  for (int i = 0; i < 3; ++i) {
    f.set_xyz(i, 1, 1, 1);
    f.set(i, "timestamp", header_s + 0.01 * i);
  }
  const auto df = f.decode(time_request("timestamp", 1'000'000'000));
  EXPECT_TRUE(df.absolute_time);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(df.offset_s[i], 0.01 * i, 5e-7) << i;

  // integer absolute times (here Unix seconds in a uint32) in exact integer ns arithmetic
  Cloud s(xyz_and({{"sec", PointFieldType::Uint32}}), 2);
  const std::int64_t header_sec = kHeaderNs / 1'000'000'000;
  for (int i = 0; i < 2; ++i) {
    s.set_xyz(i, 1, 1, 1);
    s.set(i, "sec", static_cast<double>(header_sec + i));
  }
  const auto ds = s.decode(time_request("sec", 1'000'000'000));
  EXPECT_TRUE(ds.absolute_time);
  // exact: (sec * 1e9 - header_ns) / 1e9 in integer ns
  EXPECT_EQ(ds.offset_s[0], static_cast<double>(header_sec * 1'000'000'000 - kHeaderNs) / kNsPerS);
  EXPECT_EQ(ds.offset_s[1], static_cast<double>((header_sec + 1) * 1'000'000'000 - kHeaderNs) / kNsPerS);
}

TEST(PointCloud2, NanTimesMakeNanStatistics) {
  Cloud c(xyz_and({{"t", PointFieldType::Float32}}), 3);
  for (int i = 0; i < 3; ++i) {
    c.set_xyz(i, 1, 1, 1);
    c.set(i, "t", i == 1 ? std::numeric_limits<double>::quiet_NaN() : 0.01 * i);
  }
  const auto d = c.decode(time_request("t", 1'000'000'000));
  EXPECT_TRUE(std::isnan(d.time_min));
  EXPECT_TRUE(std::isnan(d.time_max));
  EXPECT_TRUE(std::isnan(d.offset_min_s));
  EXPECT_FALSE(d.absolute_time);
}

TEST(PointCloud2, EmptyCloudAndDuplicateNames) {
  Cloud empty(xyz_and({{"t", PointFieldType::Uint32}}), 0);
  const auto e = empty.decode(time_request("t", 1));
  EXPECT_TRUE(e.points.empty());
  EXPECT_TRUE(e.has_time);
  EXPECT_TRUE(e.offset_s.empty());

  Cloud dup(xyz_and({{"x", PointFieldType::Float32}}), 1);
  store(dup.data.data(), PointFieldType::Float32, 4.0, false);       // the first x
  store(dup.data.data() + 12, PointFieldType::Float32, 9.0, false);  // the second x
  EXPECT_EQ(dup.decode().points.at(0).x(), 4.0f);
}

TEST(PointCloud2, AnEmptyCloudWithAHugeRowStepReadsNothing) {
  // found by fuzz_pointcloud2: width 0, two rows 2^63 - 255 bytes apart, no data passed the size
  // check and the row pointer was advanced past the data (undefined behaviour under UBSan)
  Cloud wide(xyz_and({{"t", PointFieldType::Uint32}}), 0, 2);
  wide.layout.row_step = std::numeric_limits<std::int64_t>::max() - 254;
  wide.data.clear();
  const auto d = wide.decode(time_request("t", 1));
  EXPECT_TRUE(d.points.empty() && d.offset_s.empty());
}

TEST(PointCloud2, BadLayoutsAreClearErrors) {
  const auto xyz_t = [] { return Cloud(xyz_and({{"t", PointFieldType::Uint32}}), 4, 2); };
  Cloud no_z({{"x", PointFieldType::Float32}, {"y", PointFieldType::Float32}, {"t", PointFieldType::Float32}}, 2);
  expect_decode_error(no_z, "PointCloud2 has no field 'z' (fields: x, y, t); expected x, y, z");
  Cloud none({}, 2);
  expect_decode_error(none, "no field 'x', 'y', 'z' (fields: none)");

  Cloud bad_type = xyz_t();
  bad_type.layout.fields[3].datatype = 9;
  expect_decode_error(bad_type, "field 't' has datatype 9; expected one of [1, 2, 3, 4, 5, 6, 7, 8]");

  Cloud past = xyz_t();
  past.layout.fields[3].offset = 14;
  expect_decode_error(past, "field 't' at offset 14 (1 x 4 bytes) extends past point_step 16");
  Cloud past_count = xyz_t();
  past_count.layout.fields[3].count = 2;
  expect_decode_error(past_count, "field 't' at offset 12 (2 x 4 bytes) extends past point_step 16");
  Cloud negative = xyz_t();
  negative.layout.fields[1].offset = -4;
  expect_decode_error(negative, "field 'y' has a negative offset -4");

  Cloud vector_x(xyz_and(), 2);
  vector_x.layout.fields[0].count = 3;  // x, y, z as one field of 3: the x field's count
  vector_x.layout.point_step = 12;
  expect_decode_error(vector_x, "field 'x' has count 3; expected 1");

  Cloud z_count = xyz_t();
  z_count.layout.fields[2].count = 2;  // z spans z and t
  expect_decode_error(z_count, "field 'z' has count 2; expected 1");
  Cloud time_count(xyz_and({{"t", PointFieldType::Uint32}}), 2, 1, false, 4);
  time_count.layout.fields[3].count = 2;
  expect_decode_error(time_count, "time field 't' has count 2; expected 1", time_request("t", 1));

  Cloud short_data = xyz_t();
  short_data.data.resize(short_data.data.size() - 1);
  expect_decode_error(short_data, "data holds 127 bytes but 2 rows of 4 points need 128 (row_step 64, point_step 16");
  Cloud overlapping = xyz_t();
  overlapping.layout.row_step = 32;
  expect_decode_error(overlapping, "row_step 32 is shorter than a row of 4 points of 16 bytes");
  Cloud huge = xyz_t();
  huge.layout.width = std::int64_t{1} << 62;
  expect_decode_error(huge, "need more than can be addressed");
  Cloud negative_width = xyz_t();
  negative_width.layout.width = -1;
  expect_decode_error(negative_width, "negative size in the layout (width -1");

  expect_decode_error(xyz_t(), "no time field 'stamp' (fields: x, y, z, t)", time_request("stamp", 1));
  PointCloud2Request inten;
  inten.intensity_field = "intensity";
  expect_decode_error(xyz_t(), "no intensity field 'intensity'", inten);
}
