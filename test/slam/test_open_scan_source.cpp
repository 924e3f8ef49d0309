#include <gtest/gtest.h>

#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/io/box_room_source.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

std::string open_error(const std::string& path, const SourceOptions& options = {}) {
  try {
    open_scan_source(path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(OpenScanSource, UnreadableInputsNameTheProblem) {
  const auto dir = test::scratch_dir("open_scan_source");
  write_bytes(dir / "empty.pcap", "");
  write_bytes(dir / "capture.pcapng", std::string("\x0a\x0d\x0d\x0a\x1c\x00\x00\x00", 8));
  write_bytes(dir / "old.bag", "#ROSBAG V1.2\n");
  write_bytes(dir / "scan.bin", std::string(32, '\0'));
  write_bytes(dir / "notes.txt", "hello\n");
  EXPECT_NE(open_error((dir / "nothing-here").string()).find("no such file"), std::string::npos);
  EXPECT_NE(open_error((dir / "empty.pcap").string()).find("empty file"), std::string::npos);
  EXPECT_NE(open_error((dir / "capture.pcapng").string()).find("editcap"), std::string::npos);
  EXPECT_NE(open_error((dir / "old.bag").string()).find("2.0"), std::string::npos);
  EXPECT_NE(open_error((dir / "scan.bin").string()).find("folder"), std::string::npos);
  EXPECT_NE(open_error((dir / "notes.txt").string()).find("unrecognised format"),
            std::string::npos);
}

TEST(OpenScanSource, DetectsEachFormatFromItsContent) {
  const auto data = test::shared_data_dir();
  if (data.empty()) GTEST_SKIP() << "../shared/data not found beside the checkout";
  EXPECT_EQ(open_scan_source((data / "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap").string())
                ->info()
                .format,
            "ouster-pcap");
  EXPECT_EQ(open_scan_source((data / "ouster/512x10_raw.bag").string())->info().format, "rosbag");
  EXPECT_EQ(open_scan_source((data / "velodyne/251370668.pcd").string())->info().format, "pcd");
  // The content decides, not the name: a PCD called .dat is still a PCD.
  const auto dir = test::scratch_dir("open_scan_source_detect");
  std::filesystem::copy_file(data / "velodyne/251370668.pcd", dir / "scan.dat");
  EXPECT_EQ(open_scan_source((dir / "scan.dat").string())->info().format, "pcd");
}

TEST(OpenScanSource, RangeLimitsApplyToEveryReader) {
  FEATSENSE_SHARED_FILE(pcap, "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  SourceOptions options;
  options.min_range_m = 2.0;
  options.max_range_m = 10.0;
  auto limited = open_scan_source(pcap.string(), options);
  auto full = open_scan_source(pcap.string());
  const auto a = limited->next();
  const auto b = full->next();
  ASSERT_TRUE(a && b);
  EXPECT_LT(a->valid_count(), b->valid_count());
  EXPECT_GT(a->valid_count(), 0u);
  for (size_t i = 0; i < a->size(); ++i) {
    if (!a->valid[i]) continue;
    const float r = a->xyz[i].norm();
    ASSERT_GE(r, 2.0f);
    ASSERT_LE(r, 10.0f);
  }
}

TEST(OpenScanSource, TheSelfBoxDropsTheVehiclesOwnReturnsAndNothingElse) {
  // A box around the sensor reaching 6 m forward and 2 m to each side (the OS1-128 sees the
  // floor 1.5 m below from 3.6 m on): the room's floor returns inside it are dropped, every
  // other return is kept as it was.
  const std::array<double, 6> box{-1.0, -2.0, -2.0, 6.0, 2.0, 0.5};
  auto boxed = with_range_limits(make_box_room_source(default_box_room()), 0.0, 1e9, box);
  auto full = with_range_limits(make_box_room_source(default_box_room()), 0.0, 1e9);
  const auto a = boxed->next();
  const auto b = full->next();
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->size(), b->size());
  size_t inside = 0;
  for (size_t i = 0; i < b->size(); ++i) {
    if (!b->valid[i]) continue;
    const Eigen::Vector3f& p = b->xyz[i];
    const bool in = p.x() >= -1.0f && p.x() <= 6.0f && p.y() >= -2.0f && p.y() <= 2.0f &&
                    p.z() >= -2.0f && p.z() <= 0.5f;
    inside += in ? 1 : 0;
    EXPECT_EQ(static_cast<bool>(a->valid[i]), !in) << i;
  }
  EXPECT_GT(inside, 10u) << "the box must hold some of the room's returns for this test";
}

}  // namespace
}  // namespace featsense::slam
