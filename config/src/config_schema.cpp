#include "config_schema.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "featsense/config/config_error.hpp"
#include "featsense/config/sensor_model.hpp"

namespace featsense::config::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Range {
  double min = -kInf;
  double max = kInf;
  bool min_exclusive = false;  ///< "> min" rather than ">= min"
};

std::string describe(const Range& r) {
  std::ostringstream s;
  if (r.min > -kInf) s << (r.min_exclusive ? "> " : ">= ") << r.min;
  if (r.min > -kInf && r.max < kInf) s << " and ";
  if (r.max < kInf) s << "<= " << r.max;
  return s.str();
}

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw ConfigError(where + ": " + what);
}

double parse_number(const YAML::Node& node, const std::string& where, const Range& range) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    fail(where, "expected a number");
  }
  if (!std::isfinite(value)) fail(where, "expected a finite number, got " + node.Scalar());
  const bool below = range.min_exclusive ? value <= range.min : value < range.min;
  if (below || value > range.max) {
    fail(where, "value " + node.Scalar() + " is out of range (must be " + describe(range) + ")");
  }
  return value;
}

template <typename Section, typename Field>
using Member = Field Section::*;

template <typename Section>
using SectionOf = Section Config::*;

template <typename Section>
KeySpec number_key(std::string path, SectionOf<Section> section, Member<Section, double> field,
                   Range range) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            (c.*section).*field = parse_number(v, where, range);
          },
          [=](const Config& c) { return YAML::Node((c.*section).*field); }};
}

template <typename Section>
KeySpec optional_number_key(std::string path, SectionOf<Section> section,
                            Member<Section, std::optional<double>> field, Range range) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            if (v.IsNull() || (v.IsScalar() && v.Scalar() == "auto")) {
              (c.*section).*field = std::nullopt;
            } else {
              (c.*section).*field = parse_number(v, where, range);
            }
          },
          [=](const Config& c) {
            const auto& value = (c.*section).*field;
            return value ? YAML::Node(*value) : YAML::Node(YAML::NodeType::Null);
          }};
}

template <typename Section>
KeySpec integer_key(std::string path, SectionOf<Section> section, Member<Section, int> field,
                    int min, int max) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            int value = 0;
            if (!v.IsScalar() || !YAML::convert<int>::decode(v, value)) {
              fail(where, "expected a whole number");
            }
            if (value < min || value > max) {
              fail(where, "value " + v.Scalar() + " is out of range (must be " +
                              std::to_string(min) + " .. " + std::to_string(max) + ")");
            }
            (c.*section).*field = value;
          },
          [=](const Config& c) { return YAML::Node((c.*section).*field); }};
}

template <typename Section>
KeySpec bool_key(std::string path, SectionOf<Section> section, Member<Section, bool> field) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            bool value = false;
            if (!v.IsScalar() || !YAML::convert<bool>::decode(v, value)) {
              fail(where, "expected true or false");
            }
            (c.*section).*field = value;
          },
          [=](const Config& c) { return YAML::Node((c.*section).*field); }};
}

template <typename Section>
KeySpec vec3_key(std::string path, SectionOf<Section> section,
                 Member<Section, std::array<double, 3>> field, Range range) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            if (!v.IsSequence() || v.size() != 3) fail(where, "expected a list of 3 numbers");
            std::array<double, 3> value{};
            for (size_t i = 0; i < 3; ++i) {
              value[i] = parse_number(v[i], where + "[" + std::to_string(i) + "]", range);
            }
            (c.*section).*field = value;
          },
          [=](const Config& c) {
            YAML::Node node(YAML::NodeType::Sequence);
            for (double x : (c.*section).*field) node.push_back(x);
            node.SetStyle(YAML::EmitterStyle::Flow);
            return node;
          }};
}

/// null, or [x_min, y_min, z_min, x_max, y_max, z_max] with each min below its max.
template <typename Section>
KeySpec optional_box_key(std::string path, SectionOf<Section> section,
                         Member<Section, std::optional<std::array<double, 6>>> field) {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            if (v.IsNull()) {
              (c.*section).*field = std::nullopt;
              return;
            }
            if (!v.IsSequence() || v.size() != 6)
              fail(where, "expected null or [x_min, y_min, z_min, x_max, y_max, z_max]");
            std::array<double, 6> box{};
            for (size_t i = 0; i < 6; ++i) {
              box[i] = parse_number(v[i], where + "[" + std::to_string(i) + "]", Range{});
            }
            for (size_t axis = 0; axis < 3; ++axis) {
              if (!(box[axis] < box[axis + 3])) {
                fail(where, std::string("the box's ") + "xyz"[axis] +
                                " minimum must be below its maximum");
              }
            }
            (c.*section).*field = box;
          },
          [=](const Config& c) {
            const auto& box = (c.*section).*field;
            if (!box) return YAML::Node(YAML::NodeType::Null);
            YAML::Node node(YAML::NodeType::Sequence);
            for (double x : *box) node.push_back(x);
            node.SetStyle(YAML::EmitterStyle::Flow);
            return node;
          }};
}

std::string scalar_choice(const YAML::Node& v, const std::string& where,
                          const std::vector<std::string>& choices) {
  if (!v.IsScalar()) fail(where, "expected one of the names listed in default.yaml");
  for (const auto& choice : choices) {
    if (v.Scalar() == choice) return choice;
  }
  std::string message = "unknown value '" + v.Scalar() + "'";
  const std::string hint = closest_match(v.Scalar(), choices);
  if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
  message += "; choose one of:";
  for (const auto& choice : choices) message += " " + choice;
  fail(where, message);
}

KeySpec preset_key() {
  return {"sensor.preset",
          [](Config& c, const YAML::Node& v, const std::string& where) {
            std::vector<std::string> choices = {"auto"};
            for (const auto& name : sensor_preset_names()) choices.push_back(name);
            c.sensor.preset = scalar_choice(v, where, choices);
          },
          [](const Config& c) { return YAML::Node(c.sensor.preset); }};
}

KeySpec backend_key() {
  return {"map.backend",
          [](Config& c, const YAML::Node& v, const std::string& where) {
            const std::string name = scalar_choice(v, where, {"auto", "cuda", "cpu"});
            c.map.backend = name == "cuda"  ? Backend::kCuda
                            : name == "cpu" ? Backend::kCpu
                                            : Backend::kAuto;
          },
          [](const Config& c) { return YAML::Node(to_string(c.map.backend)); }};
}

/// A file path (or another name: `expected` says what) that may be unset (null).
template <typename Section>
KeySpec optional_path_key(std::string path, SectionOf<Section> section,
                          Member<Section, std::optional<std::string>> field,
                          std::string expected = "a file path") {
  return {std::move(path),
          [=](Config& c, const YAML::Node& v, const std::string& where) {
            if (v.IsNull()) {
              (c.*section).*field = std::nullopt;
            } else if (!v.IsScalar() || v.Scalar().empty()) {
              fail(where, "expected " + expected + " or null");
            } else {
              (c.*section).*field = v.Scalar();
            }
          },
          [=](const Config& c) {
            const auto& value = (c.*section).*field;
            return value ? YAML::Node(*value) : YAML::Node(YAML::NodeType::Null);
          }};
}

std::vector<KeySpec> make_specs() {
  return {
      preset_key(),
      optional_number_key("sensor.min_range", &Config::sensor, &SensorConfig::min_range_m,
                          {0.0, 1000.0}),
      optional_number_key("sensor.max_range", &Config::sensor, &SensorConfig::max_range_m,
                          {0.0, 10000.0, true}),
      bool_key("sensor.drop_mixed_pixels", &Config::sensor, &SensorConfig::drop_mixed_pixels),
      bool_key("sensor.times_from_azimuth", &Config::sensor, &SensorConfig::times_from_azimuth),
      optional_path_key("sensor.calibration", &Config::sensor, &SensorConfig::calibration),
      number_key("sensor.scan_cut_deg", &Config::sensor, &SensorConfig::scan_cut_deg, {0.0, 360.0}),
      bool_key("sensor.imu", &Config::sensor, &SensorConfig::imu),
      optional_path_key("sensor.imu_topic", &Config::sensor, &SensorConfig::imu_topic,
                        "a topic name"),
      optional_box_key("sensor.self_box", &Config::sensor, &SensorConfig::self_box),
      vec3_key("sensor.imu_rotation", &Config::sensor, &SensorConfig::imu_rotation_deg,
               {-360.0, 360.0}),
      number_key("map.voxel_size", &Config::map, &MapConfig::voxel_size_m, {0.005, 2.0}),
      number_key("map.truncation", &Config::map, &MapConfig::truncation_m, {0.0, 10.0, true}),
      number_key("map.max_weight", &Config::map, &MapConfig::max_weight, {1.0, 500.0}),
      vec3_key("map.size", &Config::map, &MapConfig::size_m, {1.0, 2000.0}),
      number_key("map.shift_threshold", &Config::map, &MapConfig::shift_threshold_m,
                 {0.0, 1000.0, true}),
      bool_key("map.vertical_interpolation", &Config::map, &MapConfig::vertical_interpolation),
      bool_key("map.sparse_carving", &Config::map, &MapConfig::sparse_carving),
      bool_key("map.carve_free_space", &Config::map, &MapConfig::carve_free_space),
      bool_key("map.keep_unmoved", &Config::map, &MapConfig::keep_unmoved),
      number_key("map.flush_interval", &Config::map, &MapConfig::flush_interval_s, {1.0, 86400.0}),
      backend_key(),
      integer_key("features.neighbours", &Config::features, &FeaturesConfig::neighbours, 1, 20),
      integer_key("features.sectors", &Config::features, &FeaturesConfig::sectors, 1, 64),
      integer_key("features.max_edges_per_sector", &Config::features,
                  &FeaturesConfig::max_edges_per_sector, 0, 10000),
      integer_key("features.max_surfaces_per_sector", &Config::features,
                  &FeaturesConfig::max_surfaces_per_sector, 0, 10000),
      number_key("features.edge_threshold", &Config::features, &FeaturesConfig::edge_threshold,
                 {0.0, 1.0, true}),
      number_key("features.max_edge_threshold", &Config::features,
                 &FeaturesConfig::max_edge_threshold, {0.0, 1.0, true}),
      number_key("features.surface_threshold", &Config::features,
                 &FeaturesConfig::surface_threshold, {0.0, 1.0, true}),
      number_key("features.min_range", &Config::features, &FeaturesConfig::min_range_m,
                 {0.0, 1000.0}),
      number_key("features.max_range", &Config::features, &FeaturesConfig::max_range_m,
                 {0.0, 10000.0, true}),
      number_key("features.occlusion_jump", &Config::features, &FeaturesConfig::occlusion_jump_m,
                 {0.0, 100.0, true}),
      number_key("features.parallel_gap_ratio", &Config::features,
                 &FeaturesConfig::parallel_gap_ratio, {1.0, 1000.0}),
      number_key("features.intensity_percentile", &Config::features,
                 &FeaturesConfig::intensity_percentile, {0.0, 25.0}),
      number_key("features.intensity_blur_sigma", &Config::features,
                 &FeaturesConfig::intensity_blur_sigma, {0.0, 10.0}),
      number_key("features.intensity_bilateral_sigma_color", &Config::features,
                 &FeaturesConfig::intensity_bilateral_sigma_color, {0.0, 255.0}),
      number_key("features.intensity_bilateral_sigma_space", &Config::features,
                 &FeaturesConfig::intensity_bilateral_sigma_space, {0.0, 10.0}),
      number_key("features.intensity_edge_fraction", &Config::features,
                 &FeaturesConfig::intensity_edge_fraction, {0.0, 1.0, true}),
      number_key("features.intensity_noise_factor", &Config::features,
                 &FeaturesConfig::intensity_noise_factor, {0.0, 100.0}),
      integer_key("features.intensity_tolerance_px", &Config::features,
                  &FeaturesConfig::intensity_tolerance_px, 0, 5),
      integer_key("odometry.optimization_steps", &Config::odometry,
                  &OdometryConfig::optimization_steps, 1, 20),
      bool_key("odometry.intensity_fusion", &Config::odometry, &OdometryConfig::intensity_fusion),
      bool_key("odometry.deskew", &Config::odometry, &OdometryConfig::deskew),
      bool_key("odometry.hold_still", &Config::odometry, &OdometryConfig::hold_still),
      number_key("odometry.edge_voxel", &Config::odometry, &OdometryConfig::edge_voxel_m,
                 {0.0, 10.0, true}),
      number_key("odometry.surface_voxel", &Config::odometry, &OdometryConfig::surface_voxel_m,
                 {0.0, 10.0, true}),
      number_key("odometry.map_radius", &Config::odometry, &OdometryConfig::map_radius_m,
                 {1.0, 10000.0}),
      number_key("odometry.max_correspondence_distance", &Config::odometry,
                 &OdometryConfig::max_correspondence_distance_m, {0.0, 100.0, true}),
      number_key("odometry.plane_tolerance", &Config::odometry, &OdometryConfig::plane_tolerance_m,
                 {0.0, 10.0, true}),
      number_key("odometry.huber_loss", &Config::odometry, &OdometryConfig::huber_loss_m,
                 {0.0, 100.0, true}),
      number_key("odometry.degeneracy_threshold", &Config::odometry,
                 &OdometryConfig::degeneracy_threshold, {0.0, 1.0}),
      number_key("odometry.max_speed", &Config::odometry, &OdometryConfig::max_speed_m_s,
                 {0.0, 1000.0, true}),
      number_key("odometry.max_turn_rate", &Config::odometry, &OdometryConfig::max_turn_rate_rad_s,
                 {0.0, 100.0, true}),
      number_key("odometry.poor_fit_ratio", &Config::odometry, &OdometryConfig::poor_fit_ratio,
                 {1.0, 100.0, true}),
      number_key("odometry.turn_search", &Config::odometry, &OdometryConfig::turn_search_deg,
                 {0.0, 45.0}),
      bool_key("refine.enabled", &Config::refine, &RefineConfig::enabled),
      number_key("refine.distance", &Config::refine, &RefineConfig::distance_m,
                 {0.0, 10000.0, true}),
      number_key("refine.voxel", &Config::refine, &RefineConfig::voxel_m, {0.02, 5.0}),
      integer_key("refine.max_scans", &Config::refine, &RefineConfig::max_scans, 2, 1000),
      number_key("refine.min_constraint_ratio", &Config::refine,
                 &RefineConfig::min_constraint_ratio, {0.0, 1.0}),
      bool_key("loop.enabled", &Config::loop, &LoopConfig::enabled),
      number_key("loop.keyframe_distance", &Config::loop, &LoopConfig::keyframe_distance_m,
                 {0.0, 1000.0, true}),
      number_key("loop.keyframe_angle_deg", &Config::loop, &LoopConfig::keyframe_angle_deg,
                 {0.0, 180.0, true}),
      number_key("loop.min_separation_s", &Config::loop, &LoopConfig::min_separation_s, {0.0, 1e6}),
      number_key("loop.min_separation", &Config::loop, &LoopConfig::min_separation_m, {0.0, 1e6}),
      number_key("loop.max_descriptor_distance", &Config::loop,
                 &LoopConfig::max_descriptor_distance, {0.0, 1.0, true}),
      number_key("loop.max_fitness", &Config::loop, &LoopConfig::max_fitness_m, {0.0, 10.0, true}),
      number_key("loop.min_inliers", &Config::loop, &LoopConfig::min_inlier_fraction, {0.0, 1.0}),
      number_key("loop.drift", &Config::loop, &LoopConfig::drift, {0.0, 1.0}),
      bool_key("loop.gravity", &Config::loop, &LoopConfig::gravity),
      number_key("loop.gravity_window", &Config::loop, &LoopConfig::gravity_window_s, {0.5, 60.0}),
      bool_key("loop.gyro", &Config::loop, &LoopConfig::gyro),
      integer_key("relocalize.max_scans", &Config::relocalize, &RelocalizeConfig::max_scans, 1,
                  1000000),
      integer_key("relocalize.confirmations", &Config::relocalize, &RelocalizeConfig::confirmations,
                  1, 100),
      number_key("localize.radius", &Config::localize, &LocalizeConfig::radius_m, {5.0, 1000.0}),
      number_key("localize.cache_mb", &Config::localize, &LocalizeConfig::cache_mb, {16.0, 1e6}),
      number_key("localize.voxel", &Config::localize, &LocalizeConfig::voxel_m, {0.05, 5.0}),
      integer_key("localize.max_points", &Config::localize, &LocalizeConfig::max_points, 100,
                  1000000),
      number_key("localize.min_inliers", &Config::localize, &LocalizeConfig::min_inlier_fraction,
                 {0.0, 1.0}),
      number_key("localize.max_fitness", &Config::localize, &LocalizeConfig::max_fitness_m,
                 {0.0, 10.0, true}),
      number_key("localize.contradiction_inliers", &Config::localize,
                 &LocalizeConfig::contradiction_fraction, {0.0, 1.0}),
      integer_key("localize.contradictions", &Config::localize, &LocalizeConfig::contradictions, 1,
                  1000),
      number_key("localize.odometry_timeout", &Config::localize,
                 &LocalizeConfig::odometry_timeout_s, {0.0, 3600.0}),
  };
}

}  // namespace

const std::vector<KeySpec>& key_specs() {
  static const std::vector<KeySpec> specs = make_specs();
  return specs;
}

void validate_relations(const Config& c) {
  if (c.sensor.min_range_m && c.sensor.max_range_m &&
      *c.sensor.min_range_m >= *c.sensor.max_range_m) {
    throw ConfigError("sensor.min_range (" + std::to_string(*c.sensor.min_range_m) +
                      " m) must be below sensor.max_range (" +
                      std::to_string(*c.sensor.max_range_m) + " m)");
  }
  if (c.map.truncation_m < c.map.voxel_size_m) {
    throw ConfigError("map.truncation (" + std::to_string(c.map.truncation_m) +
                      " m) must be at least one voxel (map.voxel_size = " +
                      std::to_string(c.map.voxel_size_m) + " m)");
  }
  double voxels = 1.0;
  for (double extent : c.map.size_m) {
    const double cells = std::ceil(extent / c.map.voxel_size_m);
    if (cells < 3) {
      throw ConfigError("map.size: every extent must span at least 3 voxels of map.voxel_size");
    }
    voxels *= cells;
  }
  // Voxel indices are 32-bit on the GPU; a map beyond that would not fit in memory anyway.
  if (voxels > static_cast<double>(std::numeric_limits<int32_t>::max())) {
    std::ostringstream s;
    s << "map.size / map.voxel_size give " << voxels
      << " voxels, more than the 2^31 a local map may hold; use a smaller map or larger voxels";
    throw ConfigError(s.str());
  }
  if (c.features.min_range_m >= c.features.max_range_m) {
    throw ConfigError("features.min_range (" + std::to_string(c.features.min_range_m) +
                      " m) must be below features.max_range (" +
                      std::to_string(c.features.max_range_m) + " m)");
  }
  if (c.features.surface_threshold >= c.features.edge_threshold ||
      c.features.edge_threshold >= c.features.max_edge_threshold) {
    throw ConfigError(
        "features.surface_threshold < features.edge_threshold < features.max_edge_threshold "
        "must hold");
  }
  if (c.localize.contradiction_fraction >= c.localize.min_inlier_fraction) {
    throw ConfigError("localize.contradiction_inliers (" +
                      std::to_string(c.localize.contradiction_fraction) +
                      ") must be below localize.min_inliers (" +
                      std::to_string(c.localize.min_inlier_fraction) + ")");
  }
  const double half_smallest = 0.5 * std::min(c.map.size_m[0], c.map.size_m[1]);
  if (c.map.shift_threshold_m > half_smallest) {
    throw ConfigError("map.shift_threshold (" + std::to_string(c.map.shift_threshold_m) +
                      " m) must be at most half the smallest horizontal extent of map.size (" +
                      std::to_string(half_smallest) + " m)");
  }
}

}  // namespace featsense::config::detail
