// Sizes announced by a file that overflow or exceed their limit: each case once crashed, hung
// or misread a reader. Crafted bytes are written to a file and read back through
// read_point_cloud, as a user's file would be.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "farlio/io/lzf.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

constexpr const char* kCountWrapCount = "2305843009213693952";  // 2^61: 4 * 2^61 = 2^63

/// Fields a x y z b, all float32; a and b have COUNTs whose SIZE * COUNT sum wraps the record
/// size to exactly 0 (4 * (2^61 + 2^61 - 3) + 12 = 2^64), as ../shared/data/bad/count_wrap.pcd.
std::string count_wrap_pcd(const std::string& data) {
  return std::string("# .PCD v0.7\nVERSION 0.7\nFIELDS a x y z b\nSIZE 4 4 4 4 4\nTYPE F F F F F\nCOUNT ") +
         kCountWrapCount + " 1 1 1 2305843009213693949\nWIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA " + data + "\n";
}

Scan read_bytes(const TempDir& tmp, const std::string& name, const std::string& bytes) {
  const auto p = tmp.path() / name;
  test::write_raw(p, bytes);
  return read_point_cloud(p);
}

template <class F>
void expect_error(const TempDir& tmp, const std::string& name, F&& make_bytes, const std::string& fragment) {
  const auto p = tmp.path() / name;
  test::write_raw(p, make_bytes());
  test::expect_input_error([&] { (void)read_point_cloud(p); }, p, fragment);
}

}  // namespace

TEST(SizeLimits, PcdCountWrappingTheRecordSizeIsRejectedNamingTheField) {
  TempDir tmp;
  const std::string fragment = std::string("COUNT ") + kCountWrapCount + " of field 'a' is over the limit of";
  expect_error(
      tmp, "count_wrap.pcd", [] { return count_wrap_pcd("binary"); }, fragment);
  expect_error(
      tmp, "count_wrap_compressed.pcd",
      [] {
        std::string s = count_wrap_pcd("binary_compressed");
        test::append_binary<std::uint32_t>(s, 0);  // compressed and uncompressed sizes 0
        test::append_binary<std::uint32_t>(s, 0);
        return s;
      },
      fragment);
  expect_error(
      tmp, "count_wrap_ascii.pcd", [] { return count_wrap_pcd("ascii"); }, fragment);
}

TEST(SizeLimits, PcdWidthOverTheLimitIsRejected) {
  TempDir tmp;
  // 2^62 points of 16 bytes: the data size wrapped to 0 and the scan asked for 2^62 points.
  expect_error(
      tmp, "width.pcd",
      [] {
        return std::string(
            "FIELDS x y z i\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 4611686018427387904\nHEIGHT 1\nDATA binary\n");
      },
      "WIDTH 4611686018427387904 is over the limit of");
  expect_error(
      tmp, "height.pcd",
      [] {
        return std::string("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 9223372036854775807\nDATA ascii\n");
      },
      "HEIGHT 9223372036854775807 is over the limit of");
  expect_error(
      tmp, "points.pcd",
      [] { return std::string("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4294967296\nHEIGHT 2\nDATA binary\n"); },
      "WIDTH * HEIGHT = 8589934592 points is over the limit of");
}

TEST(SizeLimits, PcdDataSizeOverflowIsRejected) {
  // Every COUNT within its limit, but 2^32 points of exactly 2^32 bytes: the data size wraps
  // to 0, so an empty data section passed the size check and x was read far outside it.
  constexpr int kWideFields = 511;  // 511 * 8 * 2^20 bytes = 2^32 - 2^23
  std::string fields = "x y z", sizes = "4 4 4", types = "F F F", counts = "1 1 1";
  for (int k = 0; k < kWideFields; ++k) {
    fields += " w" + std::to_string(k);
    sizes += " 8";
    types += " F";
    counts += " 1048576";
  }
  fields += " u v";  // 4 * 2^20 + 4 * 1048573 = 2^23 - 12 more bytes
  sizes += " 4 4";
  types += " F F";
  counts += " 1048576 1048573";
  TempDir tmp;
  expect_error(
      tmp, "data_wrap.pcd",
      [&] {
        return "FIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " + counts +
               "\nWIDTH 65536\nHEIGHT 65536\nDATA binary\n";
      },
      "4294967296 points of 4294967296 bytes each overflow the size of the data");
}

TEST(SizeLimits, PcdSensorIdMustBeAByte) {
  TempDir tmp;
  const std::string head = "FIELDS x y z sensor_id\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\nDATA ascii\n";
  EXPECT_EQ(read_bytes(tmp, "ok.pcd", head + "1 2 3 7\n").sensor_id.at(0), 7);
  for (const std::string v : {"300", "-1", "nan", "2.5"}) {
    expect_error(
        tmp, "id.pcd", [&] { return head + "1 2 3 " + v + "\n"; }, "field 'sensor_id' of point 0");
  }
}

TEST(SizeLimits, PlyElementCountOverTheLimitIsRejected) {
  TempDir tmp;
  // An element without properties holds no data, so its count was not bounded by the data:
  // 2^62 empty instances were looped over (a hang).
  expect_error(
      tmp, "faces.ply",
      [] {
        return std::string(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 4611686018427387904\nend_header\n1 2 3\n");
      },
      "count 4611686018427387904 of element 'face' is over the limit of");
  // Within the limit, empty instances are skipped at once.
  const Scan s = read_bytes(tmp, "empty.ply",
                            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                            "property float z\nelement nothing 4294967296\nend_header\n1 2 3\n");
  EXPECT_EQ(s.size(), 1u);
}

TEST(SizeLimits, PlyListLengthMustBeAnInteger) {
  TempDir tmp;
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int idx\nend_header\n1 2 3\n";
  EXPECT_EQ(read_bytes(tmp, "ok.ply", head + "2 0 0\n").size(), 1u);
  // NaN passed the range check and was cast to an integer (undefined behaviour); 2.5 was truncated.
  for (const std::string len : {"nan", "2.5", "-1"}) {
    expect_error(
        tmp, "list.ply", [&] { return head + len + " 0 0\n"; }, "list length");
  }
}

TEST(SizeLimits, LzfRefusesAnExpansionItsDataCannotReach) {
  // A size prefix of 2 GiB with 1 byte of data used to reserve the 2 GiB first.
  const std::vector<unsigned char> one_byte = {0};
  try {
    (void)lzf_decompress(one_byte, std::size_t{1} << 31);
    ADD_FAILURE() << "no LzfError";
  } catch (const LzfError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot expand to 2147483648 bytes"), std::string::npos) << e.what();
  }
}

TEST(SizeLimits, SharedBadFilesGiveAClearError) {
  FARLIO_REQUIRE_SHARED_DATA();
  const auto dir = test::shared_data() / "bad";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << dir << " is absent";
  for (const char* name : {"count_wrap.pcd", "count_wrap_compressed.pcd"}) {
    const auto p = dir / name;
    if (!std::filesystem::exists(p)) GTEST_SKIP() << p << " is absent";
    test::expect_input_error([&] { (void)read_point_cloud(p); }, p, "of field 'a' is over the limit of");
  }
}
