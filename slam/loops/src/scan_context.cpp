#include "featsense/slam/loops/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace featsense::slam::loops {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The ground under the sensor: a low percentile of the heights nearby, so that a few points
/// below the road (noise, a kerb's drop) do not set it.
float ground_height(const std::vector<Eigen::Vector3f>& points, double min_range_m) {
  std::vector<float> heights;
  heights.reserve(points.size() / 4);
  for (const Eigen::Vector3f& p : points) {
    const double range = std::hypot(p.x(), p.y());
    if (p.allFinite() && range >= min_range_m && range < 20.0) heights.push_back(p.z());
  }
  if (heights.empty()) return 0.0f;
  const size_t k = heights.size() / 20;
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k),
                   heights.end());
  return heights[k];
}

/// Per ring, the fraction of its sectors that hold a point.
void fill_ring_key(ScanContext& context) {
  context.ring_key.assign(static_cast<size_t>(context.rings), 0.0f);
  for (int r = 0; r < context.rings; ++r) {
    int occupied = 0;
    for (int s = 0; s < context.sectors; ++s) occupied += context.at(r, s) > 0.0f ? 1 : 0;
    context.ring_key[static_cast<size_t>(r)] = static_cast<float>(occupied) / context.sectors;
  }
}

}  // namespace

ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& levelled_points,
                              const ScanContextSettings& settings) {
  if (settings.rings < 1 || settings.sectors < 1 || !(settings.max_range_m > settings.min_range_m))
    throw std::invalid_argument("scan context: rings, sectors and the range must be positive");
  ScanContext out;
  out.rings = settings.rings;
  out.sectors = settings.sectors;
  out.bins.assign(static_cast<size_t>(settings.rings * settings.sectors), 0.0f);
  const float ground = ground_height(levelled_points, settings.min_range_m);
  const double ring_width = settings.max_range_m / settings.rings;
  const double sector_width = 2.0 * kPi / settings.sectors;
  for (const Eigen::Vector3f& p : levelled_points) {
    if (!p.allFinite()) continue;
    const double range = std::hypot(p.x(), p.y());
    if (range < settings.min_range_m || range >= settings.max_range_m) continue;
    const int ring = std::min(static_cast<int>(range / ring_width), settings.rings - 1);
    const double azimuth = std::atan2(p.y(), p.x()) + kPi;  // 0 .. 2 pi
    const int sector = std::min(static_cast<int>(azimuth / sector_width), settings.sectors - 1);
    // Above the ground, and never 0 for a point that is there (0 means empty).
    const float height = std::max(p.z() - ground, 1e-3f);
    float& bin = out.bins[static_cast<size_t>(ring * settings.sectors + sector)];
    bin = std::max(bin, height);
  }
  fill_ring_key(out);
  return out;
}

ScanContext scan_context_from_bins(int rings, int sectors, std::vector<float> bins) {
  if (rings < 1 || sectors < 1 || bins.size() != static_cast<size_t>(rings) * sectors)
    throw std::invalid_argument("scan context: " + std::to_string(bins.size()) + " bins are not " +
                                std::to_string(rings) + " rings x " + std::to_string(sectors) +
                                " sectors");
  for (const float bin : bins) {
    if (!std::isfinite(bin) || bin < 0.0f)
      throw std::invalid_argument("scan context: a bin is negative or not finite");
  }
  ScanContext out;
  out.rings = rings;
  out.sectors = sectors;
  out.bins = std::move(bins);
  fill_ring_key(out);
  return out;
}

Eigen::Matrix3d levelling(const Eigen::Isometry3d& T_map_sensor) {
  const Eigen::Matrix3d R = T_map_sensor.rotation();
  // The heading: where the sensor's x axis points, projected on the ground plane.
  const Eigen::Vector3d forward = R.col(0);
  const double heading = std::hypot(forward.x(), forward.y()) > 1e-9
                             ? std::atan2(forward.y(), forward.x())
                             : std::atan2(-R(0, 1), R(1, 1));  // looking straight down or up
  // levelled <- sensor: map <- sensor, then turned back by the heading alone.
  return Eigen::AngleAxisd(-heading, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

ScanContext levelled_scan_context(const Eigen::Isometry3d& T_map_sensor,
                                  const std::vector<Eigen::Vector3f>& points,
                                  const ScanContextSettings& settings) {
  const Eigen::Matrix3f L = levelling(T_map_sensor).cast<float>();
  std::vector<Eigen::Vector3f> levelled;
  levelled.reserve(points.size());
  for (const Eigen::Vector3f& p : points) levelled.push_back(L * p);
  return make_scan_context(levelled, settings);
}

Eigen::Isometry3d descriptor_guess(const Eigen::Isometry3d& T_map_candidate,
                                   const Eigen::Isometry3d& T_map_query, double yaw_rad) {
  Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
  guess.linear() = levelling(T_map_candidate).transpose() *
                   Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                   levelling(T_map_query);
  return guess;
}

ScanContextMatch match(const ScanContext& query, const ScanContext& candidate) {
  if (query.rings != candidate.rings || query.sectors != candidate.sectors || query.empty())
    throw std::invalid_argument("scan context: descriptors of different sizes");
  const int rings = query.rings;
  const int sectors = query.sectors;
  const auto column_norms = [&](const ScanContext& d) {
    std::vector<double> norms(static_cast<size_t>(sectors), 0.0);
    for (int s = 0; s < sectors; ++s) {
      for (int r = 0; r < rings; ++r)
        norms[static_cast<size_t>(s)] += double(d.at(r, s)) * d.at(r, s);
      norms[static_cast<size_t>(s)] = std::sqrt(norms[static_cast<size_t>(s)]);
    }
    return norms;
  };
  const std::vector<double> query_norms = column_norms(query);
  const std::vector<double> candidate_norms = column_norms(candidate);
  ScanContextMatch best;
  for (int shift = 0; shift < sectors; ++shift) {
    double similarity = 0.0;
    int columns = 0;
    for (int s = 0; s < sectors; ++s) {
      const int c = (s + shift) % sectors;
      const double qn = query_norms[static_cast<size_t>(s)];
      const double cn = candidate_norms[static_cast<size_t>(c)];
      if (qn == 0.0 && cn == 0.0) continue;
      ++columns;
      // A column seen in one scan and empty in the other counts as nothing alike.
      if (qn == 0.0 || cn == 0.0) continue;
      double dot = 0.0;
      for (int r = 0; r < rings; ++r) dot += double(query.at(r, s)) * candidate.at(r, c);
      similarity += dot / (qn * cn);
    }
    if (columns == 0) continue;
    const double distance = 1.0 - similarity / columns;
    if (distance < best.distance) {
      best.distance = distance;
      // The query's column s looks where the candidate's column s + shift does: the query
      // sensor is turned by shift sectors against the candidate's.
      double yaw = 2.0 * kPi * shift / sectors;
      if (yaw > kPi) yaw -= 2.0 * kPi;
      best.yaw_rad = yaw;
    }
  }
  return best;
}

double ring_key_distance(const ScanContext& a, const ScanContext& b) {
  if (a.ring_key.size() != b.ring_key.size())
    throw std::invalid_argument("scan context: ring keys of different sizes");
  double sum = 0.0;
  for (size_t i = 0; i < a.ring_key.size(); ++i) {
    const double d = a.ring_key[i] - b.ring_key[i];
    sum += d * d;
  }
  return std::sqrt(sum);
}

}  // namespace featsense::slam::loops
