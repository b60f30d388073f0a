#pragma once
// imu.csv of a sequence folder: header "t_ns,gx,gy,gz,ax,ay,az" (columns matched by name,
// unknown columns ignored with a warning), then one sample a line: rad/s and m/s^2.
#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include "farlio/core/types.hpp"

namespace farlio::io {

/// Reads the samples. A sample not strictly after the previous kept one is dropped with a
/// warning naming the file and line; a missing column, a wrong number of fields or a
/// non-numeric field throws InputError naming the file (and line).
[[nodiscard]] std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path,
                                                  std::vector<std::string>& warnings);
/// The same on text in memory (or any stream); `file` names it in errors and warnings.
[[nodiscard]] std::vector<ImuSample> parse_imu_csv(std::istream& in, const std::string& file,
                                                   std::vector<std::string>& warnings);
void write_imu_csv(const std::filesystem::path& path, const std::vector<ImuSample>& samples);

}  // namespace farlio::io
