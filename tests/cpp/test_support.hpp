#pragma once
// Helpers shared by the C++ tests: where the real recordings are, temporary folders.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

namespace farlio::test {

/// ../shared/data (or $FARLIO_SHARED_DATA); empty path if absent.
inline std::filesystem::path shared_data() {
  const char* env = std::getenv("FARLIO_SHARED_DATA");
  std::filesystem::path p = env ? env : FARLIO_DEFAULT_SHARED_DATA;
  return std::filesystem::is_directory(p) ? p : std::filesystem::path{};
}

#define FARLIO_REQUIRE_SHARED_DATA()                                                       \
  do {                                                                                     \
    if (::farlio::test::shared_data().empty()) GTEST_SKIP() << "../shared/data is absent"; \
  } while (0)

/// A fresh, empty temporary folder removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("farlio_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace farlio::test
