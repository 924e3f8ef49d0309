#include "featsense/slam/io/imu_csv.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

constexpr size_t kSkippedKept = 5;

std::string trimmed(const std::string& line) {
  const size_t begin = line.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return {};
  const size_t end = line.find_last_not_of(" \t\r");
  return line.substr(begin, end - begin + 1);
}

/// Reads the comma-separated fields of a data line; false where one is missing or bad.
bool parse_line(const std::string& line, ImuSample* sample) {
  const char* p = line.c_str();
  char* end = nullptr;
  errno = 0;
  const long long stamp = std::strtoll(p, &end, 10);
  if (end == p || errno != 0) return false;
  sample->stamp_ns = static_cast<int64_t>(stamp);
  double values[6];
  for (double& value : values) {
    p = end;
    while (*p == ' ') ++p;
    if (*p != ',') return false;
    ++p;
    value = std::strtod(p, &end);
    if (end == p || !std::isfinite(value)) return false;
  }
  while (*end == ' ') ++end;
  if (*end != '\0') return false;
  sample->accel_mps2 = Eigen::Vector3d(values[0], values[1], values[2]);
  sample->gyro_radps = Eigen::Vector3d(values[3], values[4], values[5]);
  return true;
}

}  // namespace

void append_imu_csv_line(const ImuSample& sample, std::string* out) {
  char line[256];
  // 17 significant digits: every double reads back as the same double.
  std::snprintf(line, sizeof line, "%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                static_cast<long long>(sample.stamp_ns), sample.accel_mps2.x(),
                sample.accel_mps2.y(), sample.accel_mps2.z(), sample.gyro_radps.x(),
                sample.gyro_radps.y(), sample.gyro_radps.z());
  *out += line;
}

std::vector<ImuSample> parse_imu_csv(const std::string& text, const std::string& origin,
                                     std::vector<std::string>* skipped, size_t* skipped_count) {
  std::vector<ImuSample> samples;
  size_t line_number = 0;
  size_t start = 0;
  bool header_seen = false;
  while (start < text.size()) {
    size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    const std::string line = trimmed(text.substr(start, stop - start));
    start = stop + 1;
    ++line_number;
    if (line.empty()) continue;
    if (!header_seen) {
      if (line != kImuCsvHeader) {
        throw InputError(origin + ": line " + std::to_string(line_number) +
                         " must be the header '" + kImuCsvHeader + "'");
      }
      header_seen = true;
      continue;
    }
    ImuSample sample;
    if (parse_line(line, &sample)) {
      samples.push_back(sample);
      continue;
    }
    ++*skipped_count;
    if (skipped->size() < kSkippedKept) {
      skipped->push_back(origin + ": line " + std::to_string(line_number) +
                         " is not a stamp and six finite numbers; skipped");
    }
  }
  if (!header_seen)
    throw InputError(origin + ": empty (expected the header '" + std::string(kImuCsvHeader) + "')");
  return samples;
}

}  // namespace featsense::slam
