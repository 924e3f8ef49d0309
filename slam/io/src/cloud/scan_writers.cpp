// write_scan_pcd(), write_scan_ply(), write_scan_kitti_bin(): one scan per file.

#include "featsense/slam/io/scan_writers.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <vector>

#include "cloud/scalar_type.hpp"

namespace featsense::slam {
namespace {

using cloud::store_f32_le;
using cloud::store_le;

/// Field names are single words in both formats.
std::string field_name(const std::string& channel) {
  std::string name = channel.empty() ? std::string("channel") : channel;
  for (char& c : name) {
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

/// x y z range t (float32) ring (uint16) and one float32 per channel: the record both the
/// PCD and the PLY writer store, little-endian.
class PointRecord {
 public:
  explicit PointRecord(const Scan& scan) : scan_(scan) {}

  size_t bytes() const { return 5 * 4 + 2 + 4 * scan_.channels.size(); }

  /// Writes cell i (of row `row`) at `out`; invalid cells get NaN geometry.
  void store(size_t i, int row, uint8_t* out) const {
    const bool valid = scan_.valid[i] != 0;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const Eigen::Vector3f& p = scan_.xyz[i];
    store_f32_le(out + 0, valid ? p.x() : nan);
    store_f32_le(out + 4, valid ? p.y() : nan);
    store_f32_le(out + 8, valid ? p.z() : nan);
    store_f32_le(out + 12, valid ? scan_.range_m[i] : nan);
    store_f32_le(out + 16, scan_.time_offset_s[i]);
    store_le(out + 20, static_cast<uint16_t>(row), 2);
    uint8_t* channel = out + 22;
    for (const ScanChannel& c : scan_.channels) {
      store_f32_le(channel, c.values[i]);
      channel += 4;
    }
  }

 private:
  const Scan& scan_;
};

void write_file(const std::string& path, const std::string& header,
                const std::vector<uint8_t>& body) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw WriteError(path + ": cannot open for writing");
  file.write(header.data(), static_cast<std::streamsize>(header.size()));
  file.write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
  file.close();
  if (!file) throw WriteError(path + ": write failed (disk full?)");
}

void check_scan(const Scan& scan, const std::string& path) {
  const size_t n = scan.size();
  bool consistent = scan.rows >= 0 && scan.cols >= 0 && scan.xyz.size() == n &&
                    scan.range_m.size() == n && scan.time_offset_s.size() == n &&
                    scan.valid.size() == n && scan.rows <= 65535;
  for (const ScanChannel& c : scan.channels) consistent = consistent && c.values.size() == n;
  if (!consistent) throw WriteError(path + ": the scan's arrays do not match rows x cols");
}

/// Where the sweep began: the column measured first (the first of equals), 0 for a scan
/// without times.
int earliest_column(const Scan& scan) {
  const std::vector<std::optional<float>> times = scan.column_time_offsets_s();
  int first = 0;
  std::optional<float> earliest;
  for (int col = 0; col < scan.cols; ++col) {
    const std::optional<float>& t = times[static_cast<size_t>(col)];
    if (t && (!earliest || *t < *earliest)) {
      earliest = t;
      first = col;
    }
  }
  return first;
}

}  // namespace

void write_scan_pcd(const Scan& scan, const std::string& path) {
  check_scan(scan, path);
  std::string fields = "x y z range t ring", sizes = "4 4 4 4 4 2", types = "F F F F F U",
              counts = "1 1 1 1 1 1";
  for (const ScanChannel& c : scan.channels) {
    fields += " " + field_name(c.name);
    sizes += " 4";
    types += " F";
    counts += " 1";
  }
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "# featsense stamp_ns " +
      std::to_string(scan.stamp_ns) +
      "\n"
      "VERSION 0.7\n"
      "FIELDS " +
      fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\nWIDTH " +
      std::to_string(scan.cols) + "\nHEIGHT " + std::to_string(scan.rows) +
      "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(scan.size()) + "\nDATA binary\n";
  const PointRecord record(scan);
  std::vector<uint8_t> body(scan.size() * record.bytes());
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      const size_t i = scan.index(r, c);
      record.store(i, r, body.data() + i * record.bytes());
    }
  }
  write_file(path, header, body);
}

void write_scan_ply(const Scan& scan, const std::string& path) {
  check_scan(scan, path);
  const PointRecord record(scan);
  const size_t valid = scan.valid_count();
  std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment featsense stamp_ns " +
      std::to_string(scan.stamp_ns) + "\nelement vertex " + std::to_string(valid) +
      "\nproperty float x\nproperty float y\nproperty float z\nproperty float range\n"
      "property float t\nproperty ushort ring\n";
  for (const ScanChannel& c : scan.channels)
    header += "property float " + field_name(c.name) + "\n";
  header += "end_header\n";
  std::vector<uint8_t> body(valid * record.bytes());
  uint8_t* out = body.data();
  for (int r = 0; r < scan.rows; ++r) {
    for (int c = 0; c < scan.cols; ++c) {
      const size_t i = scan.index(r, c);
      if (!scan.valid[i]) continue;
      record.store(i, r, out);
      out += record.bytes();
    }
  }
  write_file(path, header, body);
}

void write_scan_kitti_bin(const Scan& scan, const std::string& path) {
  check_scan(scan, path);
  const ScanChannel* intensity = scan.intensity();
  float largest = 0.0f;
  if (intensity) {
    for (size_t i = 0; i < scan.size(); ++i) {
      if (scan.valid[i] && std::isfinite(intensity->values[i])) {
        largest = std::max(largest, intensity->values[i]);
      }
    }
  }
  std::vector<uint8_t> body;
  body.reserve(scan.valid_count() * 16);
  uint8_t point[16];
  // The points in the order they were measured, which is all that tells their times to a
  // reader of a format without them (azimuth_times.hpp).
  const int first_col = earliest_column(scan);
  for (int k = 0; k < scan.cols; ++k) {
    const int col = (first_col + k) % scan.cols;
    for (int row = 0; row < scan.rows; ++row) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      const float value = intensity && largest > 0.0f ? intensity->values[i] / largest : 0.0f;
      store_f32_le(point + 0, scan.xyz[i].x());
      store_f32_le(point + 4, scan.xyz[i].y());
      store_f32_le(point + 8, scan.xyz[i].z());
      store_f32_le(point + 12, std::isfinite(value) ? std::clamp(value, 0.0f, 1.0f) : 0.0f);
      body.insert(body.end(), point, point + 16);
    }
  }
  write_file(path, "", body);
}

}  // namespace featsense::slam
