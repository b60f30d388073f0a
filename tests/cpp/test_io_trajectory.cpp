#include <gtest/gtest.h>

#include <random>

#include "farlio/io/text_number.hpp"
#include "farlio/io/trajectory_io.hpp"
#include "io_test_util.hpp"
#include "test_support.hpp"

using namespace farlio;
using namespace farlio::io;
using farlio::test::TempDir;

namespace {

Trajectory random_trajectory(std::size_t n, unsigned seed, std::int64_t t0_ns) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<std::int64_t> dt(1, 200'000'000);
  Trajectory tr;
  std::int64_t t = t0_ns;
  for (std::size_t i = 0; i < n; ++i) {
    Vec6d xi;
    for (int k = 0; k < 6; ++k) xi[k] = g(rng) * 10.0;
    xi.tail<3>() *= 0.25;
    tr.push_back(t, SE3::exp(xi));
    t += dt(rng);
  }
  return tr;
}

void expect_same(const Trajectory& a, const Trajectory& b, bool stamps) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (stamps) {
      EXPECT_EQ(a[i].stamp_ns, b[i].stamp_ns) << i;
    }
    EXPECT_LT((a[i].pose.translation() - b[i].pose.translation()).norm(), 1e-9) << i;
    EXPECT_LT((a[i].pose.inverse() * b[i].pose).angle_rad(), 1e-9) << i;
  }
}

}  // namespace

TEST(TextNumber, SecondsNsExactConversion) {
  for (std::int64_t ns : {std::int64_t{0}, std::int64_t{1}, std::int64_t{999'999'999},
                          std::int64_t{1'700'000'000'123'456'789}, std::int64_t{-1'500'000'001}, std::int64_t{-1}}) {
    const std::string s = format_seconds_from_ns(ns);
    EXPECT_EQ(s.size() - s.find('.') - 1, 9u) << s;
    EXPECT_EQ(parse_seconds_to_ns(s), ns) << s;
  }
  EXPECT_EQ(parse_seconds_to_ns("1.5"), 1'500'000'000);
  EXPECT_EQ(parse_seconds_to_ns("2"), 2'000'000'000);
  EXPECT_EQ(parse_seconds_to_ns("1e-3"), 1'000'000);
  EXPECT_EQ(parse_seconds_to_ns("0.0000000015"), 2);  // rounds the 10th decimal
  EXPECT_FALSE(parse_seconds_to_ns("abc"));
  EXPECT_FALSE(parse_seconds_to_ns("1.2.3"));
  EXPECT_FALSE(parse_seconds_to_ns("99999999999.5"));  // beyond int64 ns
}

TEST(Tum, RoundTripWithLargeStamps) {
  TempDir tmp;
  const auto tr = random_trajectory(200, 1, 1'700'000'000'000'000'123);
  const auto p = tmp.path() / "a.tum";
  write_tum(p, tr);
  expect_same(tr, read_tum(p), true);
}

TEST(Tum, CommentsBlankLinesAndErrorsWithLineNumbers) {
  TempDir tmp;
  const auto p = tmp.path() / "b.tum";
  test::write_raw(
      p, "# header\n\n1.0 1 2 3 0 0 0 1\n  # indented comment\n2.5 4 5 6 0 0 0.7071067811865476 0.7071067811865476\n");
  const auto tr = read_tum(p);
  ASSERT_EQ(tr.size(), 2u);
  EXPECT_EQ(tr[1].stamp_ns, 2'500'000'000);
  EXPECT_EQ(tr[1].pose.translation(), Eigen::Vector3d(4, 5, 6));
  EXPECT_NEAR(tr[1].pose.angle_rad(), M_PI / 2, 1e-12);

  test::write_raw(p, "1.0 1 2 3 0 0 0 1\n2.0 1 2 3 0 0 1\n");
  test::expect_input_error([&] { (void)read_tum(p); }, p, "b.tum:2");
  test::write_raw(p, "1.0 1 2 3 0 0 0 1\n\n2.0 1 x 3 0 0 0 1\n");
  test::expect_input_error([&] { (void)read_tum(p); }, p, "b.tum:3");
  test::write_raw(p, "1.0 1 2 3 0 0 0 0\n");
  test::expect_input_error([&] { (void)read_tum(p); }, p, "zero norm");
  test::expect_input_error([&] { (void)read_tum(tmp.path() / "none.tum"); }, tmp.path() / "none.tum", "no such file");
}

TEST(Kitti, RoundTripAndStamps) {
  TempDir tmp;
  const auto tr = random_trajectory(50, 2, 0);
  const auto p = tmp.path() / "poses.txt";
  write_kitti(p, tr);
  const auto plain = read_kitti(p);
  expect_same(tr, plain, false);
  for (std::size_t i = 0; i < plain.size(); ++i)
    EXPECT_EQ(plain[i].stamp_ns, static_cast<std::int64_t>(i) * kKittiDefaultPeriodNs);
  std::vector<std::int64_t> stamps;
  for (const auto& sp : tr) stamps.push_back(sp.stamp_ns);
  expect_same(tr, read_kitti(p, &stamps), true);
  stamps.pop_back();
  test::expect_input_error([&] { (void)read_kitti(p, &stamps); }, p, "stamps");
  test::write_raw(p, "1 0 0 0 0 1 0 0 0 0 1\n");
  test::expect_input_error([&] { (void)read_kitti(p); }, p, "poses.txt:1");
}

TEST(TrajectoryWriter, FlushesEveryPose) {
  TempDir tmp;
  const auto tr = random_trajectory(5, 3, 42);
  const auto p = tmp.path() / "live.tum";
  TrajectoryWriter w(p);
  for (std::size_t i = 0; i < tr.size(); ++i) {
    w.append(tr[i].stamp_ns, tr[i].pose);
    // Readable while the writer is still open: every line is already on disk.
    const auto partial = read_tum(p);
    ASSERT_EQ(partial.size(), i + 1);
    EXPECT_EQ(partial[i].stamp_ns, tr[i].stamp_ns);
  }
  EXPECT_EQ(w.size(), tr.size());
  expect_same(tr, read_tum(p), true);
}

TEST(Stamps, SecondsALineExactlyWithCommentsAndCommas) {
  TempDir tmp;
  const auto p = tmp.path() / "times.txt";
  test::write_raw(p, "# seconds\n1700000000.123456789\n\n  1700000000.2 extra\n1.036400e-01\n0.5,ouster\n");
  EXPECT_EQ(read_stamps(p), (std::vector<std::int64_t>{1'700'000'000'123'456'789, 1'700'000'000'200'000'000,
                                                       103'640'000, 500'000'000}));
  test::write_raw(p, "0.1\n0.2\nabc\n");
  test::expect_input_error([&] { (void)read_stamps(p); }, p, "times.txt:3: 'abc'");
  test::write_raw(p, "# only a comment\n\n");
  test::expect_input_error([&] { (void)read_stamps(p); }, p, "no stamps");
  const auto none = tmp.path() / "none.txt";
  test::expect_input_error([&] { (void)read_stamps(none); }, none, "no such file");
}

TEST(TrajectoryFile, FormatNamesAndDetection) {
  EXPECT_EQ(parse_trajectory_format("auto"), TrajectoryFormat::kAuto);
  EXPECT_EQ(parse_trajectory_format("tum"), TrajectoryFormat::kTum);
  EXPECT_EQ(parse_trajectory_format("kitti"), TrajectoryFormat::kKitti);
  EXPECT_FALSE(parse_trajectory_format("TUM"));
  EXPECT_FALSE(parse_trajectory_format("csv"));

  TempDir tmp;
  const auto tum = tmp.path() / "a.tum";
  const auto kitti = tmp.path() / "a.txt";
  write_tum(tum, random_trajectory(3, 4, 1));
  write_kitti(kitti, random_trajectory(3, 4, 1));
  EXPECT_EQ(detect_trajectory_format(tum), TrajectoryFormat::kTum);
  EXPECT_EQ(detect_trajectory_format(kitti), TrajectoryFormat::kKitti);
  const auto odd = tmp.path() / "odd.txt";
  test::write_raw(odd, "# comment\n1 2 3 4 5 6 7\n");
  test::expect_input_error([&] { (void)detect_trajectory_format(odd); }, odd, "odd.txt:2: 7 values is neither TUM");
  test::write_raw(odd, "\n# nothing\n");
  test::expect_input_error([&] { (void)detect_trajectory_format(odd); }, odd, "no poses");
  test::expect_input_error([&] { (void)read_trajectory(odd); }, odd, "no poses");
}

TEST(TrajectoryFile, ReadsEitherFormatWithItsStamps) {
  TempDir tmp;
  const auto tr = random_trajectory(20, 5, 1'700'000'000'000'000'007);
  const auto tum = tmp.path() / "a.tum";
  const auto kitti = tmp.path() / "a.txt";
  const auto times = tmp.path() / "times.txt";
  write_tum(tum, tr);
  write_kitti(kitti, tr);
  std::string text;
  for (const auto& p : tr) text += format_seconds_from_ns(p.stamp_ns) + "\n";
  test::write_raw(times, text);

  expect_same(tr, read_trajectory(tum), true);
  expect_same(tr, read_trajectory(tum, TrajectoryFormat::kTum, times), true);  // TUM ignores the times
  expect_same(tr, read_trajectory(kitti, TrajectoryFormat::kAuto, times), true);
  const Trajectory plain = read_trajectory(kitti, TrajectoryFormat::kKitti);
  expect_same(tr, plain, false);
  EXPECT_EQ(plain[3].stamp_ns, 3 * kKittiDefaultPeriodNs);
  test::expect_input_error([&] { (void)read_trajectory(kitti, TrajectoryFormat::kTum); }, kitti, "a.txt:1");
  test::write_raw(times, "0.1\n0.2\n");
  test::expect_input_error([&] { (void)read_trajectory(kitti, TrajectoryFormat::kAuto, times); }, kitti,
                           "20 poses but 2 stamps");
}

// A run that filled the disk or died mid-line leaves a torn last line without a newline: it is
// skipped with a warning naming the file and line; the same line in the middle stays an error.
TEST(TornLastLine, SkippedWithAWarningInEveryTrajectoryReader) {
  TempDir tmp;
  const auto tum = tmp.path() / "odometry_body.tum";
  test::write_raw(tum, "# t x y z qx qy qz qw\n1.0 1 2 3 0 0 0 1\n2.0 4 5 6 0 0 0 1\n3.0 7 8");
  Warnings warnings;
  const Trajectory t = read_tum(tum, &warnings);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].stamp_ns, 2'000'000'000);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("odometry_body.tum:4: last line skipped"), std::string::npos) << warnings[0];
  EXPECT_EQ(read_trajectory(tum, TrajectoryFormat::kAuto).size(), 2u);  // without a list: to std::cerr

  // With its newline the same line was written whole: an error.
  test::write_raw(tum, "1.0 1 2 3 0 0 0 1\n2.0 4 5 6 0 0 0 1\n3.0 7 8\n");
  test::expect_input_error([&] { (void)read_tum(tum); }, tum, "odometry_body.tum:3");
  // A bad line in the middle stays an error even when the last line is torn.
  test::write_raw(tum, "1.0 1 2 3 0 0 0 1\n2.0 4 x 6 0 0 0 1\n3.0 7 8");
  test::expect_input_error([&] { (void)read_tum(tum); }, tum, "odometry_body.tum:2");
  // A whole last line without a newline is read as before.
  test::write_raw(tum, "1.0 1 2 3 0 0 0 1\n2.0 4 5 6 0 0 0 1");
  EXPECT_EQ(read_tum(tum).size(), 2u);

  const auto kitti = tmp.path() / "poses.txt";
  test::write_raw(kitti, "1 0 0 1 0 1 0 2 0 0 1 3\n1 0 0 4 0 1 0 5 0 0 1 6\n1 0 0 7 0 1");
  warnings.clear();
  EXPECT_EQ(read_kitti(kitti, nullptr, &warnings).size(), 2u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("poses.txt:3"), std::string::npos) << warnings[0];
  // The times file may still hold the torn pose's stamp.
  const std::vector<std::int64_t> stamps = {10, 20, 30};
  const Trajectory stamped = read_kitti(kitti, &stamps, &warnings);
  ASSERT_EQ(stamped.size(), 2u);
  EXPECT_EQ(stamped[1].stamp_ns, 20);
  EXPECT_EQ(read_trajectory(kitti, TrajectoryFormat::kAuto, std::nullopt, &warnings).size(), 2u);

  const auto times = tmp.path() / "times.txt";
  test::write_raw(times, "0.1\n0.2\n0.3e");
  warnings.clear();
  EXPECT_EQ(read_stamps(times, &warnings), (std::vector<std::int64_t>{100'000'000, 200'000'000}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("times.txt:3"), std::string::npos) << warnings[0];
}

// The writers say why a write failed and name the file (/dev/full: "No space left on device").
TEST(WriteErrors, NameTheFileAndTheReason) {
  const std::filesystem::path full = "/dev/full";
  if (!std::filesystem::exists(full)) GTEST_SKIP() << "no /dev/full";
  auto expect_reason = [&](auto&& write) {
    try {
      write();
      ADD_FAILURE() << "no error writing to " << full;
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("/dev/full: write error: No space left on device"), std::string::npos) << msg;
    }
  };
  const Trajectory tr = random_trajectory(3, 6, 0);
  expect_reason([&] { TrajectoryWriter w(full); });
  expect_reason([&] { write_tum(full, tr); });
  expect_reason([&] { write_kitti(full, tr); });
  expect_reason([&] {
    OutputFile out(full);
    out.write(std::string_view("1.0 0 0 0 0 0 0 1\n"));  // buffered: fails at the flush
    out.flush();
  });
}
