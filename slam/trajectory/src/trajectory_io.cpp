// TUM and KITTI trajectory files: readers that name the file and line of any error.

#include "featsense/slam/trajectory/trajectory_io.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace featsense::slam {
namespace {

[[noreturn]] void fail(const std::string& path, size_t line, const std::string& what) {
  throw TrajectoryError(path + ":" + std::to_string(line) + ": " + what);
}

std::ifstream open_or_throw(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open trajectory file");
  return in;
}

bool skip_line(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

/// Reads exactly `count` numbers from the line; false if fewer, more or not numbers.
bool parse_numbers(const std::string& line, size_t count, std::vector<double>* values) {
  std::istringstream in(line);
  values->assign(count, 0.0);
  for (size_t i = 0; i < count; ++i) {
    if (!(in >> (*values)[i]) || !std::isfinite((*values)[i])) return false;
  }
  std::string rest;
  return !(in >> rest);
}

int64_t seconds_to_ns(double seconds) { return std::llround(seconds * 1e9); }

/// The first word of the line as nanoseconds, digit by digit: a double holds only about 16
/// digits, too few for Unix time in nanoseconds. Falls back to the double for exponents.
int64_t stamp_ns_of(const std::string& line, double as_double) {
  std::istringstream in(line);
  std::string word;
  in >> word;
  if (word.find_first_of("eE") != std::string::npos) return seconds_to_ns(as_double);
  const bool negative = !word.empty() && word[0] == '-';
  const size_t start = (!word.empty() && (word[0] == '-' || word[0] == '+')) ? 1 : 0;
  const size_t dot = word.find('.');
  const std::string whole =
      word.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
  std::string fraction = dot == std::string::npos ? "" : word.substr(dot + 1);
  if (whole.size() > 10) return seconds_to_ns(as_double);
  fraction = (fraction + "000000000").substr(0, 9);  // digits beyond 1 ns are dropped
  const int64_t ns = (whole.empty() ? 0 : std::stoll(whole)) * 1'000'000'000 + std::stoll(fraction);
  return negative ? -ns : ns;
}

}  // namespace

Trajectory read_tum(const std::string& path) {
  std::ifstream in = open_or_throw(path);
  Trajectory trajectory;
  std::string line;
  std::vector<double> v;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (skip_line(line)) continue;
    if (!parse_numbers(line, 8, &v)) {
      fail(path, number, "expected 8 numbers 'stamp_s tx ty tz qx qy qz qw' (TUM format)");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      fail(path, number,
           "quaternion is not of unit length (|q| = " + std::to_string(q.norm()) + ")");
    }
    const int64_t stamp = stamp_ns_of(line, v[0]);
    if (!trajectory.empty() && stamp <= trajectory.stamps_ns.back()) {
      fail(path, number, "time stamps must increase");
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    trajectory.push_back(stamp, T);
  }
  if (trajectory.empty()) throw TrajectoryError(path + ": no pose in the file");
  return trajectory;
}

Trajectory read_kitti(const std::string& path, const std::optional<std::string>& times_path) {
  std::ifstream in = open_or_throw(path);
  Trajectory trajectory;
  trajectory.has_stamps = false;
  std::string line;
  std::vector<double> v;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (skip_line(line)) continue;
    if (!parse_numbers(line, 12, &v)) {
      fail(path, number, "expected 12 numbers (3 x 4 pose matrix, row-major; KITTI format)");
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = v[static_cast<size_t>(4 * r + c)];
    }
    const Eigen::Matrix3d R = T.linear();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0) {
      fail(path, number, "the 3 x 3 part is not a rotation");
    }
    trajectory.push_back(static_cast<int64_t>(trajectory.size()), T);
  }
  if (trajectory.empty()) throw TrajectoryError(path + ": no pose in the file");
  if (times_path) {
    std::ifstream times = open_or_throw(*times_path);
    size_t index = 0;
    for (size_t number = 1; std::getline(times, line); ++number) {
      if (skip_line(line)) continue;
      if (!parse_numbers(line, 1, &v)) fail(*times_path, number, "expected one time in seconds");
      if (index >= trajectory.size()) {
        fail(*times_path, number, "more times than poses in " + path);
      }
      const int64_t stamp = stamp_ns_of(line, v[0]);
      if (index > 0 && stamp <= trajectory.stamps_ns[index - 1]) {
        fail(*times_path, number, "times must increase");
      }
      trajectory.stamps_ns[index++] = stamp;
    }
    if (index != trajectory.size()) {
      throw TrajectoryError(*times_path + ": " + std::to_string(index) + " times for " +
                            std::to_string(trajectory.size()) + " poses in " + path);
    }
    trajectory.has_stamps = true;
  }
  return trajectory;
}

std::string detect_trajectory_format(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError("cannot open trajectory " + path);
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    size_t count = 0;
    for (std::string field; fields >> field;) ++count;
    if (count == 0) continue;
    if (count == 8) return "tum";
    if (count == 12) return "kitti";
    throw TrajectoryError(path + ":" + std::to_string(number) + ": a line of " +
                          std::to_string(count) + " numbers is neither TUM (8) nor KITTI (12)");
  }
  throw TrajectoryError(path + " holds no pose");
}

Trajectory read_trajectory(const std::string& path, const std::string& format,
                           const std::optional<std::string>& times_path) {
  const std::string resolved = format == "auto" ? detect_trajectory_format(path) : format;
  if (resolved == "kitti") return read_kitti(path, times_path);
  if (resolved != "tum") {
    throw TrajectoryError("unknown trajectory format '" + format +
                          "' (expected auto, tum or kitti)");
  }
  if (times_path) {
    throw TrajectoryError(path + ": a times file (" + *times_path +
                          ") goes with KITTI poses, and this is a TUM file with its own stamps");
  }
  return read_tum(path);
}

const char* const kTumHeader = "# timestamp tx ty tz qx qy qz qw\n";

std::string tum_line(int64_t stamp_ns, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d t = T.translation();
  const int64_t whole = stamp_ns / 1000000000;
  const int64_t frac = stamp_ns % 1000000000;
  char line[256];
  std::snprintf(line, sizeof line, "%s%lld.%09lld %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                stamp_ns < 0 ? "-" : "", static_cast<long long>(std::llabs(whole)),
                static_cast<long long>(std::llabs(frac)), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                q.w());
  return line;
}

void write_tum(const Trajectory& trajectory, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw TrajectoryError(path + ": cannot write trajectory file");
  out << kTumHeader;
  for (size_t i = 0; i < trajectory.size(); ++i)
    out << tum_line(trajectory.stamps_ns[i], trajectory.poses[i]);
  if (!out) throw TrajectoryError(path + ": write failed");
}

void write_kitti(const Trajectory& trajectory, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw TrajectoryError(path + ": cannot write trajectory file");
  char number[32];
  for (const Eigen::Isometry3d& T : trajectory.poses) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        std::snprintf(number, sizeof number, "%.9e", T.matrix()(r, c));
        out << number << (r == 2 && c == 3 ? "\n" : " ");
      }
    }
  }
  if (!out) throw TrajectoryError(path + ": write failed");
}

}  // namespace featsense::slam
