#include "farlio/io/calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "farlio/core/config_fields.hpp"
#include "farlio/core/error.hpp"
#include "farlio/io/file_bytes.hpp"
#include "farlio/io/rigid_transform.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr int kMatrixSize = 4;
constexpr const char* kExtrinsicKey = "T_imu_lidar";

double scalar_value(const YAML::Node& node, const std::string& file, const std::string& key) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) throw InputError(file + ": key '" + key + "' is not finite");
    return v;
  } catch (const YAML::Exception&) {
    throw InputError(file + ": key '" + key + "' is not a number");
  }
}

/// `gravity`: its magnitude in m/s^2 (validate_gravity), not a vector.
double gravity_value(const YAML::Node& node, const std::string& file) {
  const std::string what = file + ": key 'gravity'";
  if (!node.IsScalar()) {
    throw InputError(what + ": expected the magnitude of gravity in m/s^2 (one number, about 9.8), got a " +
                     (node.IsSequence() ? "list" : "mapping") + "; the direction comes from the accelerometer");
  }
  const double g = scalar_value(node, file, "gravity");
  try {
    validate_gravity(g, what);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return g;
}

/// A rigid transform written as a 4x4 row-major nested list under `key`.
SE3 extrinsic_value(const YAML::Node& node, const std::string& file, const std::string& key) {
  const std::string what = file + ": key '" + key + "'";
  if (!node.IsSequence() || node.size() != kMatrixSize) {
    throw InputError(what + ": expected a 4x4 matrix as a list of 4 rows");
  }
  Mat4d m;
  for (int r = 0; r < kMatrixSize; ++r) {
    const YAML::Node row = node[static_cast<std::size_t>(r)];
    if (!row.IsSequence() || row.size() != kMatrixSize) {
      throw InputError(what + ": row " + std::to_string(r) + " does not hold 4 numbers");
    }
    for (int c = 0; c < kMatrixSize; ++c) {
      const std::string element = key + "[" + std::to_string(r) + "][" + std::to_string(c) + "]";
      m(r, c) = scalar_value(row[static_cast<std::size_t>(c)], file, element);
    }
  }
  return rigid_transform_from_matrix(m, what);
}

/// The mapping form of T_imu_lidar: LiDAR topic or frame id -> 4x4 matrix.
std::map<std::string, SE3> extrinsics_by_name(const YAML::Node& node, const std::string& file) {
  std::map<std::string, SE3> out;
  for (const auto& entry : node) {
    if (!entry.first.IsScalar()) {
      throw InputError(file + ": key '" + kExtrinsicKey + "': an entry's name is not a LiDAR topic or frame id");
    }
    const std::string name = entry.first.Scalar();
    out[name] = extrinsic_value(entry.second, file, std::string(kExtrinsicKey) + "[" + name + "]");
  }
  if (out.empty()) throw InputError(file + ": key '" + kExtrinsicKey + "': the mapping has no entry");
  return out;
}

double optional_rate(const YAML::Node& root, const char* section, const std::string& file) {
  const YAML::Node s = root[section];
  if (!s || !s.IsMap() || !s["rate_hz"]) return 0.0;
  return scalar_value(s["rate_hz"], file, std::string(section) + ".rate_hz");
}

/// The rows of `pose`'s matrix as YAML flow lists, one per line, each line starting with `indent`.
std::string matrix_text(const SE3& pose, const std::string& indent) {
  const Mat4d m = pose.matrix();
  std::string text;
  for (int r = 0; r < kMatrixSize; ++r) {
    text += indent + "- [";
    for (int c = 0; c < kMatrixSize; ++c) {
      if (c) text += ", ";
      text += format_number(m(r, c));
    }
    text += "]\n";
  }
  return text;
}

/// `name` as a YAML double-quoted scalar (any topic or frame id survives the round trip).
std::string quoted(const std::string& name) {
  YAML::Emitter out;
  out << YAML::DoubleQuoted << name;
  return out.c_str();
}

std::string extrinsics_text(const Calibration& calib) {
  std::string text =
      std::string(kExtrinsicKey) + ":  # 4x4 row-major, maps LiDAR-frame points into the IMU (body) frame";
  if (calib.T_imu_lidar_by_name.empty()) return text + "\n" + matrix_text(calib.T_imu_lidar, "  ");
  text += ", per LiDAR topic or frame id\n";
  for (const auto& [name, pose] : calib.T_imu_lidar_by_name) {
    text += "  " + quoted(name) + ":\n" + matrix_text(pose, "    ");
  }
  return text;
}

/// "'a' or 'b'" / "a, b": the names a lookup tried and the entries it had.
std::string joined(const std::vector<std::string>& names, const std::string& separator, bool quote) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : separator) + (quote ? "'" + n + "'" : n);
  return out;
}

}  // namespace

const SE3& Calibration::lidar_extrinsic(const std::vector<std::string>& names) const {
  if (T_imu_lidar_by_name.empty()) return T_imu_lidar;
  for (const auto& name : names) {
    if (const auto it = T_imu_lidar_by_name.find(name); it != T_imu_lidar_by_name.end()) return it->second;
  }
  std::vector<std::string> entries;
  for (const auto& entry : T_imu_lidar_by_name) entries.push_back(entry.first);
  throw InputError(source.string() + ": " + kExtrinsicKey + " has no entry for " + joined(names, " or ", true) +
                   " (entries: " + joined(entries, ", ", false) + ")");
}

Calibration read_calibration(const std::filesystem::path& path) {
  const Bytes bytes = read_file_bytes(path);
  return parse_calibration(std::string(bytes.begin(), bytes.end()), path);
}

Calibration parse_calibration(const std::string& text, const std::filesystem::path& path) {
  const std::string file = path.string();
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file + ": not valid YAML (" + e.what() + ")");
  }
  if (!root.IsMap()) throw InputError(file + ": expected a YAML mapping at the top level");
  const YAML::Node extrinsic = root[kExtrinsicKey];
  if (!extrinsic) throw InputError(file + ": missing key '" + kExtrinsicKey + "'");
  Calibration c;
  c.source = path;
  if (extrinsic.IsMap()) {
    c.T_imu_lidar_by_name = extrinsics_by_name(extrinsic, file);
  } else {
    c.T_imu_lidar = extrinsic_value(extrinsic, file, kExtrinsicKey);
  }
  if (root["gravity"]) c.gravity_m_s2 = gravity_value(root["gravity"], file);
  c.imu_rate_hz = optional_rate(root, "imu", file);
  c.lidar_rate_hz = optional_rate(root, "lidar", file);
  return c;
}

void write_calibration(const std::filesystem::path& path, const Calibration& calib) {
  std::string text = extrinsics_text(calib);
  if (calib.gravity_m_s2) text += "gravity: " + format_number(*calib.gravity_m_s2) + "\n";
  if (calib.imu_rate_hz > 0) text += "imu:\n  rate_hz: " + format_number(calib.imu_rate_hz) + "\n";
  if (calib.lidar_rate_hz > 0) text += "lidar:\n  rate_hz: " + format_number(calib.lidar_rate_hz) + "\n";
  write_text_file(path, text);
}

}  // namespace farlio::io
