// Ouster metadata JSON: both layouts, the values of a real sensor's file, and clear errors.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "common/test_data.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"
#include "ouster_test_metadata.hpp"
#include "pcap_test_util.hpp"

namespace featsense::slam {
namespace {

using nlohmann::json;

constexpr double kDegToRad = M_PI / 180.0;

OusterMetadata parse(const json& doc) { return parse_ouster_metadata(doc.dump(), "meta.json"); }

/// The message of the InputError that parsing `text` throws ("" when it does not throw).
std::string text_error(const std::string& text) {
  try {
    parse_ouster_metadata(text, "meta.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string parse_error(const json& doc) { return text_error(doc.dump()); }

void expect_same(const OusterMetadata& a, const OusterMetadata& b) {
  EXPECT_EQ(a.prod_line, b.prod_line);
  EXPECT_EQ(a.lidar_mode, b.lidar_mode);
  EXPECT_EQ(a.profile, b.profile);
  EXPECT_EQ(a.pixels_per_column, b.pixels_per_column);
  EXPECT_EQ(a.columns_per_packet, b.columns_per_packet);
  EXPECT_EQ(a.columns_per_frame, b.columns_per_frame);
  EXPECT_EQ(a.column_window, b.column_window);
  EXPECT_EQ(a.pixel_shift_by_row, b.pixel_shift_by_row);
  EXPECT_EQ(a.beam_altitude_deg, b.beam_altitude_deg);
  EXPECT_EQ(a.beam_azimuth_deg, b.beam_azimuth_deg);
  EXPECT_EQ(a.lidar_origin_to_beam_origin_mm, b.lidar_origin_to_beam_origin_mm);
  EXPECT_EQ(a.beam_to_lidar, b.beam_to_lidar);
  EXPECT_EQ(a.lidar_to_sensor, b.lidar_to_sensor);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.serial, b.serial);
  EXPECT_EQ(a.initialization_id, b.initialization_id);
}

TEST(OusterMetadata, ReadsTheOs1SensorFile) {
  FEATSENSE_SHARED_FILE(path, "ouster/OS-1-128_v2.3.0_1024x10.json");
  const std::string text = test::read_file(path);
  const json doc = json::parse(text);
  const OusterMetadata meta = parse_ouster_metadata(text, path.string());
  EXPECT_EQ(meta.prod_line, "OS-1-128");
  EXPECT_EQ(meta.lidar_mode, "1024x10");
  EXPECT_EQ(meta.profile, OusterProfile::kRng15Rfl8Nir8);
  EXPECT_EQ(meta.pixels_per_column, 128);
  EXPECT_EQ(meta.columns_per_packet, 16);
  EXPECT_EQ(meta.columns_per_frame, 1024);
  EXPECT_EQ(meta.column_window, (std::array<int, 2>{0, 1023}));
  EXPECT_EQ(meta.rate_hz, 10.0);
  EXPECT_EQ(meta.beam_altitude_deg, doc["beam_altitude_angles"].get<std::vector<double>>());
  EXPECT_EQ(meta.beam_azimuth_deg, doc["beam_azimuth_angles"].get<std::vector<double>>());
  EXPECT_EQ(meta.pixel_shift_by_row,
            doc["data_format"]["pixel_shift_by_row"].get<std::vector<int>>());
  EXPECT_EQ(meta.lidar_origin_to_beam_origin_mm, 15.806);
  // PACKET_FORMAT.md: on the OS1 the transform flips x and y and lifts z by 36.18 mm.
  EXPECT_EQ(meta.lidar_to_sensor[0], -1.0);
  EXPECT_EQ(meta.lidar_to_sensor[5], -1.0);
  EXPECT_EQ(meta.lidar_to_sensor[10], 1.0);
  EXPECT_EQ(meta.lidar_to_sensor[11], 36.18);
  // PACKET_FORMAT.md: 32 + 16 x (12 + 128 x 4) + 32 bytes, as the pcap's packets are.
  EXPECT_EQ(meta.packet_size(), 8448u);
  // Who it is of: the serial is a string there, as the pcap's packet headers say
  // (bytes 7-11: 122201000998; bytes 4-6: 7109750).
  EXPECT_EQ(meta.serial, std::optional<uint64_t>(122201000998u));
  EXPECT_EQ(meta.initialization_id, std::optional<uint64_t>(7109750u));
}

TEST(OusterMetadata, TheUnitsIdentityIsOptionalButNeverMalformed) {
  json doc = test::tiny_flat_metadata("RNG19_RFL8_SIG16_NIR16");
  EXPECT_FALSE(parse(doc).serial);
  EXPECT_FALSE(parse(doc).initialization_id);
  doc["prod_sn"] = 992109000123u;  // a number is taken too
  doc["initialization_id"] = 12;
  EXPECT_EQ(parse(doc).serial, std::optional<uint64_t>(992109000123u));
  EXPECT_EQ(parse(doc).initialization_id, std::optional<uint64_t>(12u));
  for (const json& bad : {json("12a4"), json(-3), json(""), json(1.5)}) {
    doc["prod_sn"] = bad;
    try {
      parse(doc);
      ADD_FAILURE() << "took prod_sn " << bad.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("'prod_sn' must be a non-negative integer"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(OusterMetadata, SensorModelFollowsTheMetadata) {
  const OusterMetadata meta = parse(test::tiny_flat_metadata("RNG19_RFL8_SIG16_NIR16"));
  const config::SensorModel model = meta.sensor_model();
  EXPECT_EQ(model.name, "os-1-16");
  EXPECT_EQ(model.beams, 16);
  EXPECT_EQ(model.columns, 64);
  EXPECT_EQ(model.rate_hz, 10.0);
  ASSERT_EQ(model.elevation_rad.size(), 16u);
  EXPECT_DOUBLE_EQ(model.elevation_rad.front(), 15.0 * kDegToRad);  // row 0 is the highest
  EXPECT_DOUBLE_EQ(model.elevation_rad.back(), -15.0 * kDegToRad);
  // SensorModel offsets are counter-clockwise; Ouster's azimuths clockwise.
  EXPECT_DOUBLE_EQ(model.azimuth_offset_rad[0], -2.0 * kDegToRad);
  EXPECT_DOUBLE_EQ(model.azimuth_offset_rad[1], 2.0 * kDegToRad);
  EXPECT_DOUBLE_EQ(model.beam_origin_offset_m, 0.015806);
  EXPECT_EQ(model.min_range_m, 0.5);
  EXPECT_EQ(model.max_range_m, 200.0);
  EXPECT_NO_THROW(model.validate());

  json os0 = test::tiny_flat_metadata("");
  os0["prod_line"] = "OS-0-128";
  EXPECT_EQ(parse(os0).sensor_model().max_range_m, 100.0);
  EXPECT_EQ(parse(os0).sensor_model().name, "os-0-128");
}

TEST(OusterMetadata, NestedLayoutGivesTheSameResult) {
  for (const char* profile : {"LEGACY", "RNG19_RFL8_SIG16_NIR16", "RNG15_RFL8_NIR8", ""}) {
    SCOPED_TRACE(profile);
    const json flat = test::tiny_flat_metadata(profile);
    expect_same(parse(flat), parse(test::to_nested_layout(flat)));
  }
}

TEST(OusterMetadata, NestedLayoutOfTheRealSensorFile) {
  FEATSENSE_SHARED_FILE(path, "ouster/OS-1-128_v2.3.0_1024x10.json");
  const json flat = json::parse(test::read_file(path));
  json nested = test::to_nested_layout(flat);
  // Newer firmware also writes the profile into lidar_data_format: it must agree.
  nested["lidar_data_format"]["udp_profile_lidar"] = "RNG15_RFL8_NIR8";
  expect_same(parse(flat), parse(nested));
  // A z offset in beam_to_lidar_transform is read (only the nested layout has one).
  nested["beam_intrinsics"]["beam_to_lidar_transform"][11] = 4.5;
  EXPECT_EQ(parse(nested).beam_to_lidar[11], 4.5);
}

TEST(OusterMetadata, ProfilesAndPacketSizes) {
  // PACKET_FORMAT.md: legacy = 16 x (16 + 12 H + 4); new profiles = 32 + C x (12 + P H) + 32.
  EXPECT_EQ(parse(test::tiny_flat_metadata("")).profile, OusterProfile::kLegacy);
  EXPECT_EQ(parse(test::tiny_flat_metadata("")).packet_size(), 16u * (16 + 16 * 12 + 4));
  EXPECT_EQ(parse(test::tiny_flat_metadata("LEGACY", 64, 1024)).packet_size(), 12608u);
  EXPECT_EQ(parse(test::tiny_flat_metadata("RNG19_RFL8_SIG16_NIR16", 128, 1024)).packet_size(),
            24832u);  // the OS2-128 size PACKET_FORMAT.md quotes
  EXPECT_EQ(parse(test::tiny_flat_metadata("RNG15_RFL8_NIR8", 16, 64, 8)).packet_size(),
            32u + 8 * (12 + 16 * 4) + 32);
  EXPECT_EQ(to_string(OusterProfile::kRng19Rfl8Sig16Nir16), "RNG19_RFL8_SIG16_NIR16");
}

TEST(OusterMetadata, RateComesFromTheLidarMode) {
  json doc = test::tiny_flat_metadata("", 16, 512);
  doc["lidar_mode"] = "512x20";
  EXPECT_EQ(parse(doc).rate_hz, 20.0);
  doc["lidar_mode"] = "1024x20";  // disagrees with columns_per_frame
  EXPECT_NE(parse_error(doc).find("lidar_mode"), std::string::npos);
  doc["lidar_mode"] = "fast";
  EXPECT_NE(parse_error(doc).find("'lidar_mode' must look like"), std::string::npos);
}

TEST(OusterMetadata, MissingKeysAreNamed) {
  const json flat = test::tiny_flat_metadata("RNG15_RFL8_NIR8");
  const std::vector<std::vector<std::string>> flat_keys = {{"beam_altitude_angles"},
                                                           {"beam_azimuth_angles"},
                                                           {"lidar_origin_to_beam_origin_mm"},
                                                           {"lidar_to_sensor_transform"},
                                                           {"lidar_mode"},
                                                           {"prod_line"},
                                                           {"data_format"},
                                                           {"data_format", "pixels_per_column"},
                                                           {"data_format", "columns_per_frame"},
                                                           {"data_format", "pixel_shift_by_row"},
                                                           {"data_format", "column_window"},
                                                           {"data_format", "columns_per_packet"}};
  const json nested = test::to_nested_layout(flat);
  const std::vector<std::vector<std::string>> nested_keys = {
      {"beam_intrinsics", "beam_altitude_angles"},
      {"lidar_intrinsics"},
      {"lidar_intrinsics", "lidar_to_sensor_transform"},
      {"lidar_data_format", "columns_per_frame"},
      {"config_params", "lidar_mode"},
      {"sensor_info", "prod_line"},
      {"sensor_info"}};
  for (const auto& [doc, keys] :
       {std::make_pair(flat, flat_keys), std::make_pair(nested, nested_keys)}) {
    for (const std::vector<std::string>& key : keys) {
      json broken = doc;
      std::string dotted = key[0];
      if (key.size() == 1) {
        broken.erase(key[0]);
      } else {
        broken[key[0]].erase(key[1]);
        dotted += "." + key[1];
      }
      const std::string message = parse_error(broken);
      EXPECT_NE(message.find("meta.json"), std::string::npos) << message;
      EXPECT_NE(message.find("missing key '" + dotted + "'"), std::string::npos) << message;
    }
  }
}

TEST(OusterMetadata, WrongTypesAreNamed) {
  const json flat = test::tiny_flat_metadata("RNG15_RFL8_NIR8");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> cases = {
      {[](json& d) { d["beam_altitude_angles"] = "many"; }, "'beam_altitude_angles' must be"},
      {[](json& d) { d["beam_azimuth_angles"][3] = "x"; }, "'beam_azimuth_angles' must be"},
      {[](json& d) { d["data_format"]["columns_per_frame"] = "64"; },
       "'data_format.columns_per_frame' must be an integer"},
      {[](json& d) { d["data_format"]["pixel_shift_by_row"][0] = 1.5; },
       "'data_format.pixel_shift_by_row' must be an array of integers"},
      {[](json& d) { d["lidar_mode"] = 64; }, "'lidar_mode' must be a string"},
      {[](json& d) { d["data_format"] = 5; }, "'data_format' must be an object"},
      {[](json& d) {
         d["lidar_to_sensor_transform"] = {1, 0, 0};
       },
       "'lidar_to_sensor_transform' must hold 16 numbers"},
      {[](json& d) { d["data_format"]["pixels_per_column"] = 1e12; },
       "'data_format.pixels_per_column' must be an integer"},
  };
  for (const auto& [edit, expected] : cases) {
    json broken = flat;
    edit(broken);
    const std::string message = parse_error(broken);
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  }
}

TEST(OusterMetadata, UnsupportedProfilesAreNamed) {
  std::string message = parse_error(test::tiny_flat_metadata("RNG99_FANCY"));
  EXPECT_NE(message.find("'data_format.udp_profile_lidar'"), std::string::npos) << message;
  EXPECT_NE(message.find("RNG99_FANCY"), std::string::npos) << message;
  message = parse_error(test::tiny_flat_metadata("RNG19_RFL8_SIG16_NIR16_DUAL"));
  EXPECT_NE(message.find("dual-return"), std::string::npos) << message;
  EXPECT_NE(message.find("RNG19_RFL8_SIG16_NIR16_DUAL"), std::string::npos) << message;
  // Nested files name the profile in lidar_data_format, older ones only in config_params.
  json nested = test::to_nested_layout(test::tiny_flat_metadata("FUSA_RNG15_RFL8_NIR8_DUAL"));
  message = parse_error(nested);
  EXPECT_NE(message.find("'lidar_data_format.udp_profile_lidar'"), std::string::npos) << message;
  nested["lidar_data_format"].erase("udp_profile_lidar");
  message = parse_error(nested);
  EXPECT_NE(message.find("'config_params.udp_profile_lidar'"), std::string::npos) << message;
}

TEST(OusterMetadata, EmptyOrNonJsonFiles) {
  EXPECT_NE(text_error("").find("meta.json: empty"), std::string::npos);
  EXPECT_NE(text_error(" \n\t").find("meta.json: empty"), std::string::npos);
  EXPECT_NE(text_error("{\"beam_altitude_angles\": [1,").find("not valid JSON"), std::string::npos);
  EXPECT_NE(text_error("[1, 2]").find("expected a JSON object"), std::string::npos);
  EXPECT_NE(text_error("{}").find("missing key 'beam_altitude_angles'"), std::string::npos);
}

TEST(OusterMetadata, InconsistentMetadataIsRejected) {
  const json flat = test::tiny_flat_metadata("RNG15_RFL8_NIR8");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> cases = {
      {[](json& d) { d["beam_altitude_angles"].erase(0); }, "beam_altitude_angles has 15 entries"},
      {[](json& d) { d["beam_azimuth_angles"].push_back(0.0); }, "beam_azimuth_angles has 17"},
      {[](json& d) { d["data_format"]["pixel_shift_by_row"].erase(0); },
       "pixel_shift_by_row has 15"},
      {[](json& d) { d["data_format"]["pixel_shift_by_row"][2] = 64; },
       "pixel_shift_by_row holds 64"},
      {[](json& d) {
         d["data_format"]["column_window"] = {0, 64};
       },
       "column_window [0, 64] lies outside"},
      {[](json& d) {
         d["data_format"]["column_window"] = {-1, 10};
       },
       "lies outside"},
      {[](json& d) { d["data_format"]["column_window"] = {3}; }, "must hold two"},
      {[](json& d) {
         d["data_format"]["columns_per_frame"] = 0;
         d["lidar_mode"] = "0x10";
       },
       "lidar_mode"},
      {[](json& d) { d["data_format"]["pixels_per_column"] = 0; }, "pixels_per_column must be"},
      {[](json& d) { d["data_format"]["columns_per_packet"] = -2; }, "columns_per_packet must be"},
      {[](json& d) { d["beam_altitude_angles"][1] = 400.0; }, "impossible altitude"},
  };
  for (const auto& [edit, expected] : cases) {
    json broken = flat;
    edit(broken);
    const std::string message = parse_error(broken);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << message;
  }
}

TEST(OusterMetadata, ZeroColumnsPerFrameIsRejected) {
  json doc = test::tiny_flat_metadata("");
  doc["data_format"]["columns_per_frame"] = 0;
  // lidar_mode still says 64: whichever check runs first, the message names the problem.
  const std::string message = parse_error(doc);
  EXPECT_FALSE(message.empty());
  EXPECT_TRUE(message.find("columns_per_frame") != std::string::npos) << message;
}

}  // namespace
}  // namespace featsense::slam
