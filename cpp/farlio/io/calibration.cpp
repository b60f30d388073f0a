#include "farlio/io/file_bytes.hpp"
#include "farlio/io/calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/io/text_number.hpp"

namespace farlio::io {
namespace {

constexpr int kMatrixSize = 4;
constexpr double kRigidTolerance = 1e-4;  // max deviation of R^T R from I and of the last row

double scalar_value(const YAML::Node& node, const std::string& file, const std::string& key) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) throw InputError(file + ": key '" + key + "' is not finite");
    return v;
  } catch (const YAML::Exception&) {
    throw InputError(file + ": key '" + key + "' is not a number");
  }
}

SE3 read_matrix(const YAML::Node& node, const std::string& file, const std::string& key) {
  auto bad = [&](const std::string& what) { return InputError(file + ": key '" + key + "': " + what); };
  if (!node.IsSequence() || node.size() != kMatrixSize) throw bad("expected a 4x4 matrix as a list of 4 rows");
  Mat4d m;
  for (int r = 0; r < kMatrixSize; ++r) {
    const YAML::Node row = node[static_cast<std::size_t>(r)];
    if (!row.IsSequence() || row.size() != kMatrixSize) throw bad("row " + std::to_string(r) + " does not hold 4 numbers");
    for (int c = 0; c < kMatrixSize; ++c) {
      m(r, c) = scalar_value(row[static_cast<std::size_t>(c)], file, key + "[" + std::to_string(r) + "][" + std::to_string(c) + "]");
    }
  }
  const Eigen::RowVector4d last(0, 0, 0, 1);
  if ((m.row(3) - last).cwiseAbs().maxCoeff() > kRigidTolerance) throw bad("last row is not [0, 0, 0, 1]");
  const Mat3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Mat3d::Identity()).cwiseAbs().maxCoeff() > kRigidTolerance || R.determinant() < 0) {
    throw bad("the rotation block is not a rotation matrix");
  }
  return SE3::from_matrix(m);
}

double optional_rate(const YAML::Node& root, const char* section, const std::string& file) {
  const YAML::Node s = root[section];
  if (!s || !s.IsMap() || !s["rate_hz"]) return 0.0;
  return scalar_value(s["rate_hz"], file, std::string(section) + ".rate_hz");
}

}  // namespace

Calibration read_calibration(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(file + ": no such file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::Exception& e) {
    throw InputError(file + ": not valid YAML (" + e.what() + ")");
  }
  if (!root.IsMap()) throw InputError(file + ": expected a YAML mapping at the top level");
  Calibration c;
  if (!root["T_imu_lidar"]) throw InputError(file + ": missing key 'T_imu_lidar'");
  c.T_imu_lidar = read_matrix(root["T_imu_lidar"], file, "T_imu_lidar");
  if (root["gravity"]) c.gravity_m_s2 = scalar_value(root["gravity"], file, "gravity");
  c.imu_rate_hz = optional_rate(root, "imu", file);
  c.lidar_rate_hz = optional_rate(root, "lidar", file);
  return c;
}

void write_calibration(const std::filesystem::path& path, const Calibration& calib) {
  std::string text = "T_imu_lidar:  # 4x4 row-major, maps LiDAR-frame points into the IMU (body) frame\n";
  const Mat4d m = calib.T_imu_lidar.matrix();
  for (int r = 0; r < kMatrixSize; ++r) {
    text += "  - [";
    for (int c = 0; c < kMatrixSize; ++c) {
      if (c) text += ", ";
      text += format_number(m(r, c));
    }
    text += "]\n";
  }
  text += "gravity: " + format_number(calib.gravity_m_s2) + "\n";
  if (calib.imu_rate_hz > 0) text += "imu:\n  rate_hz: " + format_number(calib.imu_rate_hz) + "\n";
  if (calib.lidar_rate_hz > 0) text += "lidar:\n  rate_hz: " + format_number(calib.lidar_rate_hz) + "\n";
  write_text_file(path, text);
}

}  // namespace farlio::io
