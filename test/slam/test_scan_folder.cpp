// Folders of scans: KITTI .bin, PCD and PLY in natural or time stamp order, times.txt,
// sequence.yaml, and folders that cannot be read.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/io/scan_writers.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

/// A KITTI .bin of `points` points on the HDL-64's beam `beam`, all at distance `tag` + 5 m
/// so that the frame tells which file it came from; clockwise from +x seen from above, as
/// the sensor measures them.
void write_bin(const fs::path& path, int tag, int points = 50) {
  const config::SensorModel hdl64 = config::sensor_preset("hdl64");
  std::ofstream out(path, std::ios::binary);
  for (int i = 0; i < points; ++i) {
    const double e = hdl64.elevation_rad[10], a = -2 * M_PI * i / points, d = 5.0 + tag;
    const float p[4] = {static_cast<float>(d * std::cos(e) * std::cos(a)),
                        static_cast<float>(d * std::cos(e) * std::sin(a)),
                        static_cast<float>(d * std::sin(e)), 0.5f};
    out.write(reinterpret_cast<const char*>(p), sizeof p);
  }
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

/// The tag of a frame written by write_bin() (or of a scan from vlp16_scan()).
int tag_of(const Scan& scan) {
  for (size_t i = 0; i < scan.size(); ++i) {
    if (scan.valid[i]) return static_cast<int>(std::lround(scan.range_m[i] - 5.0f));
  }
  return -1;
}

std::vector<Scan> read_all(ScanSource& source) {
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

std::string error_of(const fs::path& folder, const SourceOptions& options = {}) {
  try {
    open_scan_folder(folder.string(), options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ScanFolder, KittiBinInNaturalOrder) {
  const fs::path dir = test::scratch_dir("scan_folder_natural");
  for (int n : {2, 10, 1}) write_bin(dir / (std::to_string(n) + ".bin"), n);
  write_text(dir / "calib.txt", "P0: 1 0 0\n");  // not a scan: ignored
  write_text(dir / "notes.json", "{}");
  const auto source = open_scan_folder(dir.string(), {});
  EXPECT_EQ(source->info().format, "kitti-bin");
  EXPECT_EQ(source->info().sensor.name, "hdl64");
  EXPECT_EQ(source->info().frames, 3u);
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(tag_of(scans[0]), 1);
  EXPECT_EQ(tag_of(scans[1]), 2);
  EXPECT_EQ(tag_of(scans[2]), 10);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(scans[i].sequence, i);
    EXPECT_EQ(scans[i].stamp_ns, static_cast<int64_t>(i) * 100'000'000);  // index / 10 Hz
    EXPECT_EQ(scans[i].valid_count(), 50u);
    EXPECT_EQ(scans[i].channel("intensity")->values[scans[i].index(10, 0)], 0.5f);
  }
}

TEST(ScanFolder, TimesTxtBesideOrOneUp) {
  const fs::path sequence = test::scratch_dir("scan_folder_times");
  const fs::path dir = sequence / "velodyne";
  fs::create_directories(dir);
  for (int n = 0; n < 3; ++n) write_bin(dir / ("00000" + std::to_string(n) + ".bin"), n);
  write_text(sequence / "times.txt", "0.000000e+00\n1.036592e-01\n2.072750e-01\n");
  std::vector<Scan> scans = read_all(*open_scan_folder(dir.string(), {}));
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[1].stamp_ns, 103659200);
  EXPECT_EQ(scans[2].stamp_ns, 207275000);

  // Beside the scans wins over one folder up.
  write_text(dir / "times.txt", "1\n2\n3\n");
  scans = read_all(*open_scan_folder(dir.string(), {}));
  EXPECT_EQ(scans[2].stamp_ns, 3'000'000'000);

  // A subset of a sequence: the names index times.txt.
  fs::remove(dir / "times.txt");
  fs::remove(dir / "000000.bin");
  scans = read_all(*open_scan_folder(dir.string(), {}));
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].stamp_ns, 103659200);

  // A times.txt that fits nothing: a warning, stamps from the rate.
  write_text(sequence / "times.txt", "0.5\n");
  const auto source = open_scan_folder(dir.string(), {});
  scans = read_all(*source);
  EXPECT_EQ(scans[1].stamp_ns, 100'000'000);
  EXPECT_EQ(source->stats().warning_count, 1u);
  EXPECT_NE(source->stats().warnings[0].find("times.txt has 1 lines for 2 scans"),
            std::string::npos);
}

TEST(ScanFolder, DamagedBinIsASkippedFrame) {
  const fs::path dir = test::scratch_dir("scan_folder_damaged");
  for (int n = 0; n < 3; ++n) write_bin(dir / (std::to_string(n) + ".bin"), n);
  fs::resize_file(dir / "1.bin", 50 * 16 - 3);
  const auto source = open_scan_folder(dir.string(), {});
  EXPECT_EQ(source->info().frames, 3u);
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[1].sequence, 2u);
  EXPECT_EQ(source->stats().frames_read, 2u);
  EXPECT_EQ(source->stats().frames_skipped, 1u);
  ASSERT_EQ(source->stats().warnings.size(), 1u);
  EXPECT_NE(source->stats().warnings[0].find("1.bin: 797 bytes is not a multiple of 16"),
            std::string::npos)
      << source->stats().warnings[0];
}

TEST(ScanFolder, FoldersThatCannotBeRead) {
  const fs::path dir = test::scratch_dir("scan_folder_errors");
  EXPECT_NE(error_of(dir).find(": empty folder"), std::string::npos);
  write_text(dir / "README.txt", "hello");
  EXPECT_NE(error_of(dir).find("no scans (.bin, .pcd or .ply files) among 1 entries"),
            std::string::npos);
  write_bin(dir / "1.bin", 1);
  write_bin(dir / "2.bin", 2);
  write_text(dir / "3.pcd", "not really");
  write_text(dir / "4.PLY", "ply");
  const std::string mixed = error_of(dir);
  EXPECT_NE(mixed.find("mixed scan formats in one folder (2 .bin, 1 .pcd, 1 .ply)"),
            std::string::npos)
      << mixed;
  EXPECT_NE(error_of(dir / "missing").find("not a folder"), std::string::npos);

  // A folder of PCDs none of which can be read.
  const fs::path bad = test::scratch_dir("scan_folder_unreadable");
  write_text(bad / "a.pcd", "");
  write_text(bad / "b.pcd", "VERSION 0.7\n");
  EXPECT_NE(error_of(bad).find("no readable scan"), std::string::npos) << error_of(bad);
}

/// A 16 x 1800 scan on the VLP-16's beams at distance tag + 5 m (see tag_of()).
Scan vlp16_scan(int tag) {
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  Scan scan = Scan::allocate(16, 1800);
  for (int r = 0; r < 16; ++r) {
    for (int c = 0; c < 1800; c += 9) {
      const size_t i = scan.index(r, c);
      const double e = vlp16.elevation_rad[static_cast<size_t>(r)], a = -2 * M_PI * c / 1800,
                   d = 5.0 + tag;
      scan.xyz[i] = Eigen::Vector3d(d * std::cos(e) * std::cos(a), d * std::cos(e) * std::sin(a),
                                    d * std::sin(e))
                        .cast<float>();
      scan.range_m[i] = static_cast<float>(d);
      scan.valid[i] = 1;
    }
  }
  return scan;
}

TEST(ScanFolder, PcdAndPlyFoldersOrderedByNameStamps) {
  // Seconds with a fraction: natural order would put .25 after .5; the stamps do not.
  for (const bool ply : {false, true}) {
    const fs::path dir = test::scratch_dir(ply ? "scan_folder_ply" : "scan_folder_pcd");
    const std::vector<std::pair<std::string, int>> files = {
        {"1673400472.5", 2}, {"1673400472.25", 1}, {"1673400471.9", 0}};
    for (const auto& [name, tag] : files) {
      Scan scan = vlp16_scan(tag);
      scan.stamp_ns = 42;  // the name's stamp wins over the file's own
      const std::string path = (dir / (name + (ply ? ".ply" : ".pcd"))).string();
      ply ? write_scan_ply(scan, path) : write_scan_pcd(scan, path);
    }
    const auto source = open_scan_folder(dir.string(), {});
    EXPECT_EQ(source->info().format, ply ? "ply" : "pcd");
    EXPECT_EQ(source->info().sensor.name, "vlp16");
    const std::vector<Scan> scans = read_all(*source);
    ASSERT_EQ(scans.size(), 3u);
    EXPECT_EQ(scans[0].stamp_ns, 1673400471'900000000);
    EXPECT_EQ(scans[1].stamp_ns, 1673400472'250000000);
    EXPECT_EQ(scans[2].stamp_ns, 1673400472'500000000);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(tag_of(scans[static_cast<size_t>(k)]), k);
  }
}

TEST(ScanFolder, PcdFolderWithABadFrameInTheMiddle) {
  const fs::path dir = test::scratch_dir("scan_folder_bad_frame");
  for (int n = 0; n < 3; ++n) {
    Scan scan = vlp16_scan(n);
    scan.stamp_ns = 1000 + n;
    write_scan_pcd(scan, (dir / ("frame_" + std::to_string(n) + ".pcd")).string());
  }
  fs::resize_file(dir / "frame_1.pcd", 300);
  const auto source = open_scan_folder(dir.string(), {});
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(tag_of(scans[1]), 2);
  EXPECT_EQ(scans[1].stamp_ns, 1002);  // from the file's own comment
  EXPECT_EQ(source->stats().frames_skipped, 1u);
}

TEST(ScanFolder, SimulatedSequence) {
  const fs::path dir = test::scratch_dir("scan_folder_sequence");
  for (int n = 0; n < 2; ++n) {
    write_scan_pcd(vlp16_scan(n), (dir / ("frame_00000" + std::to_string(n) + ".pcd")).string());
  }
  write_text(dir / "sequence.yaml",
             "format: featsense-sequence\nversion: 1\nsensor: vlp16\nrate_hz: 20\nframes:\n"
             "  - {file: frame_000000.pcd, stamp_ns: 1700000000000000000}\n"
             "  - {file: frame_000001.pcd, stamp_ns: 1700000000050000000}\n"
             "  - {file: frame_000002.pcd, stamp_ns: 1700000000100000000}\n");
  const auto source = open_scan_folder(dir.string(), {});
  EXPECT_EQ(source->info().format, "simulated");
  EXPECT_TRUE(source->info().sensor_from_metadata);
  EXPECT_EQ(source->info().frames, 3u);
  const std::vector<Scan> scans = read_all(*source);
  ASSERT_EQ(scans.size(), 2u);  // frame_000002.pcd is missing: skipped
  EXPECT_EQ(scans[1].stamp_ns, 1700000000050000000);
  EXPECT_EQ(tag_of(scans[1]), 1);
  EXPECT_EQ(source->stats().frames_skipped, 1u);

  // An inline sensor of another shape: the 16-row frames do not fit its 8 beams, and a
  // folder without a single readable frame is an error.
  write_text(dir / "sequence.yaml",
             "format: featsense-sequence\nversion: 1\n"
             "sensor: {name: sim-8, beams: 8, columns: 1800, rate_hz: 10, "
             "vfov_deg: [7, -7], beam_origin_offset_m: 0, min_range_m: 0.1, max_range_m: 50}\n"
             "frames:\n  - {file: frame_000000.pcd, stamp_ns: 5}\n");
  EXPECT_NE(error_of(dir).find(
                "no readable scan; the last error: " + (dir / "frame_000000.pcd").string() +
                ": an organized cloud of 16 rows for a sensor of 8 beams"),
            std::string::npos)
      << error_of(dir);
  write_text(dir / "sequence.yaml",
             "format: featsense-sequence\nversion: 1\n"
             "sensor: {name: sim-16, beams: 16, columns: 1800, rate_hz: 10, "
             "vfov_deg: [15, -15], beam_origin_offset_m: 0, min_range_m: 0.1, max_range_m: 50}\n"
             "frames:\n  - {file: frame_000000.pcd, stamp_ns: 5}\n");
  const auto inline_sensor = open_scan_folder(dir.string(), {});
  EXPECT_EQ(inline_sensor->info().sensor.name, "sim-16");
  EXPECT_EQ(inline_sensor->info().fields,
            (std::vector<std::string>{"x", "y", "z", "range", "t", "ring"}));
  const std::optional<Scan> only = inline_sensor->next();
  ASSERT_TRUE(only);
  EXPECT_EQ(only->stamp_ns, 5);
  EXPECT_FALSE(inline_sensor->next());

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"format: other\nversion: 1\nsensor: vlp16\nframes: []\n", "format must be"},
      {"format: featsense-sequence\nversion: 2\nsensor: vlp16\nframes: []\n", "version 2"},
      {"format: featsense-sequence\nversion: 1\nsensor: vlp61\nframes: []\n", "did you mean"},
      {"format: featsense-sequence\nversion: 1\nsensor: vlp16\nframes: []\nextra: 1\n",
       "unknown key 'extra'"},
      {"format: featsense-sequence\nversion: 1\nsensor: vlp16\nframes:\n  - {file: ../x.pcd, "
       "stamp_ns: 1}\n",
       "inside the folder"},
      {"format: featsense-sequence\nversion: 1\nsensor: vlp16\nframes:\n  - {file: a.pcd}\n",
       "frames[0].stamp_ns"},
      {"format: featsense-sequence\nversion: 1\nsensor: vlp16\nframes: []\n", "lists no frames"},
      {"[unclosed\n", "invalid YAML"},
  };
  for (const auto& [text, expected] : bad) {
    write_text(dir / "sequence.yaml", text);
    const std::string message = error_of(dir);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "', got '" << message << "'";
    EXPECT_NE(message.find("sequence.yaml"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace featsense::slam
