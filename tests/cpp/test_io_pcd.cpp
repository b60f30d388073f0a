#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "farlio/io/lzf.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

std::string header(const std::string& fields, const std::string& size, const std::string& type,
                   const std::string& count, std::size_t n, const std::string& data) {
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT " + count +
         "\nWIDTH " + std::to_string(n) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) +
         "\nDATA " + data + "\n";
}

}  // namespace

TEST(Pcd, BinaryRoundTripIsBitExact) {
  TempDir tmp;
  for (auto enc : {PcdEncoding::Binary, PcdEncoding::BinaryCompressed, PcdEncoding::Ascii}) {
    for (bool intensity : {false, true}) {
      for (bool time : {false, true}) {
        Scan s = test::random_scan(1234, 11, intensity, time);
        if (intensity) s.sensor_id.assign(s.size(), 3);
        const auto p = tmp.path() / ("c_" + std::string(to_string(enc)) + ".pcd");
        write_pcd(p, s, enc);
        const Scan r = read_point_cloud(p);
        // ascii uses shortest round-trip formatting, so it is exact as well
        test::expect_bit_equal(s, r);
        EXPECT_EQ(r.start_stamp_ns, 0);
        EXPECT_EQ(r.end_stamp_ns, 0);
      }
    }
  }
}

TEST(Pcd, EmptyCloudRoundTrips) {
  TempDir tmp;
  for (auto enc : {PcdEncoding::Binary, PcdEncoding::BinaryCompressed, PcdEncoding::Ascii}) {
    const auto p = tmp.path() / "empty.pcd";
    write_pcd(p, Scan{}, enc);
    EXPECT_TRUE(read_point_cloud(p).empty());
  }
}

TEST(Pcd, GzipRoundTrip) {
  TempDir tmp;
  const Scan s = test::random_scan(500, 2);
  const auto p = tmp.path() / "a.pcd.gz";
  write_pcd(p, s, PcdEncoding::Binary);
  EXPECT_NE(test::read_raw(p).substr(0, 2), "# ");  // really gzip'd
  test::expect_bit_equal(s, read_point_cloud(p));
}

TEST(Pcd, CompressedIsSmallerForStructuredCloud) {
  TempDir tmp;
  Scan s;
  for (int i = 0; i < 5000; ++i) {
    s.points.emplace_back(static_cast<float>(i % 10), 1.0f, 2.0f);
    s.intensity.push_back(7.0f);
  }
  write_pcd(tmp.path() / "b.pcd", s, PcdEncoding::Binary);
  write_pcd(tmp.path() / "c.pcd", s, PcdEncoding::BinaryCompressed);
  EXPECT_LT(std::filesystem::file_size(tmp.path() / "c.pcd") * 5, std::filesystem::file_size(tmp.path() / "b.pcd"));
  test::expect_bit_equal(s, read_point_cloud(tmp.path() / "c.pcd"));
}

// Shuffled field order, skipped fields (rgb, normal COUNT 3, uint16 ring, double), uint32 ns time.
TEST(Pcd, ShuffledFieldsExtraFieldsAndOusterTime) {
  TempDir tmp;
  const std::string fields = "ring normal t rgb z intensity y x extra";
  const std::string size = "2 4 4 4 4 4 4 4 8";
  const std::string type = "U F U F F F F F F";
  const std::string count = "1 3 1 1 1 1 1 1 1";
  const std::size_t n = 3;
  std::string bin = header(fields, size, type, count, n, "binary");
  std::string ascii = header(fields, size, type, count, n, "ascii");
  for (std::size_t i = 0; i < n; ++i) {
    const float x = 1.5f + static_cast<float>(i), y = -2.25f, z = 0.125f * static_cast<float>(i),
                in = 10.0f * static_cast<float>(i);
    const std::uint32_t t_ns = 25'000'000u * static_cast<std::uint32_t>(i);
    test::append_binary<std::uint16_t>(bin, static_cast<std::uint16_t>(i));
    for (int k = 0; k < 3; ++k) test::append_binary<float>(bin, 9.0f);
    test::append_binary<std::uint32_t>(bin, t_ns);
    test::append_binary<float>(bin, 0.5f);
    test::append_binary<float>(bin, z);
    test::append_binary<float>(bin, in);
    test::append_binary<float>(bin, y);
    test::append_binary<float>(bin, x);
    test::append_binary<double>(bin, 123.0);
    ascii += std::to_string(i) + " 9 9 9 " + std::to_string(t_ns) + " 0.5 " + std::to_string(z) + " " +
             std::to_string(in) + " " + std::to_string(y) + " " + std::to_string(x) + " 123\n";
  }
  for (const auto& [name, text] : {std::pair{"bin.pcd", bin}, std::pair{"ascii.pcd", ascii}}) {
    const auto p = tmp.path() / name;
    test::write_raw(p, text);
    const Scan s = read_point_cloud(p);
    ASSERT_EQ(s.size(), n) << name;
    ASSERT_EQ(s.time_s.size(), n);
    ASSERT_EQ(s.intensity.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(s.points[i], Vec3f(1.5f + static_cast<float>(i), -2.25f, 0.125f * static_cast<float>(i))) << name;
      EXPECT_FLOAT_EQ(s.intensity[i], 10.0f * static_cast<float>(i));
      EXPECT_NEAR(s.time_s[i], 0.025 * static_cast<double>(i), 1e-9) << "uint32 t is ns";
    }
  }
}

TEST(Pcd, BinaryCompressedWithExtraFieldsIsStructureOfArrays) {
  // Build a binary_compressed file by hand: fields y x normal(COUNT 3) time(double seconds).
  TempDir tmp;
  const std::size_t n = 4;
  std::string soa;
  for (std::size_t i = 0; i < n; ++i) test::append_binary<float>(soa, 10.0f + static_cast<float>(i));   // y
  for (std::size_t i = 0; i < n; ++i) test::append_binary<float>(soa, static_cast<float>(i));           // x
  for (std::size_t i = 0; i < 3 * n; ++i) test::append_binary<float>(soa, -1.0f);                       // normal
  for (std::size_t i = 0; i < n; ++i) test::append_binary<double>(soa, 0.01 * static_cast<double>(i));  // time
  std::string z_block;
  for (std::size_t i = 0; i < n; ++i) test::append_binary<float>(z_block, 5.0f);
  soa.insert(4 * n * 2, z_block);  // z after x
  const std::vector<unsigned char> raw(soa.begin(), soa.end());
  const auto packed = lzf_compress(raw);
  std::string file = header("y x z normal time", "4 4 4 4 8", "F F F F F", "1 1 1 3 1", n, "binary_compressed");
  test::append_binary<std::uint32_t>(file, static_cast<std::uint32_t>(packed.size()));
  test::append_binary<std::uint32_t>(file, static_cast<std::uint32_t>(raw.size()));
  file.append(packed.begin(), packed.end());
  const auto p = tmp.path() / "soa.pcd";
  test::write_raw(p, file);
  const Scan s = read_point_cloud(p);
  ASSERT_EQ(s.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(s.points[i], Vec3f(static_cast<float>(i), 10.0f + static_cast<float>(i), 5.0f));
    EXPECT_FLOAT_EQ(s.time_s[i], 0.01f * static_cast<float>(i));
  }
  EXPECT_TRUE(s.intensity.empty());
}

TEST(Pcd, IntegerAndSmallTypesAreRead) {
  TempDir tmp;
  std::string f = header("x y z intensity", "1 2 8 1", "I I I U", "1 1 1 1", 2, "binary");
  for (int i = 0; i < 2; ++i) {
    test::append_binary<std::int8_t>(f, static_cast<std::int8_t>(-5 - i));
    test::append_binary<std::int16_t>(f, static_cast<std::int16_t>(-3000));
    test::append_binary<std::int64_t>(f, 1234567);
    test::append_binary<std::uint8_t>(f, 200);
  }
  const auto p = tmp.path() / "ints.pcd";
  test::write_raw(p, f);
  const Scan s = read_point_cloud(p);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.points[1], Vec3f(-6.0f, -3000.0f, 1234567.0f));
  EXPECT_EQ(s.intensity[0], 200.0f);
}

TEST(Pcd, TruncatedBinaryNamesFileAndCounts) {
  TempDir tmp;
  const auto p = tmp.path() / "trunc.pcd";
  write_pcd(p, test::random_scan(1000, 4), PcdEncoding::Binary);
  std::string bytes = test::read_raw(p);
  bytes.resize(bytes.size() - 360 * 20);  // 20 bytes per point (x y z intensity t)
  test::write_raw(p, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "header says 1000 points but data holds 640");
}

TEST(Pcd, TruncatedAsciiAndCompressedThrow) {
  TempDir tmp;
  const auto a = tmp.path() / "trunc_ascii.pcd";
  write_pcd(a, test::random_scan(100, 5), PcdEncoding::Ascii);
  std::string bytes = test::read_raw(a);
  bytes.resize(bytes.size() / 2);
  bytes.resize(bytes.rfind('\n') + 1);
  test::write_raw(a, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(a); }, a, "truncated");

  const auto c = tmp.path() / "trunc_comp.pcd";
  write_pcd(c, test::random_scan(100, 6), PcdEncoding::BinaryCompressed);
  bytes = test::read_raw(c);
  bytes.resize(bytes.size() - 50);
  test::write_raw(c, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(c); }, c, "truncated");
}

TEST(Pcd, CorruptCompressedDataThrows) {
  TempDir tmp;
  const auto p = tmp.path() / "corrupt.pcd";
  Scan s;
  for (int i = 0; i < 2000; ++i) s.points.emplace_back(1.0f, 2.0f, static_cast<float>(i % 3));
  write_pcd(p, s, PcdEncoding::BinaryCompressed);
  std::string bytes = test::read_raw(p);
  const std::size_t data = bytes.find("DATA binary_compressed\n") + 23 + 8;
  // Turn every byte of the compressed block into a far back-reference: must be detected.
  for (std::size_t k = data; k < bytes.size(); ++k) bytes[k] = static_cast<char>(0xff);
  test::write_raw(p, bytes);
  test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "corrupt");
}

TEST(Pcd, MalformedHeadersThrow) {
  TempDir tmp;
  struct Case {
    std::string name, text, fragment;
  };
  const std::string ok_fields = "x y z";
  const std::vector<Case> cases = {
      {"nofields.pcd", "VERSION 0.7\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "FIELDS"},
      {"nowidth.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "WIDTH"},
      {"nodata.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\n", "DATA"},
      {"mismatch.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "SIZE"},
      {"badtype.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "TYPE"},
      {"badsize.pcd", "FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "SIZE 3"},
      {"points.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 5\nHEIGHT 1\nPOINTS 4\nDATA ascii\n", "POINTS"},
      {"unknownkey.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOLOR 1\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n",
       "COLOR"},
      {"encoding.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA zip\n", "zip"},
      {"noz.pcd", "FIELDS x y w\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n", "'z'"},
      {"wrongpoints.pcd",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n",
       "header says 3 points but data holds 2"},
      {"extrapoint.pcd",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n4 5 6\n", "another"},
      {"nan_text.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 two 3\n",
       "'two'"},
      {"short_line.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n",
       "expected 3"},
      {"xcount.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 2 1 1\nWIDTH 0\nHEIGHT 1\nPOINTS 0\nDATA ascii\n",
       "COUNT 2"},
      {"empty.pcd", "", "DATA"},
  };
  for (const auto& c : cases) {
    const auto p = tmp.path() / c.name;
    test::write_raw(p, c.text);
    SCOPED_TRACE(c.name);
    test::expect_input_error([&] { (void)read_point_cloud(p); }, p, c.fragment);
  }
}

TEST(PointCloud, MissingFileAndUnknownExtensionThrow) {
  TempDir tmp;
  const auto missing = tmp.path() / "nothere.pcd";
  test::expect_input_error([&] { (void)read_point_cloud(missing); }, missing, "no such file");
  const auto txt = tmp.path() / "cloud.xyz";
  test::write_raw(txt, "1 2 3\n");
  test::expect_input_error([&] { (void)read_point_cloud(txt); }, txt, "unknown point cloud file type");
  const auto badgz = tmp.path() / "bad.pcd.gz";
  test::write_raw(badgz, std::string("\x1f\x8b\x08\x00garbage-not-deflate", 24));
  test::expect_input_error([&] { (void)read_point_cloud(badgz); }, badgz, "gzip");
}
