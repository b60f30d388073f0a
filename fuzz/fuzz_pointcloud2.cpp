// libFuzzer target: the PointCloud2 decoder of the bag loader and the ROS 2 node
// (decode_pointcloud2). The input's tail gives the layout (width, height, steps, byte order, up to
// 8 fields with any name, offset, datatype and count) and the request (intensity and time fields,
// the time unit, the header stamp), its head the message's data. With the first flag set the
// layout is the common one (x y z intensity float32, t float64) and only its size, byte order and
// the data vary, so mutations also reach the decoding of well-formed clouds.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "farlio/io/pointcloud2.hpp"
#include "fuzz_support.hpp"

namespace {

using farlio::io::PointCloud2Field;
using farlio::io::PointCloud2Layout;
using farlio::io::PointCloud2Request;

constexpr std::array<const char*, 8> kNames = {"x", "y", "z", "intensity", "t", "time", "ring", ""};
constexpr std::array<std::int64_t, 5> kNsPerUnit = {1, 1000, 1000000, 1000000000, 0};
constexpr int kMaxFields = 8;
constexpr std::int64_t kMaxDimension = 1 << 16;  // width, height of the drawn layouts
constexpr std::int64_t kMaxStep = 1 << 10;
// the common layout: x y z intensity (float32) t (float64)
constexpr std::int64_t kCommonStep = 24;
constexpr std::int64_t kFloat32 = 7, kFloat64 = 8;

PointCloud2Layout common_layout(FuzzedDataProvider& in, std::size_t data_size) {
  PointCloud2Layout l;
  l.point_step = kCommonStep;
  l.width = in.ConsumeIntegralInRange<std::int64_t>(0, static_cast<std::int64_t>(data_size) / kCommonStep + 1);
  l.height = 1;
  l.big_endian = in.ConsumeBool();
  l.fields = {{"x", 0, kFloat32, 1},
              {"y", 4, kFloat32, 1},
              {"z", 8, kFloat32, 1},
              {"intensity", 12, kFloat32, 1},
              {"t", 16, kFloat64, 1}};
  return l;
}

PointCloud2Layout drawn_layout(FuzzedDataProvider& in) {
  PointCloud2Layout l;
  // mostly small values, sometimes anything (overflow of width x height x step)
  const bool wild = in.ConsumeBool();
  l.width = wild ? in.ConsumeIntegral<std::int64_t>() : in.ConsumeIntegralInRange<std::int64_t>(0, kMaxDimension);
  l.height = wild ? in.ConsumeIntegral<std::int64_t>() : in.ConsumeIntegralInRange<std::int64_t>(0, 4);
  l.point_step = wild ? in.ConsumeIntegral<std::int64_t>() : in.ConsumeIntegralInRange<std::int64_t>(0, kMaxStep);
  l.row_step = in.ConsumeBool() ? 0 : in.ConsumeIntegral<std::int64_t>();
  l.big_endian = in.ConsumeBool();
  const int fields = in.ConsumeIntegralInRange<int>(0, kMaxFields);
  for (int f = 0; f < fields; ++f) {
    PointCloud2Field field;
    field.name = kNames[in.ConsumeIntegralInRange<std::size_t>(0, kNames.size() - 1)];
    field.offset = in.ConsumeIntegralInRange<std::int64_t>(-4, kMaxStep + 8);
    field.datatype = in.ConsumeIntegralInRange<std::int64_t>(-1, 10);
    field.count = in.ConsumeIntegralInRange<std::int64_t>(-1, 3);
    l.fields.push_back(field);
  }
  return l;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace farlio;
  FuzzedDataProvider in(data, size);
  const bool common = in.ConsumeBool();
  PointCloud2Layout layout = common ? common_layout(in, size) : drawn_layout(in);
  PointCloud2Request request;
  request.intensity_field = in.ConsumeBool() ? "intensity" : "";
  request.time_field = in.ConsumeBool() ? (in.ConsumeBool() ? "t" : "time") : "";
  request.time_ns_per_unit = kNsPerUnit[in.ConsumeIntegralInRange<std::size_t>(0, kNsPerUnit.size() - 1)];
  request.header_ns = in.ConsumeIntegral<std::int64_t>();
  request.header_s = static_cast<double>(request.header_ns) / 1e9;
  request.absolute_time_min_s = in.ConsumeFloatingPoint<double>();
  const std::vector<std::uint8_t> bytes = in.ConsumeRemainingBytes<std::uint8_t>();
  fuzz::expect_input_error_or_success([&] {
    const io::PointCloud2Points out = io::decode_pointcloud2(layout, bytes, request, fuzz::kInputName);
    const std::size_t n = out.points.size();
    // never more points than the layout holds, and every channel one value a point
    FARLIO_FUZZ_CHECK(layout.width >= 0 && layout.height >= 0);
    FARLIO_FUZZ_CHECK(static_cast<double>(n) <= static_cast<double>(layout.width) * static_cast<double>(layout.height));
    FARLIO_FUZZ_CHECK(out.intensity.empty() || out.intensity.size() == n);
    FARLIO_FUZZ_CHECK(out.offset_s.empty() || out.offset_s.size() == n);
    FARLIO_FUZZ_CHECK(!out.has_time || !request.time_field.empty());
    FARLIO_FUZZ_CHECK(request.intensity_field.empty() || out.intensity.size() == n);
  });
  return 0;
}
