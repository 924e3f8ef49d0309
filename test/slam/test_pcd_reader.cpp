// The PCD reader: files written here by a small independent writer, the Velodyne recordings
// in ../shared/data, and headers that lie.

#include <gtest/gtest.h>
#include <lzf.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <unordered_map>

#include "common/file_bytes.hpp"
#include "common/pcd_test_writer.hpp"
#include "common/test_data.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/readers.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

using test::Mode;
using test::TestField;

std::string lzf_library(const std::string& plain) {
  std::string out(plain.size() + plain.size() / 16 + 64, '\0');
  const unsigned int n = lzf_compress(plain.data(), static_cast<unsigned int>(plain.size()),
                                      out.data(), static_cast<unsigned int>(out.size()));
  EXPECT_GT(n, 0u);
  out.resize(n);
  return out;
}

/// The test writer with liblzf's compressor for Mode::kCompressedLzf.
std::string test_pcd(const std::vector<TestField>& fields,
                     const std::vector<std::vector<double>>& values, Mode mode, int width = -1,
                     int height = 1) {
  return test::pcd_bytes(fields, values, mode, width, height, lzf_library);
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// The InputError message of decoding `bytes`, or "" when it decodes.
std::string decode_error(const std::string& bytes) {
  try {
    decode_pcd(bytes, "test.pcd");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A cloud with every kind of field: x y z float, a 3-value normal (skipped), intensity u16,
// a padding byte, ring u8, t u32 ns.
const std::vector<TestField> kMixedFields = {
    {"x", 'F', 4},         {"y", 'F', 4}, {"z", 'F', 4},    {"normal", 'F', 4, 3},
    {"intensity", 'U', 2}, {"_", 'U', 1}, {"ring", 'U', 1}, {"t", 'U', 4}};

std::vector<std::vector<double>> mixed_points(int n) {
  std::mt19937 random(3);
  std::uniform_real_distribution<float> coordinate(-20.0f, 20.0f);
  // Coordinates that are floats already, so that the file's float32 x y z hold them exactly.
  auto next = [&] { return static_cast<double>(coordinate(random)); };
  std::vector<std::vector<double>> points;
  for (int i = 0; i < n; ++i) {
    points.push_back({next(), next(), next(), 0.5, -0.5, 1.0, static_cast<double>(i * 7 % 65536), 0,
                      static_cast<double>(i % 16), static_cast<double>(i) * 1000.0});
  }
  return points;
}

// ---------------------------------------------------------------------------------------

TEST(PcdReader, ReadsEveryDataKindExactly) {
  const auto points = mixed_points(500);
  for (Mode mode : {Mode::kAscii, Mode::kBinary, Mode::kCompressed, Mode::kCompressedLzf}) {
    SCOPED_TRACE(static_cast<int>(mode));
    const DecodedCloud d = decode_pcd(test_pcd(kMixedFields, points, mode), "mixed.pcd");
    EXPECT_EQ(d.format, "pcd");
    EXPECT_FALSE(d.organized());
    EXPECT_EQ(d.width, 500);
    EXPECT_EQ(d.fields,
              (std::vector<std::string>{"x", "y", "z", "normal", "intensity", "_", "ring", "t"}));
    ASSERT_EQ(d.cloud.size(), 500u);
    ASSERT_EQ(d.cloud.channels.size(), 1u);
    EXPECT_EQ(d.cloud.channels[0].name, "intensity");
    ASSERT_EQ(d.cloud.ring.size(), 500u);
    ASSERT_EQ(d.cloud.time_offset_s.size(), 500u);
    EXPECT_TRUE(d.cloud.range_m.empty());
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_EQ(d.cloud.xyz[i],
                Eigen::Vector3d(points[i][0], points[i][1], points[i][2]).cast<float>());
      EXPECT_EQ(d.cloud.channels[0].values[i], static_cast<float>(points[i][6]));
      EXPECT_EQ(d.cloud.ring[i], static_cast<int>(points[i][8]));
      // u32 t counts nanoseconds.
      EXPECT_FLOAT_EQ(d.cloud.time_offset_s[i], static_cast<float>(points[i][9] * 1e-9));
    }
  }
}

TEST(PcdReader, TimeUnitsAndAbsoluteTimes) {
  const std::vector<TestField> float_time = {
      {"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"time", 'F', 4}};
  const DecodedCloud seconds =
      decode_pcd(test_pcd(float_time, {{1, 2, 3, 0.05}, {1, 2, 4, -0.01}}, Mode::kBinary), "s");
  EXPECT_FLOAT_EQ(seconds.cloud.time_offset_s[0], 0.05f);
  EXPECT_FLOAT_EQ(seconds.cloud.time_offset_s[1], -0.01f);
  EXPECT_FALSE(seconds.stamp_ns);

  // Seconds since 1970 in a double: offsets from the earliest, which becomes the stamp.
  const std::vector<TestField> epoch = {
      {"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"timestamp", 'F', 8}};
  const DecodedCloud absolute = decode_pcd(
      test_pcd(epoch, {{1, 2, 3, 1673400472.25}, {1, 2, 4, 1673400472.20}}, Mode::kBinary), "a");
  ASSERT_TRUE(absolute.stamp_ns);
  EXPECT_NEAR(static_cast<double>(*absolute.stamp_ns), 1673400472.20e9, 1e3);
  EXPECT_NEAR(absolute.cloud.time_offset_s[0], 0.05f, 1e-6f);
  EXPECT_EQ(absolute.cloud.time_offset_s[1], 0.0f);

  // Nanoseconds since 1970 in an integer field.
  const std::vector<TestField> epoch_ns = {
      {"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"t", 'U', 8}};
  const DecodedCloud ns = decode_pcd(
      test_pcd(epoch_ns, {{1, 2, 3, 1.6734e18 + 2e6}, {1, 2, 4, 1.6734e18}}, Mode::kBinary), "n");
  ASSERT_TRUE(ns.stamp_ns);
  EXPECT_NEAR(static_cast<double>(*ns.stamp_ns), 1.6734e18, 512.0);
  EXPECT_NEAR(ns.cloud.time_offset_s[0], 0.002f, 1e-6f);
}

TEST(PcdReader, TimesThatCannotBeWithinTheRevolutionAreDropped) {
  // `time` in float seconds spanning 5 s over a full turn: not one revolution of 0.1 s.
  const config::SensorModel vlp16 = config::sensor_preset("vlp16");
  std::vector<std::vector<double>> points;
  for (int c = 0; c < 1800; c += 10) {
    const double a = -2 * M_PI * c / 1800;
    points.push_back({5 * std::cos(a), 5 * std::sin(a), 0.0, 0.0, 5.0 * c / 1800});
  }
  const DecodedCloud d = decode_pcd(
      test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"ring", 'U', 1}, {"time", 'F', 4}},
               points, Mode::kBinary),
      "slow.pcd");
  std::vector<std::string> warnings;
  const Scan scan = cloud_to_scan(d, vlp16, "slow.pcd", nullptr, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("more than two of 100.0"), std::string::npos) << warnings[0];
  for (float t : scan.time_offset_s) EXPECT_EQ(t, 0.0f);

  // The same over one revolution is kept.
  for (auto& p : points) p[4] /= 50.0;
  const DecodedCloud ok = decode_pcd(
      test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"ring", 'U', 1}, {"time", 'F', 4}},
               points, Mode::kBinary),
      "ok.pcd");
  warnings.clear();
  const Scan kept = cloud_to_scan(ok, vlp16, "ok.pcd", nullptr, &warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_FLOAT_EQ(kept.time_offset_s[kept.index(15, 900)], static_cast<float>(0.1 * 900 / 1800));
}

TEST(PcdReader, OrganizedCloudMapsCellByCellAndFlipsBottomFirstRows) {
  // 4 rows x 6 columns at elevations +3, +1, -1, -3 degrees, one cell empty (NaN).
  const double elevations_deg[4] = {3, 1, -1, -3};
  const std::vector<TestField> fields = {
      {"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"reflectivity", 'U', 2}};
  for (bool bottom_first : {false, true}) {
    std::vector<std::vector<double>> cells;
    for (int r = 0; r < 4; ++r) {
      const int row = bottom_first ? 3 - r : r;
      for (int c = 0; c < 6; ++c) {
        const double e = elevations_deg[row] * M_PI / 180.0, a = -2.0 * M_PI * c / 6;
        if (row == 1 && c == 2) {
          const double nan = std::numeric_limits<double>::quiet_NaN();
          cells.push_back({nan, nan, nan, 0});
          continue;
        }
        cells.push_back({10 * std::cos(e) * std::cos(a), 10 * std::cos(e) * std::sin(a),
                         10 * std::sin(e), static_cast<double>(row * 10 + c)});
      }
    }
    // ascii spells the empty cell "nan", as PCL writes it.
    const Mode mode = bottom_first ? Mode::kAscii : Mode::kCompressed;
    const DecodedCloud d = decode_pcd(test_pcd(fields, cells, mode, 6, 4), "org.pcd");
    ASSERT_TRUE(d.organized());
    std::string why;
    const config::SensorModel sensor = choose_sensor(d, SourceOptions{}, "org.pcd", &why);
    EXPECT_EQ(sensor.beams, 4);
    EXPECT_EQ(sensor.columns, 6);
    EXPECT_NE(why.find("measured"), std::string::npos) << why;
    OrganizeStats stats;
    const Scan scan = cloud_to_scan(d, sensor, "org.pcd", &stats);
    EXPECT_EQ(stats.dropped_invalid, 1u);
    ASSERT_EQ(scan.rows, 4);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 6; ++c) {
        const size_t i = scan.index(r, c);
        EXPECT_EQ(scan.valid[i], !(r == 1 && c == 2));
        if (scan.valid[i]) {
          EXPECT_EQ(scan.channel("reflectivity")->values[i], r * 10 + c);
        }
      }
    }
    // Row 0 highest after the flip; measured elevations follow.
    EXPECT_NEAR(sensor.elevation_rad[0], 3 * M_PI / 180, 1e-6);
    EXPECT_NEAR(sensor.elevation_rad[3], -3 * M_PI / 180, 1e-6);
  }
}

/// An organized cloud of `beams` rows x 8 columns on `sensor`'s beams, rows listed in
/// `rows_with_points` only.
DecodedCloud organized_on(const config::SensorModel& sensor, const std::vector<int>& rows) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::vector<double>> cells;
  for (int r = 0; r < sensor.beams; ++r) {
    const bool used = std::find(rows.begin(), rows.end(), r) != rows.end();
    for (int c = 0; c < 8; ++c) {
      const double e = sensor.elevation_rad[static_cast<size_t>(r)], a = -2 * M_PI * c / 8;
      cells.push_back(used ? std::vector<double>{10 * std::cos(e) * std::cos(a),
                                                 10 * std::cos(e) * std::sin(a), 10 * std::sin(e)}
                           : std::vector<double>{nan, nan, nan});
    }
  }
  return decode_pcd(test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}}, cells, Mode::kBinary, 8,
                             sensor.beams),
                    "organized.pcd");
}

TEST(PcdReader, OrganizedCloudSensorFromItsRows) {
  const config::SensorModel os1_64 = config::sensor_preset("os1-64");
  std::vector<int> all(64);
  std::iota(all.begin(), all.end(), 0);
  std::string why;
  // Rows on the OS1-64's beams: that preset, not the HDL-64 that 64 rows alone suggest.
  EXPECT_EQ(choose_sensor(organized_on(os1_64, all), SourceOptions{}, "o", &why).name, "os1-64")
      << why;
  // Rows on no preset's beams: elevations measured.
  config::SensorModel odd = os1_64;
  for (double& e : odd.elevation_rad) e *= 0.8;
  const config::SensorModel measured = choose_sensor(organized_on(odd, all), SourceOptions{}, "o");
  EXPECT_EQ(measured.beams, 64);
  EXPECT_EQ(measured.columns, 8);
  for (size_t r = 0; r < 64; ++r)
    EXPECT_NEAR(measured.elevation_rad[r], odd.elevation_rad[r], 1e-6);
  // Too few rows with points to measure: the preset with that many beams.
  EXPECT_EQ(choose_sensor(organized_on(odd, {3, 40}), SourceOptions{}, "o", &why).name, "hdl64")
      << why;
  // A preset given that does not have one beam per row.
  SourceOptions options;
  options.sensor_preset = "vlp16";
  EXPECT_THROW(choose_sensor(organized_on(os1_64, all), options, "o"), InputError);
}

TEST(PcdReader, OlderHeaderWithoutVersion) {
  std::string text =
      test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}}, {{1, 2, 3}}, Mode::kAscii);
  text.erase(text.find("VERSION 0.7\n"), 12);
  EXPECT_EQ(decode_pcd(text, "old.pcd").cloud.xyz[0], Eigen::Vector3f(1, 2, 3));
}

// ---------------------------------------------------------------------------------------
// The Velodyne recordings.

/// Elevation of each row of a scan: the median over its valid points, degrees.
std::vector<double> row_elevations_deg(const Scan& scan) {
  std::vector<double> out;
  for (int r = 0; r < scan.rows; ++r) {
    std::vector<double> e;
    for (int c = 0; c < scan.cols; ++c) {
      const size_t i = scan.index(r, c);
      if (!scan.valid[i]) continue;
      const Eigen::Vector3d p = scan.xyz[i].cast<double>();
      e.push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())) * 180.0 / M_PI);
    }
    if (e.empty()) {
      out.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    std::nth_element(e.begin(), e.begin() + static_cast<long>(e.size() / 2), e.end());
    out.push_back(e[e.size() / 2]);
  }
  return out;
}

OrganizeStats organize_stats_of(const fs::path& path) {
  const DecodedCloud d = decode_pcd(test::file_bytes(path), path.string());
  OrganizeStats stats;
  cloud_to_scan(d, choose_sensor(d, SourceOptions{}, path.string()), path.string(), &stats);
  return stats;
}

TEST(PcdReader, Vlp16RecordingOrganizesIntoSixteenRings) {
  FEATSENSE_SHARED_FILE(path, "velodyne/vlp16_1673400472138016708.pcd");
  const auto source = open_pcd_file(path.string(), {});
  EXPECT_EQ(source->info().format, "pcd");
  EXPECT_EQ(source->info().sensor.name, "vlp16");  // 16 rings from the `channel` field
  EXPECT_EQ(source->info().frames, 1u);
  const std::optional<Scan> scan = source->next();
  ASSERT_TRUE(scan);
  EXPECT_FALSE(source->next());
  EXPECT_EQ(scan->rows, 16);
  EXPECT_EQ(scan->cols, 1800);
  EXPECT_EQ(scan->stamp_ns, 1673400472138016708);  // from the file name
  std::cout << "VLP-16: 14831 points in the file, " << scan->valid_count() << " valid cells; "
            << source->info().detail << "\n";
  // Every point is a return (no zero points, none off the beams). The driver repeats points
  // at packet borders (same azimuth twice in a ring, about 9 % of the points of ring 12),
  // so some share a cell: valid cells + points in occupied cells = the file's points.
  const OrganizeStats stats = organize_stats_of(path);
  EXPECT_EQ(stats.input_points, 14831u);
  EXPECT_EQ(stats.dropped_invalid, 0u);
  EXPECT_EQ(stats.dropped_outside, 0u);
  EXPECT_EQ(scan->valid_count() + stats.dropped_collisions, 14831u);
  EXPECT_LT(stats.dropped_collisions, 14831u * 15 / 100);
  ASSERT_NE(scan->channel("intensity"), nullptr);

  // Row elevations from xyz: monotonic, on the preset's 2-degree steps from +15 to -15.
  // The file's lowest ring (channel 0, -15 deg) holds no points.
  const std::vector<double> rows = row_elevations_deg(*scan);
  double previous = 90.0;
  int measured = 0;
  for (int r = 0; r < 16; ++r) {
    if (std::isnan(rows[static_cast<size_t>(r)])) continue;
    ++measured;
    EXPECT_LT(rows[static_cast<size_t>(r)], previous);
    previous = rows[static_cast<size_t>(r)];
    EXPECT_NEAR(rows[static_cast<size_t>(r)], 15.0 - 2.0 * r, 0.5) << "row " << r;
  }
  EXPECT_EQ(measured, 15);
  // time_stamp (u32) restarts with every packet of ~1.3 ms: it is not a time within the
  // revolution, so the reader drops it with a warning (the file wins over the field's name).
  bool warned = false;
  for (const auto& w : source->stats().warnings)
    warned = warned || w.find("per packet") != std::string::npos;
  EXPECT_TRUE(warned);
  for (size_t i = 0; i < scan->size(); ++i) EXPECT_EQ(scan->time_offset_s[i], 0.0f);
}

/// All-zero points of an HDL-32 file, counted straight from its bytes (x y z intensity
/// float32 after "DATA binary\n").
size_t count_zero_points(const fs::path& path, size_t* total) {
  const std::string bytes = test::file_bytes(path);
  const size_t start = bytes.find("DATA binary\n") + 12;
  *total = (bytes.size() - start) / 16;
  size_t zeros = 0;
  for (size_t i = 0; i < *total; ++i) {
    float xyz[3];
    std::memcpy(xyz, bytes.data() + start + i * 16, 12);
    zeros += (xyz[0] == 0 && xyz[1] == 0 && xyz[2] == 0) ? 1 : 0;
  }
  return zeros;
}

Scan read_hdl32(const fs::path& path, OrganizeStats* stats) {
  const DecodedCloud d = decode_pcd(test::file_bytes(path), path.string());
  std::string why;
  const config::SensorModel sensor = choose_sensor(d, SourceOptions{}, path.string(), &why);
  EXPECT_EQ(sensor.name, "hdl32") << why;
  return cloud_to_scan(d, sensor, path.string(), stats);
}

TEST(PcdReader, Hdl32RecordingsDropTheirZeroPoints) {
  for (const char* name : {"velodyne/251370668.pcd", "velodyne/251371071.pcd"}) {
    FEATSENSE_SHARED_FILE(path, name);
    size_t total = 0;
    const size_t zeros = count_zero_points(path, &total);
    OrganizeStats stats;
    const Scan scan = read_hdl32(path, &stats);
    EXPECT_EQ(scan.rows, 32);
    EXPECT_EQ(scan.cols, 2170);
    EXPECT_EQ(stats.input_points, total);
    EXPECT_EQ(stats.dropped_invalid, zeros);
    EXPECT_EQ(stats.dropped_outside, 0u);  // every point on one of the 32 beams
    EXPECT_EQ(scan.valid_count(), total - zeros - stats.dropped_collisions);
    // Columns of the recording and of the preset (2170) differ slightly: ~2 % share a cell.
    EXPECT_LT(stats.dropped_collisions, total * 3 / 100);
    std::cout << name << ": " << total << " points, " << zeros << " all-zero, "
              << stats.dropped_collisions << " in occupied cells, " << scan.valid_count()
              << " valid\n";
    const std::vector<double> rows = row_elevations_deg(scan);
    for (int r = 0; r < 32; ++r) {
      EXPECT_NEAR(rows[static_cast<size_t>(r)], 10.67 - r * (41.34 / 31), 0.1) << r;
    }
  }
}

/// Median distance from every `step`-th valid point of `a` (mapped by T) to its nearest
/// neighbour in `b`; hashed 0.5 m cells, distances beyond 0.5 m counted as 0.5 m.
double median_nearest_distance(const Scan& a, const Eigen::Matrix4d& T, const Scan& b,
                               size_t step) {
  constexpr double kCell = 0.5;
  auto key = [](const Eigen::Vector3d& p, int dx, int dy, int dz) {
    const int64_t x = static_cast<int64_t>(std::floor(p.x() / kCell)) + dx;
    const int64_t y = static_cast<int64_t>(std::floor(p.y() / kCell)) + dy;
    const int64_t z = static_cast<int64_t>(std::floor(p.z() / kCell)) + dz;
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  std::unordered_map<int64_t, std::vector<Eigen::Vector3d>> grid;
  for (size_t i = 0; i < b.size(); ++i) {
    if (b.valid[i]) grid[key(b.xyz[i].cast<double>(), 0, 0, 0)].push_back(b.xyz[i].cast<double>());
  }
  std::vector<double> distances;
  size_t seen = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!a.valid[i] || seen++ % step != 0) continue;
    const Eigen::Vector3d p = (T * a.xyz[i].cast<double>().homogeneous()).head<3>();
    double best = kCell;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(p, dx, dy, dz));
          if (it == grid.end()) continue;
          for (const auto& q : it->second) best = std::min(best, (p - q).norm());
        }
      }
    }
    distances.push_back(best);
  }
  std::nth_element(distances.begin(), distances.begin() + static_cast<long>(distances.size() / 2),
                   distances.end());
  return distances[distances.size() / 2];
}

TEST(PcdReader, Hdl32RelativeTransformAlignsTheTwoScans) {
  FEATSENSE_SHARED_FILE(first_path, "velodyne/251370668.pcd");
  FEATSENSE_SHARED_FILE(second_path, "velodyne/251371071.pcd");
  FEATSENSE_SHARED_FILE(relative_path, "velodyne/relative.txt");
  const Scan first = read_hdl32(first_path, nullptr);
  const Scan second = read_hdl32(second_path, nullptr);
  Eigen::Matrix4d T;
  std::ifstream in(relative_path);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) in >> T(r, c);
  }
  ASSERT_TRUE(in);
  const Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  const double identity = median_nearest_distance(second, I, first, 20);
  const double second_into_first = median_nearest_distance(second, T, first, 20);
  const double first_into_second = median_nearest_distance(first, T, second, 20);
  const double first_into_second_inverse = median_nearest_distance(first, T.inverse(), second, 20);
  std::cout << "median NN distance, 251371071 -> 251370668: identity " << identity
            << " m, relative.txt " << second_into_first << " m; 251370668 -> 251371071 with "
            << "relative.txt " << first_into_second << " m, with its inverse "
            << first_into_second_inverse << " m\n";
  // relative.txt maps points of the second scan (251371071) into the frame of the first
  // (251370668): p_first = T p_second.
  // (Most points are ground, close to the other scan's ground whatever the motion, so the
  // identity's median is already small.)
  EXPECT_LT(second_into_first, 0.8 * identity);
  EXPECT_LT(first_into_second_inverse, 0.8 * identity);
  EXPECT_LT(second_into_first, first_into_second);
}

// ---------------------------------------------------------------------------------------
// Sensor choice.

TEST(PcdReader, UnorganizedWithoutRingsNeedsAPreset) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-30, 30);
  std::vector<std::vector<double>> points;
  for (int i = 0; i < 1000; ++i)
    points.push_back({coordinate(random), coordinate(random), coordinate(random)});
  const DecodedCloud d = decode_pcd(
      test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}}, points, Mode::kBinary), "r.pcd");
  try {
    choose_sensor(d, SourceOptions{}, "r.pcd");
    FAIL() << "no preset fits random points";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--set sensor.preset="), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("os1-128"), std::string::npos) << e.what();
  }
  SourceOptions options;
  options.sensor_preset = "os1-64";
  EXPECT_EQ(choose_sensor(d, options, "r.pcd").name, "os1-64");
}

TEST(PcdReader, RingCountChoosesThePreset) {
  for (const auto& [rings, preset] : std::map<int, std::string>{
           {16, "vlp16"}, {32, "hdl32"}, {40, "hdl64"}, {64, "hdl64"}, {128, "os1-128"}}) {
    std::vector<std::vector<double>> points;
    for (int r = 0; r < rings; ++r) points.push_back({1, 0, 0.01 * r, static_cast<double>(r)});
    const DecodedCloud d =
        decode_pcd(test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"ring", 'U', 2}}, points,
                            Mode::kBinary),
                   "ring.pcd");
    EXPECT_EQ(choose_sensor(d, SourceOptions{}, "ring.pcd").name, preset) << rings;
  }
}

// ---------------------------------------------------------------------------------------
// Headers that lie, truncations, wrong types: one InputError naming the problem.

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(PcdReader, HeaderLiesAreErrorsNamingTheProblem) {
  const auto points = mixed_points(40);
  const std::string binary = test_pcd(kMixedFields, points, Mode::kBinary);
  const std::string compressed = test_pcd(kMixedFields, points, Mode::kCompressed);
  const std::string ascii = test_pcd(kMixedFields, points, Mode::kAscii);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {replace(binary, "POINTS 40", "POINTS 41"), "POINTS 41 differs from WIDTH x HEIGHT = 40"},
      {replace(binary, "WIDTH 40\nHEIGHT 1", "WIDTH 41\nHEIGHT 1"), "POINTS 40 differs"},
      {replace(replace(binary, "WIDTH 40", "WIDTH 80"), "POINTS 40", "POINTS 80"),
       "the header promises POINTS x point size"},
      {replace(binary, "SIZE 4 4 4 4 2 1 1 4", "SIZE 4 4 4 4 2 1 4"), "SIZE lists 7 values for 8"},
      {replace(binary, "TYPE F F F F U U U U", "TYPE F F F F U U U"), "TYPE lists 7 values"},
      {replace(binary, "COUNT 1 1 1 3", "COUNT 1 1 1"), "COUNT lists 7 values"},
      {replace(binary, "COUNT 1 1 1 3", "COUNT 1 1 1 0"), "COUNT of field 'normal'"},
      {replace(binary, "TYPE F F F", "TYPE U F F"),
       "'x' must be floating point (TYPE F, SIZE 4 or 8), is U4"},
      {replace(replace(binary, "TYPE F F F", "TYPE U F F"), "SIZE 4 4 4 4 2 1 1 4",
               "SIZE 1 4 4 4 2 1 1 4"),
       "'x' must be floating point (TYPE F, SIZE 4 or 8), is U1"},
      {replace(binary, "SIZE 4 4 4", "SIZE 1 4 4"), "field 'x' has TYPE F with SIZE 1"},
      {replace(binary, "TYPE F F F F U U U U", "TYPE F F F F U U Q U"),
       "field 'ring' has TYPE Q with SIZE 1, which PCD does not allow"},
      {replace(binary, "SIZE 4 4 4 4 2 1 1 4", "SIZE 4 4 4 4 2 1 3 4"),
       "field 'ring' has TYPE U with SIZE 3"},
      {replace(binary, "WIDTH 40", "WIDTH 99999999999"), "WIDTH x HEIGHT"},
      {replace(binary, "WIDTH 40", "WIDTH -4"), "WIDTH '-4' is not a non-negative integer"},
      {replace(binary, "HEIGHT 1", "HEIGHT 1\nHEIGHT 1"), "HEIGHT given twice"},
      {replace(binary, "DATA binary", "DATA binary_zipped"), "DATA 'binary_zipped'"},
      {replace(binary, "FIELDS x y", "FIELDS q y"), "no field 'x'"},
      {replace(binary, "FIELDS x y z", "FIELDS x y x"), "field 'x' appears twice"},
      {replace(binary, "COUNT 1 1 1", "COUNT 2 1 1"), "the header promises POINTS x point size"},
      {replace(replace(binary, "COUNT 1 1 1 3", "COUNT 2 1 1 2"), "WIDTH 40\nHEIGHT 1",
               "WIDTH 20\nHEIGHT 2"),
       "'x' must hold one value per point"},
      {replace(binary, "VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 1"), "VIEWPOINT needs 7"},
      {binary.substr(0, binary.find("DATA")), "no DATA line"},
      {"", "no DATA line"},
      {"hello world\n", "'hello' is not a PCD header keyword"},
      {replace(ascii, "DATA ascii\n", "DATA ascii\n1 2 3\n"),
       "ascii point 0 has 3 values, the header promises 10"},
      {replace(replace(ascii, "WIDTH 40", "WIDTH 41"), "POINTS 40", "POINTS 41") +
           std::string(500, ' '),
       "ascii data holds 40 points; the header promises 41"},
      {replace(ascii, "\n1", "\nabc"), "is not a number"},
  };
  for (const auto& [bytes, expected] : cases) {
    const std::string message = decode_error(bytes);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "', got '" << message << "'";
    EXPECT_EQ(message.rfind("test.pcd", 0), 0u) << message;  // names the file first
  }

  // binary_compressed sizes that lie.
  const size_t data = compressed.find("DATA binary_compressed\n") + 23;
  auto with_sizes = [&](uint32_t packed, uint32_t plain) {
    std::string out = compressed;
    std::memcpy(out.data() + data, &packed, 4);
    std::memcpy(out.data() + data + 4, &plain, 4);
    return out;
  };
  uint32_t packed = 0, plain = 0;
  std::memcpy(&packed, compressed.data() + data, 4);
  std::memcpy(&plain, compressed.data() + data + 4, 4);
  EXPECT_NE(decode_error(with_sizes(packed + 1, plain)).find("but only"), std::string::npos);
  EXPECT_NE(decode_error(with_sizes(packed, plain + 1)).find("uncompressed size"),
            std::string::npos);
  EXPECT_NE(decode_error(with_sizes(packed - 5, plain)).find("corrupt"), std::string::npos);
  EXPECT_NE(decode_error(with_sizes(0xffffffffu, 0xffffffffu)).find("but only"), std::string::npos);
  // A block far too small for what it claims to unpack to: refused before allocating.
  const std::string tiny = replace(replace(test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}},
                                                    {{1, 2, 3}}, Mode::kCompressed),
                                           "WIDTH 1", "WIDTH 100000000"),
                                   "POINTS 1", "POINTS 100000000");
  EXPECT_NE(decode_error(tiny).find("uncompressed size"), std::string::npos);
  std::string bomb = tiny;
  const size_t bomb_data = bomb.find("binary_compressed\n") + 18;
  const uint32_t claim = 1200000000u;
  std::memcpy(bomb.data() + bomb_data + 4, &claim, 4);
  bomb = replace(replace(bomb, "WIDTH 100000000", "WIDTH 100000000"), "POINTS 100000000",
                 "POINTS 100000000");
  EXPECT_NE(decode_error(bomb).find("cannot hold"), std::string::npos) << decode_error(bomb);
}

TEST(PcdReader, TruncatedFilesNeverCrash) {
  const auto points = mixed_points(60);
  for (Mode mode : {Mode::kBinary, Mode::kCompressed, Mode::kCompressedLzf, Mode::kAscii}) {
    const std::string full = test_pcd(kMixedFields, points, mode);
    for (size_t length = 0; length < full.size(); length += (length < 400 ? 1 : 7)) {
      const std::string message = decode_error(full.substr(0, length));
      // Binary data cut short always shows; ascii cut inside a number may still read.
      if (mode != Mode::kAscii) {
        EXPECT_FALSE(message.empty()) << "length " << length;
      }
    }
  }
}

TEST(PcdReader, EmptyAndMissingFiles) {
  const fs::path dir = test::scratch_dir("pcd_reader_empty");
  write_file(dir / "empty.pcd", "");
  try {
    open_pcd_file((dir / "empty.pcd").string(), {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.pcd: empty file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(open_pcd_file((dir / "missing.pcd").string(), {}), InputError);
  // No points at all is a frame without returns, not an error.
  const std::string none =
      test_pcd({{"x", 'F', 4}, {"y", 'F', 4}, {"z", 'F', 4}, {"ring", 'U', 1}}, {}, Mode::kBinary);
  EXPECT_EQ(decode_pcd(none, "none.pcd").cloud.size(), 0u);
  EXPECT_EQ(decode_pcd(replace(none, "DATA binary", "DATA binary_compressed"), "none").cloud.size(),
            0u);
}

// ---------------------------------------------------------------------------------------
// Speed (printed, not asserted).

TEST(PcdReader, Speed) {
  using Clock = std::chrono::steady_clock;
  auto frames_per_second = [](const std::function<void()>& read) {
    const auto start = Clock::now();
    int frames = 0;
    while (frames < 3 || Clock::now() - start < std::chrono::milliseconds(700)) {
      read();
      ++frames;
    }
    return frames / std::chrono::duration<double>(Clock::now() - start).count();
  };

  // 128 x 1024 organized, binary_compressed by liblzf: x y z t reflectivity nir ring.
  const config::SensorModel os1 = config::sensor_preset("os1-128");
  std::vector<std::vector<double>> cells;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> range(1.0, 40.0);
  for (int r = 0; r < 128; ++r) {
    for (int c = 0; c < 1024; ++c) {
      const double e = os1.elevation_rad[static_cast<size_t>(r)], a = -2 * M_PI * c / 1024,
                   d = range(random);
      cells.push_back({d * std::cos(e) * std::cos(a), d * std::cos(e) * std::sin(a),
                       d * std::sin(e), c * 97656.0, static_cast<double>(c % 256),
                       static_cast<double>(r * 3), static_cast<double>(r)});
    }
  }
  const std::string os1_file = test_pcd({{"x", 'F', 4},
                                         {"y", 'F', 4},
                                         {"z", 'F', 4},
                                         {"t", 'U', 4},
                                         {"reflectivity", 'U', 2},
                                         {"nir", 'U', 2},
                                         {"ring", 'U', 2}},
                                        cells, Mode::kCompressedLzf, 1024, 128);
  write_file(test::scratch_dir("pcd_reader_speed") / "os1_128x1024_compressed.pcd", os1_file);
  const DecodedCloud check = decode_pcd(os1_file, "os1.pcd");
  const config::SensorModel sensor = choose_sensor(check, SourceOptions{}, "os1.pcd");
  EXPECT_EQ(sensor.name, "os1-128");
  EXPECT_EQ(cloud_to_scan(check, sensor, "os1.pcd").valid_count(), 128u * 1024u);
  const double os1_fps = frames_per_second([&] {
    const DecodedCloud d = decode_pcd(os1_file, "os1.pcd");
    cloud_to_scan(d, sensor, "os1.pcd");
  });
  std::cout << "128 x 1024 binary_compressed PCD (" << os1_file.size() / 1024
            << " KiB): " << os1_fps << " frames/s decoded and organized\n";

  FEATSENSE_SHARED_FILE(hdl32, "velodyne/251370668.pcd");
  const double hdl_fps = frames_per_second([&] {
    const auto source = open_pcd_file(hdl32.string(), {});
    source->next();
  });
  std::cout << "HDL-32 binary PCD (69,088 points): " << hdl_fps
            << " frames/s read, sensor inferred, organized\n";
}

}  // namespace
}  // namespace featsense::slam
