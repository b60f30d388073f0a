#pragma once
// Helpers for the I/O tests: random scans, raw file writing, error-message checks.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "farlio/core/error.hpp"
#include "farlio/core/types.hpp"

namespace farlio::test {

inline Scan random_scan(std::size_t n, unsigned seed, bool with_intensity = true, bool with_time = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(-100.0f, 100.0f), unit(0.0f, 1.0f);
  Scan s;
  for (std::size_t i = 0; i < n; ++i) {
    s.points.emplace_back(coord(rng), coord(rng), coord(rng));
    if (with_intensity) s.intensity.push_back(unit(rng) * 255.0f);
    if (with_time) s.time_s.push_back(unit(rng) * 0.1f);
  }
  return s;
}

inline void write_raw(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string read_raw(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <class T>
void append_binary(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// Asserts that `f` throws InputError whose message names `file` (and contains `fragment`).
template <class F>
void expect_input_error(F&& f, const std::filesystem::path& file, const std::string& fragment = "") {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown for " << file;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << "message does not name the file: " << msg;
    if (!fragment.empty()) {
      EXPECT_NE(msg.find(fragment), std::string::npos) << "message: " << msg;
    }
  }
}

inline void expect_bit_equal(const Scan& a, const Scan& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.intensity.size(), b.intensity.size());
  ASSERT_EQ(a.time_s.size(), b.time_s.size());
  ASSERT_EQ(a.sensor_id.size(), b.sensor_id.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.points[i], b.points[i]) << "point " << i;
    if (!a.intensity.empty()) {
      ASSERT_EQ(a.intensity[i], b.intensity[i]) << "point " << i;
    }
    if (!a.time_s.empty()) {
      ASSERT_EQ(a.time_s[i], b.time_s[i]) << "point " << i;
    }
    if (!a.sensor_id.empty()) {
      ASSERT_EQ(a.sensor_id[i], b.sensor_id[i]) << "point " << i;
    }
  }
}

}  // namespace farlio::test
