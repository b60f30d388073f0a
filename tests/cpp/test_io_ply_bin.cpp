#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>

#include "farlio/io/point_cloud_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

template <class T>
void append_big_endian(std::string& out, T v) {
  std::string b(reinterpret_cast<const char*>(&v), sizeof(T));
  if (std::endian::native == std::endian::little) std::reverse(b.begin(), b.end());
  out += b;
}

}  // namespace

TEST(Ply, WriteReadRoundTripIsBitExact) {
  TempDir tmp;
  const Scan s = test::random_scan(2000, 21, true, false);
  const auto p = tmp.path() / "map.ply";
  write_ply(p, s.points, &s.intensity);
  test::expect_bit_equal(s, read_point_cloud(p));
  write_ply(p, s.points);
  const Scan r = read_point_cloud(p);
  EXPECT_TRUE(r.intensity.empty());
  ASSERT_EQ(r.size(), s.size());
  for (std::size_t i = 0; i < s.size(); ++i) ASSERT_EQ(r.points[i], s.points[i]);
}

TEST(Ply, WriteRejectsMismatchedIntensity) {
  TempDir tmp;
  const std::vector<Vec3f> pts(3, Vec3f::Ones());
  const std::vector<float> in(2, 1.0f);
  const auto p = tmp.path() / "bad.ply";
  test::expect_input_error([&] { write_ply(p, pts, &in); }, p);
}

TEST(Ply, AsciiWithFacesBeforeAndAfterVertices) {
  TempDir tmp;
  const std::string text =
      "ply\nformat ascii 1.0\ncomment test\n"
      "element camera 1\nproperty float f\nproperty list uchar int ids\n"
      "element vertex 3\nproperty uint8 ring\nproperty double z\nproperty float scalar_intensity\n"
      "property float y\nproperty float x\nproperty list uchar float extra\nproperty double t\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "1.5 3 7 8 9\n"
      "0 3.5 10 2 1 0 0.0\n"
      "1 4.5 20 3 2 2 9 9 0.05\n"
      "2 5.5 30 4 3 1 9 0.1\n"
      "3 0 1 2\n"
      "4 0 1 2 0\n";
  const auto p = tmp.path() / "a.ply";
  test::write_raw(p, text);
  const Scan s = read_point_cloud(p);
  ASSERT_EQ(s.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const float f = static_cast<float>(i);
    EXPECT_EQ(s.points[i], Vec3f(1.0f + f, 2.0f + f, 3.5f + f));
    EXPECT_EQ(s.intensity[i], 10.0f * (1.0f + f));
    EXPECT_FLOAT_EQ(s.time_s[i], 0.05f * f);
  }
}

TEST(Ply, BinaryLittleAndBigEndianWithFaces) {
  TempDir tmp;
  for (bool big : {false, true}) {
    std::string f = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "element vertex 2\nproperty short ring\nproperty float x\nproperty float y\nproperty float z\n"
                    "property uint t\nelement edge 1\nproperty int a\nproperty int b\nend_header\n";
    auto put = [&](auto v) {
      if (big) {
        append_big_endian(f, v);
      } else {
        test::append_binary(f, v);
      }
    };
    put(std::uint8_t{3});
    put(std::int32_t{0});
    put(std::int32_t{1});
    put(std::int32_t{1});
    for (int i = 0; i < 2; ++i) {
      put(std::int16_t{-7});
      put(1.25f * static_cast<float>(i + 1));
      put(-2.0f);
      put(1e3f);
      put(std::uint32_t{50'000'000u} * static_cast<std::uint32_t>(i));  // integer t: ns
    }
    put(std::int32_t{0});
    put(std::int32_t{1});
    const auto p = tmp.path() / (big ? "big.ply" : "little.ply");
    test::write_raw(p, f);
    const Scan s = read_point_cloud(p);
    ASSERT_EQ(s.size(), 2u);
    EXPECT_EQ(s.points[1], Vec3f(2.5f, -2.0f, 1e3f));
    EXPECT_NEAR(s.time_s[1], 0.05, 1e-9);

    f.resize(f.size() - 6);  // cut into the edge element
    test::write_raw(p, f);
    test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "edge");
  }
}

TEST(Ply, TruncatedAndMalformedThrow) {
  TempDir tmp;
  const Scan s = test::random_scan(100, 22, true, false);
  const auto p = tmp.path() / "trunc.ply";
  write_ply(p, s.points, &s.intensity);
  std::string bytes = test::read_raw(p);
  bytes.resize(bytes.size() - 17);
  test::write_raw(p, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "truncated");

  const std::vector<std::pair<std::string, std::string>> cases = {
      {"magic.ply", "plx\nformat ascii 1.0\nend_header\n"},
      {"noformat.ply", "ply\nelement vertex 0\nproperty float x\nend_header\n"},
      {"badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n1\n"},
      {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"},
      {"novertex.ply", "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int v\nend_header\n"},
      {"noz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n"},
      {"short.ply",
       "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3\n4 5\n"},
      {"text.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 b 3\n"},
      {"extra.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3 4\n"},
  };
  for (const auto& [name, text] : cases) {
    SCOPED_TRACE(name);
    const auto q = tmp.path() / name;
    test::write_raw(q, text);
    test::expect_input_error([&] { (void)read_point_cloud(q); }, q);
  }
}

TEST(KittiBin, RoundTripIsBitExact) {
  TempDir tmp;
  const Scan s = test::random_scan(3000, 23, true, false);
  const auto p = tmp.path() / "000000.bin";
  write_kitti_bin(p, s);
  EXPECT_EQ(std::filesystem::file_size(p), s.size() * 16);
  test::expect_bit_equal(s, read_point_cloud(p));
}

TEST(KittiBin, NoIntensityWritesZero) {
  TempDir tmp;
  const Scan s = test::random_scan(10, 24, false, true);
  const auto p = tmp.path() / "a.bin";
  write_kitti_bin(p, s);
  const Scan r = read_point_cloud(p);
  ASSERT_EQ(r.size(), 10u);
  EXPECT_TRUE(r.time_s.empty());
  for (std::size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r.points[i], s.points[i]);
    EXPECT_EQ(r.intensity[i], 0.0f);
  }
}

TEST(KittiBin, SizeNotMultipleOf16Throws) {
  TempDir tmp;
  const auto p = tmp.path() / "bad.bin";
  write_kitti_bin(p, test::random_scan(10, 25));
  std::string bytes = test::read_raw(p);
  bytes.resize(bytes.size() - 5);
  test::write_raw(p, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "multiple of 16");
}
