#pragma once
/// The typed configuration of a run. In-class defaults are the documented defaults of
/// config/default.yaml (a test keeps the two equal). Only config/ parses YAML.

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace featsense::config {

struct SensorConfig {
  /// "auto": the recording's own metadata, else its sequence.yaml, else the reader's guess.
  std::string preset = "auto";
  std::optional<double> min_range_m;  ///< metres; unset: the sensor model's own limit
  std::optional<double> max_range_m;  ///< metres; unset: the sensor model's own limit
  /// [x_min, y_min, z_min, x_max, y_max, z_max] in the sensor frame, metres: returns inside
  /// are the vehicle carrying the sensor and are dropped before anything sees them. Unset:
  /// none.
  std::optional<std::array<double, 6>> self_box;
  /// Drop veil points between a foreground edge and the surface behind it.
  bool drop_mixed_pixels = true;
  /// Clouds without a per-point time field (KITTI .bin, many PCD / PLY files and
  /// PointCloud2 messages) get each point's time from its azimuth, where the points are
  /// stored in the order the sensor measured them (slam/io azimuth_times.hpp).
  bool times_from_azimuth = true;
  /// A Velodyne calibration YAML (per-laser corrections); unset: the model's built-in table.
  std::optional<std::string> calibration;
  /// Where packet streams (Velodyne) are cut into scans: azimuth in degrees, clockwise from
  /// +x (forward). 180 puts the seam behind the sensor.
  double scan_cut_deg = 180.0;
  /// Read the IMU's samples where the input has them (Scan::imu); false leaves them out.
  bool imu = true;
  /// A bag's IMU topic; unset: the one sensor_msgs/Imu topic there is.
  std::optional<std::string> imu_topic;
  /// Roll, pitch, yaw (degrees) of the rotation from the IMU's frame into the sensor's, for
  /// inputs whose IMU messages do not say it (Ouster packets take it from the metadata).
  std::array<double, 3> imu_rotation_deg = {0.0, 0.0, 0.0};
};

enum class Backend { kAuto, kCuda, kCpu };

struct MapConfig {
  double voxel_size_m = 0.064;
  double truncation_m = 0.25;
  double max_weight = 10.0;
  std::array<double, 3> size_m = {40.0, 40.0, 15.0};
  double shift_threshold_m = 3.0;
  /// Fill the gap between neighbouring beams across each ray near the surface (paper eq. 7-8),
  /// except on rays whose neighbouring beams disagree in range (app/scan_to_rays.cpp).
  bool vertical_interpolation = true;
  /// Near the sensor, where rays are much denser than voxels, only a lattice of them carves
  /// free space (TsdfSettings::dense_range_m).
  bool sparse_carving = true;
  /// Rays carve the free space in front of their surfaces (false: the band only).
  bool carve_free_space = true;
  /// Where corrected poses make a saved map again (links to a continuing recording, merge):
  /// integrate again only where scans moved, keep the other chunks byte for byte (false:
  /// every scan again).
  bool keep_unmoved = true;
  /// Seconds between two writes of the local map into the store during a run.
  double flush_interval_s = 30.0;
  Backend backend = Backend::kAuto;
};

/// The feature front end (slam/features): curvature along each scan line, selection per
/// sector, the paper's filters and the intensity-image edges. Why each value: default.yaml.
struct FeaturesConfig {
  int neighbours = 5;  ///< N: the curvature uses +/- N points along the line
  int sectors = 6;     ///< sub-regions per scan line, each picking its own features
  int max_edges_per_sector = 20;
  int max_surfaces_per_sector = 20;
  /// Normalised curvature |sum_j (P_j - P_i)|^2 / (sum_j |P_j - P_i|)^2, in [0, 1]: 0 on a
  /// straight line, cos^2(angle / 2) at a corner of that angle between its two legs.
  double edge_threshold = 0.1;
  double max_edge_threshold = 0.9;
  double surface_threshold = 0.02;
  double min_range_m = 2.0;
  double max_range_m = 60.0;
  double occlusion_jump_m = 0.3;
  /// Both gaps to the line's neighbours above this many column spacings (range * 2 pi / cols).
  double parallel_gap_ratio = 5.0;
  double intensity_percentile = 1.0;  ///< %: the 8-bit image spans [p, 100 - p] percentiles
  double intensity_blur_sigma = 0.5;  ///< pixels
  double intensity_bilateral_sigma_color = 30.0;  ///< grey levels
  double intensity_bilateral_sigma_space = 2.0;   ///< pixels
  double intensity_edge_fraction = 0.2;           ///< of the largest gradient magnitude
  double intensity_noise_factor = 3.0;            ///< times the median gradient magnitude
  int intensity_tolerance_px = 1;
};

struct OdometryConfig {
  int optimization_steps = 3;
  bool intensity_fusion = true;
  bool deskew = true;
  bool hold_still = true;  ///< hold the pose while the sensor stands (see default.yaml)
  // Registration (slam/odometry). Why each value: default.yaml.
  double edge_voxel_m = 0.2;     ///< voxel of the local edge map and of each scan's edges
  double surface_voxel_m = 0.2;  ///< voxel of the local surface map and of the scan's surfaces
  double map_radius_m = 50.0;    ///< map points farther than this from the sensor are dropped
  double max_correspondence_distance_m = 1.0;  ///< the 5 neighbours lie within this
  double plane_tolerance_m = 0.05;             ///< see default.yaml
  double huber_loss_m = 0.1;                   ///< residuals beyond this count linearly
  double degeneracy_threshold = 0.002;         ///< see default.yaml
  double max_speed_m_s = 30.0;  ///< larger corrections of the prediction are divergence
  double max_turn_rate_rad_s = 3.0;
  double poor_fit_ratio = 2.0;   ///< see default.yaml
  double turn_search_deg = 9.0;  ///< see default.yaml
};

struct RefineConfig {
  bool enabled = true;
  double distance_m = 5.0;
  double voxel_m = 0.3;
  int max_scans = 64;
  double min_constraint_ratio = 0.005;  ///< see default.yaml
};

struct LoopConfig {
  bool enabled = true;
  double keyframe_distance_m = 1.0;
  double keyframe_angle_deg = 15.0;
  double min_separation_s = 10.0;
  double min_separation_m = 20.0;
  double max_descriptor_distance = 0.35;
  double max_fitness_m = 0.12;
  double min_inlier_fraction = 0.55;
  double drift = 0.02;
  bool gravity = true;
  double gravity_window_s = 4.0;
  bool gyro = true;
};

struct RelocalizeConfig {
  int max_scans = 600;
  int confirmations = 2;
};

/// `featsense localize`: scans registered to a saved map's surface (the keys' reasons in
/// default.yaml).
struct LocalizeConfig {
  double radius_m = 60.0;
  double cache_mb = 512.0;
  double voxel_m = 0.5;
  int max_points = 3000;
  double min_inlier_fraction = 0.5;
  double max_fitness_m = 0.1;
  double contradiction_fraction = 0.2;
  int contradictions = 3;
  double odometry_timeout_s = 10.0;
};

struct Config {
  SensorConfig sensor;
  MapConfig map;
  FeaturesConfig features;
  OdometryConfig odometry;
  RefineConfig refine;
  LoopConfig loop;
  RelocalizeConfig relocalize;
  LocalizeConfig localize;
  /// The keys given a value explicitly (by the YAML file, a --set or a command-line option
  /// that stands for the key), each with where the value that counts came from: "my.yaml:12",
  /// "--set map.voxel_size=0.05", "--voxel 0.05". A key is here even when the value given
  /// equals its default; every key not here holds its default.
  std::map<std::string, std::string> explicit_keys;

  bool is_explicit(const std::string& key) const { return explicit_keys.count(key) != 0; }
};

/// The value of one key given on the command line by an option that stands for it, e.g.
/// `--backend cuda` for map.backend. It goes through the same parser and checks as the file
/// and --set; messages name the option and the key.
struct Override {
  std::string key;     ///< "map.backend"
  std::string value;   ///< the value as YAML: "cuda", "0.05", "[40, 40, 15]"
  std::string origin;  ///< names the option in messages: "--backend cuda"
};

std::string to_string(Backend backend);

/// Builds the configuration of a run: the defaults, then the YAML file (if any), then each
/// `key=value` override (--set) in order, then each option override in order. Throws
/// ConfigError naming the key and where it came from for unknown keys (with a did-you-mean),
/// wrong types and out-of-range values.
Config load_config(const std::optional<std::string>& yaml_path,
                   const std::vector<std::string>& overrides = {},
                   const std::vector<Override>& options = {});
/// The same from YAML text instead of a file; `origin` names it in messages.
Config load_config_text(const std::string& yaml_text, const std::string& origin,
                        const std::vector<std::string>& overrides = {},
                        const std::vector<Override>& options = {});
/// The whole configuration as YAML, every key present, in the layout of default.yaml.
std::string to_yaml(const Config& config);
/// Every key path, e.g. "map.voxel_size", in schema order.
std::vector<std::string> config_keys();
/// The value of `key` in `config` as short text for help and messages: "0.064", "auto",
/// "[40, 40, 15]", "null". Throws ConfigError for an unknown key.
std::string value_text(const Config& config, const std::string& key);

}  // namespace featsense::config
