// Ouster sensor metadata JSON: the older flat layout (firmware 2.x "legacy" JSON) and the
// newer nested one (beam_intrinsics, lidar_intrinsics, lidar_data_format, config_params,
// sensor_info). PACKET_FORMAT.md lists the keys.

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"
#include "ouster/ouster_packet.hpp"

namespace featsense::slam {
namespace {

using nlohmann::json;

constexpr double kDegToRad = M_PI / 180.0;

/// Reads typed values out of a JSON object and names the full key path in every error.
class KeyReader {
 public:
  KeyReader(const json& object, std::string prefix, const std::string& origin)
      : object_(&object), prefix_(std::move(prefix)), origin_(&origin) {}

  bool has(const char* key) const { return object_->contains(key); }

  /// The sub-object `key`; throws when missing or not an object.
  KeyReader object(const char* key) const {
    const json& value = get(key);
    if (!value.is_object()) fail(key, "must be an object");
    return KeyReader(value, path(key) + ".", *origin_);
  }

  std::string string(const char* key) const {
    const json& value = get(key);
    if (!value.is_string()) fail(key, "must be a string");
    return value.get<std::string>();
  }

  double number(const char* key) const {
    const json& value = get(key);
    if (!value.is_number()) fail(key, "must be a number");
    return value.get<double>();
  }

  int integer(const char* key) const {
    const json& value = get(key);
    if (!is_int(value)) fail(key, "must be an integer");
    return value.get<int>();
  }

  std::vector<double> numbers(const char* key) const {
    const json& value = get(key);
    if (!value.is_array()) fail(key, "must be an array of numbers");
    std::vector<double> out;
    out.reserve(value.size());
    for (const json& item : value) {
      if (!item.is_number()) fail(key, "must be an array of numbers");
      out.push_back(item.get<double>());
    }
    return out;
  }

  std::vector<int> integers(const char* key) const {
    const json& value = get(key);
    if (!value.is_array()) fail(key, "must be an array of integers");
    std::vector<int> out;
    out.reserve(value.size());
    for (const json& item : value) {
      if (!is_int(item)) fail(key, "must be an array of integers");
      out.push_back(item.get<int>());
    }
    return out;
  }

  /// A non-negative integer given as a number or a string of digits (serial numbers are
  /// strings); nullopt where the key is absent.
  std::optional<uint64_t> optional_id(const char* key) const {
    if (!has(key)) return std::nullopt;
    const json& value = get(key);
    if (value.is_number_unsigned()) return value.get<uint64_t>();
    if (value.is_number_integer() && value.get<int64_t>() >= 0) {
      return static_cast<uint64_t>(value.get<int64_t>());
    }
    if (value.is_string()) {
      const std::string text = value.get<std::string>();
      if (!text.empty() && text.size() <= 19 &&
          std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return std::stoull(text);
      }
    }
    fail(key, "must be a non-negative integer or a string of digits");
  }

  /// A row-major 4x4 matrix given as 16 numbers.
  std::array<double, 16> matrix4(const char* key) const {
    const std::vector<double> values = numbers(key);
    if (values.size() != 16) fail(key, "must hold 16 numbers (a row-major 4x4 matrix)");
    std::array<double, 16> out{};
    std::copy(values.begin(), values.end(), out.begin());
    return out;
  }

  [[noreturn]] void fail(const char* key, const std::string& what) const {
    throw InputError(*origin_ + ": key '" + path(key) + "' " + what);
  }

 private:
  /// Integers that fit an int; JSON has no separate integer type, but the parser keeps one.
  static bool is_int(const json& value) {
    if (value.is_number_unsigned()) return value.get<uint64_t>() <= 0x7FFFFFFFu;
    if (value.is_number_integer()) {
      const int64_t v = value.get<int64_t>();
      return v >= -0x7FFFFFFF && v <= 0x7FFFFFFF;
    }
    return false;
  }

  const json& get(const char* key) const {
    const auto it = object_->find(key);
    if (it == object_->end()) throw InputError(*origin_ + ": missing key '" + path(key) + "'");
    return *it;
  }

  std::string path(const char* key) const { return prefix_ + key; }

  const json* object_;  // pointers, not references: readers are kept in optionals
  std::string prefix_;
  const std::string* origin_;
};

OusterProfile parse_profile(const std::string& name, const KeyReader& where, const char* key) {
  if (name == "LEGACY") return OusterProfile::kLegacy;
  if (name == "RNG19_RFL8_SIG16_NIR16") return OusterProfile::kRng19Rfl8Sig16Nir16;
  if (name == "RNG15_RFL8_NIR8") return OusterProfile::kRng15Rfl8Nir8;
  if (name.find("DUAL") != std::string::npos) {
    where.fail(key, "is the dual-return profile '" + name +
                        "', which is not supported (single-return profiles only: LEGACY, "
                        "RNG19_RFL8_SIG16_NIR16, RNG15_RFL8_NIR8)");
  }
  where.fail(key, "names the unknown lidar profile '" + name +
                      "' (supported: LEGACY, RNG19_RFL8_SIG16_NIR16, RNG15_RFL8_NIR8)");
}

/// "1024x10" -> columns 1024, rate 10 Hz.
void parse_lidar_mode(const std::string& mode, const KeyReader& where, const char* key,
                      int* columns, double* rate_hz) {
  const size_t x = mode.find('x');
  const auto all_digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 6 &&
           std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  const std::string left = x == std::string::npos ? "" : mode.substr(0, x);
  const std::string right = x == std::string::npos ? "" : mode.substr(x + 1);
  if (!all_digits(left) || !all_digits(right) || std::stoi(left) == 0 || std::stoi(right) == 0) {
    where.fail(key, "must look like \"1024x10\" (columns x rate in Hz), is \"" + mode + "\"");
  }
  *columns = std::stoi(left);
  *rate_hz = std::stod(right);
}

/// The keys of data_format / lidar_data_format, the same in both layouts.
void parse_data_format(const KeyReader& format, OusterMetadata* meta) {
  meta->pixels_per_column = format.integer("pixels_per_column");
  meta->columns_per_packet = format.integer("columns_per_packet");
  meta->columns_per_frame = format.integer("columns_per_frame");
  meta->pixel_shift_by_row = format.integers("pixel_shift_by_row");
  const std::vector<int> window = format.integers("column_window");
  if (window.size() != 2) format.fail("column_window", "must hold two measurement ids");
  meta->column_window = {window[0], window[1]};
}

/// The UDP ports where given (the sensor's defaults 7502 and 7503 otherwise).
void parse_udp_ports(const KeyReader& holder, OusterMetadata* meta) {
  const auto port = [&](const char* key, int* out) {
    if (!holder.has(key)) return;
    *out = holder.integer(key);
    if (*out < 0 || *out > 65535) holder.fail(key, "must be a UDP port, 0 .. 65535");
  };
  port("udp_port_lidar", &meta->udp_port_lidar);
  port("udp_port_imu", &meta->udp_port_imu);
}

/// Rejects metadata whose parts disagree, before anything indexes with them.
void validate(const OusterMetadata& meta, const std::string& origin) {
  const auto fail = [&](const std::string& what) { throw InputError(origin + ": " + what); };
  const int rows = meta.pixels_per_column;
  const int cols = meta.columns_per_frame;
  // The bounds keep tables and packets of sane size (the largest sensors have 128 beams and
  // 2048 columns, 16 columns per packet); they also keep every size product far from overflow.
  if (rows < 1 || rows > 1024)
    fail("pixels_per_column must be 1 .. 1024, is " + std::to_string(rows));
  if (cols < 1 || cols > 16384)
    fail("columns_per_frame must be 1 .. 16384, is " + std::to_string(cols));
  if (meta.columns_per_packet < 1 || meta.columns_per_packet > 256) {
    fail("columns_per_packet must be 1 .. 256, is " + std::to_string(meta.columns_per_packet));
  }
  const auto check_rows = [&](size_t size, const char* name) {
    if (size != static_cast<size_t>(rows)) {
      fail(std::string(name) + " has " + std::to_string(size) + " entries, pixels_per_column is " +
           std::to_string(rows));
    }
  };
  check_rows(meta.beam_altitude_deg.size(), "beam_altitude_angles");
  check_rows(meta.beam_azimuth_deg.size(), "beam_azimuth_angles");
  check_rows(meta.pixel_shift_by_row.size(), "pixel_shift_by_row");
  for (size_t i = 0; i < meta.beam_altitude_deg.size(); ++i) {
    if (!(std::abs(meta.beam_altitude_deg[i]) <= 90.0) ||
        !(std::abs(meta.beam_azimuth_deg[i]) <= 360.0)) {
      fail("beam " + std::to_string(i) + " has an impossible altitude or azimuth angle");
    }
  }
  for (int shift : meta.pixel_shift_by_row) {
    if (shift <= -cols || shift >= cols) {
      fail("pixel_shift_by_row holds " + std::to_string(shift) + ", outside (-" +
           std::to_string(cols) + ", " + std::to_string(cols) + ")");
    }
  }
  for (int id : meta.column_window) {
    if (id < 0 || id >= cols) {
      fail("column_window [" + std::to_string(meta.column_window[0]) + ", " +
           std::to_string(meta.column_window[1]) + "] lies outside the frame of " +
           std::to_string(cols) + " columns");
    }
  }
  if (!(std::abs(meta.lidar_origin_to_beam_origin_mm) < 1000.0)) {
    fail("lidar_origin_to_beam_origin_mm must be below 1 m");
  }
  for (const auto* matrix : {&meta.beam_to_lidar, &meta.lidar_to_sensor, &meta.imu_to_sensor}) {
    for (double v : *matrix) {
      if (!std::isfinite(v) || std::abs(v) > 1.0e6) fail("a transform holds a non-finite value");
    }
  }
  // The IMU's samples are turned by this matrix's rotation part, which must be one.
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double dot = 0.0;
      for (int k = 0; k < 3; ++k) {
        dot += meta.imu_to_sensor[static_cast<size_t>(4 * k + a)] *
               meta.imu_to_sensor[static_cast<size_t>(4 * k + b)];
      }
      if (std::abs(dot - (a == b ? 1.0 : 0.0)) > 1.0e-3) {
        fail("imu_to_sensor_transform's upper-left 3x3 is not a rotation");
      }
    }
  }
}

std::string lower_alnum(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (std::isalnum(c)) out += static_cast<char>(std::tolower(c));
  }
  return out;
}

}  // namespace

std::string to_string(OusterProfile profile) {
  switch (profile) {
    case OusterProfile::kLegacy:
      return "LEGACY";
    case OusterProfile::kRng19Rfl8Sig16Nir16:
      return "RNG19_RFL8_SIG16_NIR16";
    case OusterProfile::kRng15Rfl8Nir8:
      return "RNG15_RFL8_NIR8";
  }
  return "unknown";
}

size_t OusterMetadata::packet_size() const {
  return detail::OusterPacketLayout::of(*this).packet_bytes;
}

config::SensorModel OusterMetadata::sensor_model() const {
  config::SensorModel model;
  model.name.reserve(prod_line.size());
  for (unsigned char c : prod_line) model.name += static_cast<char>(std::tolower(c));
  model.beams = pixels_per_column;
  model.columns = columns_per_frame;
  model.rate_hz = rate_hz;
  for (double altitude : beam_altitude_deg) model.elevation_rad.push_back(altitude * kDegToRad);
  // SensorModel angles grow counter-clockwise (mathematical sense, as the column azimuth
  // does); Ouster's beam_azimuth_angles grow clockwise, hence the minus (PACKET_FORMAT.md:
  // theta_a = -2 pi azimuth / 360).
  for (double azimuth : beam_azimuth_deg) model.azimuth_offset_rad.push_back(-azimuth * kDegToRad);
  model.beam_origin_offset_m = lidar_origin_to_beam_origin_mm / 1000.0;
  // Ranges of the data sheets: the OS0 (formerly OS-DOME) sees to about 50 m at 10 %
  // reflectivity, so 100 m bounds it; the OS1 to 200 m. Closer than 0.5 m the returns come
  // from the housing and the mount.
  const std::string family = lower_alnum(prod_line);
  const bool os0 = family.rfind("os0", 0) == 0 || family.rfind("osdome", 0) == 0;
  model.min_range_m = 0.5;
  model.max_range_m = os0 ? 100.0 : 200.0;
  return model;
}

OusterMetadata parse_ouster_metadata(const std::string& json_text, const std::string& origin) {
  if (json_text.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw InputError(origin + ": empty metadata file (expected Ouster sensor metadata JSON)");
  }
  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::exception& e) {
    throw InputError(origin + ": not valid JSON: " + e.what());
  }
  if (!doc.is_object()) throw InputError(origin + ": expected a JSON object of sensor metadata");

  OusterMetadata meta;
  const KeyReader top(doc, "", origin);
  std::string profile_name = "LEGACY";
  const char* profile_key = "udp_profile_lidar";
  std::optional<KeyReader> profile_holder;
  std::optional<KeyReader> mode_holder;

  if (top.has("beam_intrinsics")) {  // the nested layout
    const KeyReader beams = top.object("beam_intrinsics");
    meta.beam_altitude_deg = beams.numbers("beam_altitude_angles");
    meta.beam_azimuth_deg = beams.numbers("beam_azimuth_angles");
    meta.lidar_origin_to_beam_origin_mm = beams.number("lidar_origin_to_beam_origin_mm");
    if (beams.has("beam_to_lidar_transform")) {
      meta.beam_to_lidar = beams.matrix4("beam_to_lidar_transform");
    }
    meta.lidar_to_sensor = top.object("lidar_intrinsics").matrix4("lidar_to_sensor_transform");
    if (top.has("imu_intrinsics")) {
      const KeyReader imu = top.object("imu_intrinsics");
      if (imu.has("imu_to_sensor_transform")) {
        meta.imu_to_sensor = imu.matrix4("imu_to_sensor_transform");
      }
    }
    const KeyReader format = top.object("lidar_data_format");
    parse_data_format(format, &meta);
    const KeyReader config = top.object("config_params");
    meta.lidar_mode = config.string("lidar_mode");
    mode_holder = config;
    parse_udp_ports(config, &meta);
    const KeyReader sensor_info = top.object("sensor_info");
    meta.prod_line = sensor_info.string("prod_line");
    meta.serial = sensor_info.optional_id("prod_sn");
    meta.initialization_id = sensor_info.optional_id("initialization_id");
    // Firmware writes the profile into lidar_data_format, older nested files only into
    // config_params; absent means the legacy packet format.
    if (format.has(profile_key)) {
      profile_holder = format;
    } else if (config.has(profile_key)) {
      profile_holder = config;
    }
  } else {  // the flat layout
    meta.beam_altitude_deg = top.numbers("beam_altitude_angles");
    meta.beam_azimuth_deg = top.numbers("beam_azimuth_angles");
    meta.lidar_origin_to_beam_origin_mm = top.number("lidar_origin_to_beam_origin_mm");
    meta.lidar_to_sensor = top.matrix4("lidar_to_sensor_transform");
    if (top.has("imu_to_sensor_transform")) {
      meta.imu_to_sensor = top.matrix4("imu_to_sensor_transform");
    }
    parse_udp_ports(top, &meta);
    if (top.has("beam_to_lidar_transform")) {
      meta.beam_to_lidar = top.matrix4("beam_to_lidar_transform");
    }
    const KeyReader format = top.object("data_format");
    parse_data_format(format, &meta);
    meta.lidar_mode = top.string("lidar_mode");
    mode_holder = top;
    meta.prod_line = top.string("prod_line");
    meta.serial = top.optional_id("prod_sn");
    meta.initialization_id = top.optional_id("initialization_id");
    if (format.has(profile_key)) profile_holder = format;
  }
  if (profile_holder) {
    profile_name = profile_holder->string(profile_key);
    meta.profile = parse_profile(profile_name, *profile_holder, profile_key);
  }

  int mode_columns = 0;
  parse_lidar_mode(meta.lidar_mode, *mode_holder, "lidar_mode", &mode_columns, &meta.rate_hz);
  if (mode_columns != meta.columns_per_frame) {
    mode_holder->fail("lidar_mode", "(\"" + meta.lidar_mode +
                                        "\") disagrees with columns_per_frame " +
                                        std::to_string(meta.columns_per_frame));
  }
  if (meta.beam_to_lidar == std::array<double, 16>{}) {
    // Absent: the beam origin lies n mm out along x, in the lidar's plane (PACKET_FORMAT.md).
    meta.beam_to_lidar = {1, 0, 0, meta.lidar_origin_to_beam_origin_mm, 0, 1, 0, 0, 0, 0, 1, 0, 0,
                          0, 0, 1};
  }
  validate(meta, origin);
  return meta;
}

}  // namespace featsense::slam
