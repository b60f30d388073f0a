// Binding of the sensor_msgs/PointCloud2 decoder (farlio/io/pointcloud2.hpp) into farlio._core.io:
// the message's data buffer and layout in, numpy views of the decoded arrays out (no copy; a view
// keeps its PointCloud2Points alive). farlio.datasets.pointcloud2.decode is its one caller.
#include "farlio/io/pointcloud2.hpp"

#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <tuple>

#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace farlio::python {
namespace {

using io::PointCloud2Points;
using Bytes = nb::ndarray<const std::uint8_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
/// (name, offset, datatype, count) of a sensor_msgs/PointField
using FieldTuple = std::tuple<std::string, std::int64_t, std::int64_t, std::int64_t>;

PointCloud2Points decode(const Bytes& data, std::int64_t width, std::int64_t height, std::int64_t point_step,
                         std::int64_t row_step, bool big_endian, const std::vector<FieldTuple>& fields,
                         const std::string& intensity_field, const std::string& time_field,
                         std::int64_t time_ns_per_unit, std::int64_t header_ns, double header_s,
                         double absolute_time_min_s, const std::string& where) {
  io::PointCloud2Layout layout{width, height, point_step, row_step, big_endian, {}};
  layout.fields.reserve(fields.size());
  for (const auto& [name, offset, datatype, count] : fields) layout.fields.push_back({name, offset, datatype, count});
  const io::PointCloud2Request request{intensity_field, time_field, time_ns_per_unit,
                                       header_ns,       header_s,   absolute_time_min_s};
  nb::gil_scoped_release unlocked;  // the arguments are C++ values now; `data` is held by the caller
  return io::decode_pointcloud2(layout, {data.data(), data.shape(0)}, request, where);
}

}  // namespace

void bind_pointcloud2(nb::module_& m) {
  nb::class_<PointCloud2Points>(m, "PointCloud2Points",
                                "A decoded sensor_msgs/PointCloud2: points not at the origin, their intensities and "
                                "time offsets from the header stamp (numpy views)")
      .def_prop_ro(
          "points", [](nb::handle self) { return points_view(nb::cast<PointCloud2Points&>(self).points, self); },
          "(N, 3) float32")
      .def_prop_ro(
          "intensity", [](nb::handle self) { return vector_view(nb::cast<PointCloud2Points&>(self).intensity, self); },
          "(N,) float32 (empty without an intensity field)")
      .def_prop_ro(
          "offset_s", [](nb::handle self) { return vector_view(nb::cast<PointCloud2Points&>(self).offset_s, self); },
          "(N,) float64: per-point time minus the header stamp in s (empty without a time field)")
      .def_ro("has_time", &PointCloud2Points::has_time)
      .def_ro("absolute_time", &PointCloud2Points::absolute_time, "the time field holds absolute times")
      .def_ro("time_min", &PointCloud2Points::time_min, "smallest raw time value (NaN if one is NaN)")
      .def_ro("time_max", &PointCloud2Points::time_max, "largest raw time value (NaN if one is NaN)")
      .def_ro("offset_min_s", &PointCloud2Points::offset_min_s)
      .def_ro("offset_max_s", &PointCloud2Points::offset_max_s);
  m.def("decode_pointcloud2", &decode, "data"_a, "width"_a, "height"_a, "point_step"_a, "row_step"_a, "big_endian"_a,
        "fields"_a, "intensity_field"_a, "time_field"_a, "time_ns_per_unit"_a, "header_ns"_a, "header_s"_a,
        "absolute_time_min_s"_a, "where"_a,
        "Decodes the data of a sensor_msgs/PointCloud2 (uint8 buffer) laid out as width, height, point_step, "
        "row_step, big_endian and fields [(name, offset, datatype, count)]: x, y, z and the named intensity and "
        "time fields ('' for none), the time field as offsets from the header stamp (a value v is an absolute "
        "time when min(v) * time_ns_per_unit / 1e9 > absolute_time_min_s). Points at the origin are dropped. "
        "InputError starting with `where` for a missing field, a bad layout or short data.");
}

}  // namespace farlio::python
