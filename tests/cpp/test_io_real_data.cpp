// The real recordings in ../shared/data (skipped when absent).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "farlio/io/file_bytes.hpp"
#include "farlio/io/point_cloud_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;

TEST(RealData, ScanPairPlyPointCounts) {
  FARLIO_REQUIRE_SHARED_DATA();
  const auto dir = test::shared_data() / "real" / "scan_pair";
  const Scan src = read_point_cloud(dir / "source.ply");
  const Scan tgt = read_point_cloud(dir / "target.ply");
  EXPECT_EQ(src.size(), 69792u);
  EXPECT_EQ(tgt.size(), 69088u);
  EXPECT_EQ(src.intensity.size(), src.size());  // scalar_intensity
  for (const auto& p : src.points) ASSERT_TRUE(p.allFinite());
}

TEST(RealData, Kitti16ScansGzipPcd) {
  FARLIO_REQUIRE_SHARED_DATA();
  const auto dir = test::shared_data() / "real" / "kitti_16_scans";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (has_suffix(e.path(), ".pcd.gz")) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 16u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    const Scan s = read_point_cloud(f);
    EXPECT_GT(s.size(), 100000u);
    EXPECT_EQ(s.intensity.size(), s.size());
    EXPECT_TRUE(s.time_s.empty());
    for (const auto& p : s.points) ASSERT_TRUE(p.allFinite());
  }
}

// Fields x y z intensity normal_x normal_y normal_z curvature: the normals and curvature are
// skipped, so point i is the first 3 floats of its 32-byte record and intensity the 4th.
TEST(RealData, KittiPcdSkipsNormalFields) {
  FARLIO_REQUIRE_SHARED_DATA();
  const auto f = test::shared_data() / "real" / "kitti_16_scans" / "000000.pcd.gz";
  const Bytes raw = read_file_bytes(f);
  const std::string text(raw.begin(), raw.begin() + 1000);
  ASSERT_NE(text.find("normal_x"), std::string::npos);
  const std::string marker = "DATA binary\n";
  const std::size_t data = text.find(marker) + marker.size();
  constexpr std::size_t kRecordBytes = 8 * sizeof(float);
  const Scan s = read_point_cloud(f);
  ASSERT_EQ(raw.size() - data, s.size() * kRecordBytes);
  for (std::size_t i = 0; i < s.size(); i += 997) {
    float v[4];
    std::memcpy(v, raw.data() + data + i * kRecordBytes, sizeof(v));
    ASSERT_EQ(s.points[i], Vec3f(v[0], v[1], v[2])) << i;
    ASSERT_EQ(s.intensity[i], v[3]) << i;
  }
}

TEST(RealData, KittiScanRoundTripsThroughEveryEncoding) {
  FARLIO_REQUIRE_SHARED_DATA();
  const Scan s = read_point_cloud(test::shared_data() / "real" / "kitti_16_scans" / "000003.pcd.gz");
  test::TempDir tmp;
  for (auto enc : {PcdEncoding::Ascii, PcdEncoding::Binary, PcdEncoding::BinaryCompressed}) {
    const auto p = tmp.path() / "k.pcd";
    write_pcd(p, s, enc);
    test::expect_bit_equal(s, read_point_cloud(p));
  }
}
