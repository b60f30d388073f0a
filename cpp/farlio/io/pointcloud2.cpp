#include "farlio/io/pointcloud2.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "farlio/core/error.hpp"

namespace farlio::io {
namespace {

constexpr std::int64_t kFirstDatatype = static_cast<std::int64_t>(PointFieldType::Int8);
constexpr std::int64_t kLastDatatype = static_cast<std::int64_t>(PointFieldType::Float64);
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

bool valid_datatype(std::int64_t d) { return d >= kFirstDatatype && d <= kLastDatatype; }

std::size_t datatype_bytes(PointFieldType t) {
  switch (t) {
    case PointFieldType::Int8:
    case PointFieldType::Uint8: return 1;
    case PointFieldType::Int16:
    case PointFieldType::Uint16: return 2;
    case PointFieldType::Int32:
    case PointFieldType::Uint32:
    case PointFieldType::Float32: return 4;
    case PointFieldType::Float64: return 8;
  }
  return 0;
}

/// Calls f(std::type_identity<T>{}, std::bool_constant<Swap>{}) with the C++ type of `type` and
/// whether its bytes are to be reversed (data in the other byte order than this machine's).
template <class F>
void dispatch(PointFieldType type, bool swap, F&& f) {
  const auto with_order = [&](auto tag) {
    if (swap) {
      f(tag, std::true_type{});
    } else {
      f(tag, std::false_type{});
    }
  };
  switch (type) {
    case PointFieldType::Int8: return with_order(std::type_identity<std::int8_t>{});
    case PointFieldType::Uint8: return with_order(std::type_identity<std::uint8_t>{});
    case PointFieldType::Int16: return with_order(std::type_identity<std::int16_t>{});
    case PointFieldType::Uint16: return with_order(std::type_identity<std::uint16_t>{});
    case PointFieldType::Int32: return with_order(std::type_identity<std::int32_t>{});
    case PointFieldType::Uint32: return with_order(std::type_identity<std::uint32_t>{});
    case PointFieldType::Float32: return with_order(std::type_identity<float>{});
    case PointFieldType::Float64: return with_order(std::type_identity<double>{});
  }
}

/// The value of type T stored at p (unaligned), its bytes reversed when Swap.
template <class T, bool Swap>
T load(const std::uint8_t* p) {
  T v;
  if constexpr (Swap && sizeof(T) > 1) {
    std::array<std::uint8_t, sizeof(T)> bytes;
    std::memcpy(bytes.data(), p, sizeof(T));
    std::reverse(bytes.begin(), bytes.end());
    std::memcpy(&v, bytes.data(), sizeof(T));
  } else {
    std::memcpy(&v, p, sizeof(T));
  }
  return v;
}

/// Where the points are in the data: `height` rows of `width` points, rows `row_step` apart.
struct Rows {
  const std::uint8_t* data = nullptr;
  std::size_t width = 0, height = 0, point_step = 0, row_step = 0;

  /// Calls f(index, first byte of the point) for every point, in data order.
  template <class F>
  void for_each(F&& f) const {
    std::size_t i = 0;
    for (std::size_t r = 0; r < height; ++r) {
      const std::uint8_t* row = data + r * row_step;
      for (std::size_t c = 0; c < width; ++c, ++i) f(i, row + c * point_step);
    }
  }
  /// The same for the points whose `keep` is nonzero (every point when `keep` is empty).
  template <class F>
  void for_each_kept(const std::vector<std::uint8_t>& keep, F&& f) const {
    if (keep.empty()) {
      for_each(f);
      return;
    }
    std::size_t k = 0;
    for_each([&](std::size_t i, const std::uint8_t* p) {
      if (keep[i]) f(k++, p);
    });
  }
};

struct Channel {
  PointFieldType type = PointFieldType::Float32;
  std::size_t offset = 0;
};

bool at_origin(const Vec3f& p) { return p.x() == 0.0f && p.y() == 0.0f && p.z() == 0.0f; }

/// x, y, z of one type: the points not at the origin; `keep` marks them when some are dropped.
template <class T, bool Swap>
void read_xyz(const Rows& rows, const std::array<Channel, 3>& xyz, std::vector<Vec3f>& out,
              std::vector<std::uint8_t>& keep) {
  out.resize(rows.width * rows.height);
  std::size_t kept = 0;
  rows.for_each([&](std::size_t i, const std::uint8_t* p) {
    const Vec3f v(static_cast<float>(load<T, Swap>(p + xyz[0].offset)),
                  static_cast<float>(load<T, Swap>(p + xyz[1].offset)),
                  static_cast<float>(load<T, Swap>(p + xyz[2].offset)));
    if (at_origin(v)) {
      if (keep.empty()) keep.assign(out.size(), 1);
      keep[i] = 0;
      return;
    }
    out[kept++] = v;
  });
  out.resize(kept);
}

/// One float column of every point (x, y or z of another type than the others).
template <class T, bool Swap>
void read_coordinate(const Rows& rows, std::size_t offset, std::vector<Vec3f>& out, int axis) {
  rows.for_each(
      [&](std::size_t i, const std::uint8_t* p) { out[i][axis] = static_cast<float>(load<T, Swap>(p + offset)); });
}

/// x, y, z of different types: column by column, then the points at the origin dropped.
void read_mixed_xyz(const Rows& rows, const std::array<Channel, 3>& xyz, bool swap, std::vector<Vec3f>& out,
                    std::vector<std::uint8_t>& keep) {
  out.resize(rows.width * rows.height);
  for (int axis = 0; axis < 3; ++axis) {
    dispatch(xyz[axis].type, swap, [&]<class T, bool Swap>(std::type_identity<T>, std::bool_constant<Swap>) {
      read_coordinate<T, Swap>(rows, xyz[axis].offset, out, axis);
    });
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (at_origin(out[i])) {
      if (keep.empty()) keep.assign(out.size(), 1);
      keep[i] = 0;
      continue;
    }
    out[kept++] = out[i];
  }
  out.resize(kept);
}

template <class T, bool Swap>
void read_intensity(const Rows& rows, std::size_t offset, const std::vector<std::uint8_t>& keep,
                    std::vector<float>& out) {
  rows.for_each_kept(
      keep, [&](std::size_t k, const std::uint8_t* p) { out[k] = static_cast<float>(load<T, Swap>(p + offset)); });
}

/// The time field of the kept points as offsets from the header stamp (see PointCloud2Request),
/// with the statistics of PointCloud2Points. The raw values (integers of at most 32 bits: exact in
/// a double) are gathered into offset_s and converted in place; integer absolute times in exact
/// integer ns. The conversion is monotonic, so the offsets' extremes are those of the raw values.
template <class T, bool Swap>
void read_time(const Rows& rows, std::size_t offset, const std::vector<std::uint8_t>& keep,
               const PointCloud2Request& request, PointCloud2Points& out) {
  static_assert(std::is_floating_point_v<T> || sizeof(T) <= sizeof(std::int32_t), "exact in a double");
  std::vector<double>& values = out.offset_s;
  values.resize(out.points.size());
  if (values.empty()) return;
  using Limits = std::numeric_limits<T>;
  T lo = Limits::has_infinity ? Limits::infinity() : Limits::max();
  T hi = Limits::has_infinity ? -Limits::infinity() : Limits::lowest();
  bool has_nan = false;
  rows.for_each_kept(keep, [&](std::size_t k, const std::uint8_t* p) {
    const T v = load<T, Swap>(p + offset);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    if constexpr (std::is_floating_point_v<T>) has_nan |= std::isnan(v);
    values[k] = static_cast<double>(v);
  });
  const double scale = static_cast<double>(request.time_ns_per_unit) / kNsPerS;
  out.time_min = has_nan ? kNan : static_cast<double>(lo);
  out.time_max = has_nan ? kNan : static_cast<double>(hi);
  out.absolute_time = out.time_min * scale > request.absolute_time_min_s;
  const auto to_offset = [&](double v) {
    if (!out.absolute_time) return v * scale;
    if constexpr (std::is_integral_v<T>) {  // unsigned: wraps (defined) instead of overflowing
      const std::uint64_t ns = static_cast<std::uint64_t>(static_cast<std::int64_t>(v)) *
                                   static_cast<std::uint64_t>(request.time_ns_per_unit) -
                               static_cast<std::uint64_t>(request.header_ns);
      return static_cast<double>(static_cast<std::int64_t>(ns)) / kNsPerS;
    } else {
      return v * scale - request.header_s;
    }
  };
  if (out.absolute_time) {
    for (double& v : values) v = to_offset(v);
  } else {
    for (double& v : values) v *= scale;
  }
  out.offset_min_s = has_nan ? kNan : to_offset(out.time_min);
  out.offset_max_s = has_nan ? kNan : to_offset(out.time_max);
}

std::string field_list(const std::vector<PointCloud2Field>& fields) {
  std::string s;
  for (const auto& f : fields) s += (s.empty() ? "" : ", ") + f.name;
  return s.empty() ? "none" : s;
}

const PointCloud2Field* find(const std::vector<PointCloud2Field>& fields, const std::string& name) {
  const auto it = std::find_if(fields.begin(), fields.end(), [&](const auto& f) { return f.name == name; });
  return it == fields.end() ? nullptr : &*it;
}

/// Every field has a known datatype and lies within a point.
void check_fields(const PointCloud2Layout& layout, const std::string& where) {
  for (const auto& f : layout.fields) {
    if (!valid_datatype(f.datatype)) {
      throw InputError(where + ": field '" + f.name + "' has datatype " + std::to_string(f.datatype) +
                       "; expected one of [1, 2, 3, 4, 5, 6, 7, 8] (sensor_msgs/PointField)");
    }
    if (f.offset < 0) {
      throw InputError(where + ": field '" + f.name + "' has a negative offset " + std::to_string(f.offset));
    }
    const auto bytes = static_cast<std::int64_t>(datatype_bytes(static_cast<PointFieldType>(f.datatype)));
    const std::int64_t count = std::max<std::int64_t>(f.count, 1);
    if (count > layout.point_step || f.offset + bytes * count > layout.point_step) {
      throw InputError(where + ": field '" + f.name + "' at offset " + std::to_string(f.offset) + " (" +
                       std::to_string(count) + " x " + std::to_string(bytes) + " bytes) extends past point_step " +
                       std::to_string(layout.point_step));
    }
  }
}

/// The rows of the data; throws when the data is shorter than the layout says.
Rows check_rows(const PointCloud2Layout& layout, std::span<const std::uint8_t> data, const std::string& where) {
  if (layout.width < 0 || layout.height < 0 || layout.point_step < 0 || layout.row_step < 0) {
    throw InputError(where + ": negative size in the layout (width " + std::to_string(layout.width) + ", height " +
                     std::to_string(layout.height) + ", point_step " + std::to_string(layout.point_step) +
                     ", row_step " + std::to_string(layout.row_step) + ")");
  }
  std::int64_t row_bytes = 0, rows_before = 0, needed = 0;
  bool overflow = __builtin_mul_overflow(layout.width, layout.point_step, &row_bytes);
  const std::int64_t row_step = layout.row_step ? layout.row_step : row_bytes;
  overflow = overflow || __builtin_mul_overflow(std::max<std::int64_t>(layout.height - 1, 0), row_step, &rows_before) ||
             __builtin_add_overflow(rows_before, row_bytes, &needed);
  if (!overflow && layout.height > 1 && row_step < row_bytes) {
    throw InputError(where + ": row_step " + std::to_string(row_step) + " is shorter than a row of " +
                     std::to_string(layout.width) + " points of " + std::to_string(layout.point_step) + " bytes");
  }
  if (layout.width == 0 || layout.height == 0) needed = 0;
  if (overflow || static_cast<std::uint64_t>(needed) > data.size()) {
    throw InputError(where + ": data holds " + std::to_string(data.size()) + " bytes but " +
                     std::to_string(layout.height) + " rows of " + std::to_string(layout.width) + " points need " +
                     (overflow ? std::string("more than can be addressed") : std::to_string(needed)) + " (row_step " +
                     std::to_string(row_step) + ", point_step " + std::to_string(layout.point_step) + "; truncated?)");
  }
  // an empty cloud has no rows: a row_step past the data must not even be added to its pointer
  // (fuzz_pointcloud2: width 0, height 2, row_step 2^63 - 255 passed the size check)
  if (layout.width == 0 || layout.height == 0) return Rows{data.data(), 0, 0, 0, 0};
  return Rows{data.data(), static_cast<std::size_t>(layout.width), static_cast<std::size_t>(layout.height),
              static_cast<std::size_t>(layout.point_step), static_cast<std::size_t>(row_step)};
}

/// The field `name` as a channel of one value per point; `what` names it in the errors.
Channel single_value(const PointCloud2Layout& layout, const std::string& name, const std::string& what,
                     const std::string& where) {
  const PointCloud2Field* f = find(layout.fields, name);
  if (f == nullptr) {
    throw InputError(where + ": no " + what + "'" + name + "' (fields: " + field_list(layout.fields) + ")");
  }
  if (f->count > 1) {
    throw InputError(where + ": " + what + "'" + name + "' has count " + std::to_string(f->count) + "; expected 1");
  }
  return {static_cast<PointFieldType>(f->datatype), static_cast<std::size_t>(f->offset)};
}

}  // namespace

PointCloud2Points decode_pointcloud2(const PointCloud2Layout& layout, std::span<const std::uint8_t> data,
                                     const PointCloud2Request& request, const std::string& where) {
  std::string missing;
  for (const char* c : {"x", "y", "z"}) {
    if (find(layout.fields, c) == nullptr) missing += (missing.empty() ? "'" : ", '") + std::string(c) + "'";
  }
  if (!missing.empty()) {
    throw InputError(where + ": PointCloud2 has no field " + missing + " (fields: " + field_list(layout.fields) +
                     "); expected x, y, z");
  }
  check_fields(layout, where);
  const Rows rows = check_rows(layout, data, where);
  const std::array<Channel, 3> xyz = {single_value(layout, "x", "field ", where),
                                      single_value(layout, "y", "field ", where),
                                      single_value(layout, "z", "field ", where)};
  const bool swap = layout.big_endian != (std::endian::native == std::endian::big);

  PointCloud2Points out;
  std::vector<std::uint8_t> keep;  // empty: every point kept
  if (xyz[0].type == xyz[1].type && xyz[0].type == xyz[2].type) {
    dispatch(xyz[0].type, swap, [&]<class T, bool Swap>(std::type_identity<T>, std::bool_constant<Swap>) {
      read_xyz<T, Swap>(rows, xyz, out.points, keep);
    });
  } else {
    read_mixed_xyz(rows, xyz, swap, out.points, keep);
  }
  if (!request.intensity_field.empty()) {
    const Channel c = single_value(layout, request.intensity_field, "intensity field ", where);
    out.intensity.resize(out.points.size());
    dispatch(c.type, swap, [&]<class T, bool Swap>(std::type_identity<T>, std::bool_constant<Swap>) {
      read_intensity<T, Swap>(rows, c.offset, keep, out.intensity);
    });
  }
  if (!request.time_field.empty()) {
    const Channel c = single_value(layout, request.time_field, "time field ", where);
    out.has_time = true;
    dispatch(c.type, swap, [&]<class T, bool Swap>(std::type_identity<T>, std::bool_constant<Swap>) {
      read_time<T, Swap>(rows, c.offset, keep, request, out);
    });
  }
  return out;
}

}  // namespace farlio::io
