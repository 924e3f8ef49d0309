// Ouster packet decoding and frame assembly on packets built here byte by byte from the
// layouts of PACKET_FORMAT.md, with known ranges and angles, checked against closed-form geometry.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>

#include "featsense/slam/io/ouster_frame_assembler.hpp"
#include "ouster_test_metadata.hpp"

namespace featsense::slam {
namespace {

using nlohmann::json;

constexpr int kBeams = 16;
constexpr int kColumns = 64;
constexpr uint64_t kFirstStampNs = 1'000'000'000'000;
constexpr uint64_t kColumnPeriodNs = 100'000'000 / kColumns;  // 10 Hz

void put_le(std::vector<uint8_t>& out, size_t at, uint64_t value, size_t bytes) {
  for (size_t i = 0; i < bytes; ++i) out[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

/// The values the test packets carry for beam `row` of measurement id `m` of `frame`.
uint32_t range_mm_of(int row, int m, int frame) {
  return static_cast<uint32_t>(2000 + 104 * row + 8 * m + 16 * frame);  // multiples of 8 mm
}
uint8_t reflectivity_of(int row, int m) { return static_cast<uint8_t>(row * 7 + m); }
uint16_t signal_of(int row, int m) { return static_cast<uint16_t>(1000 + row * 64 + m); }
uint8_t nir_of(int row, int m) { return static_cast<uint8_t>(200 - row - m); }
uint64_t timestamp_of(int m, int frame) {
  return kFirstStampNs + static_cast<uint64_t>(frame * kColumns + m) * kColumnPeriodNs;
}

struct PacketSpec {
  std::string profile;
  int frame = 0;
  int first_column = 0;  ///< measurement id of the packet's first column
  int columns = 16;      ///< columns per packet (legacy: always 16)
  std::function<bool(int m)> column_valid = [](int) { return true; };
  std::function<uint32_t(int row, int m)> range_word;  ///< raw range field, default range_mm_of
};

PacketSpec make_spec(const std::string& profile, int frame, int first_column, int columns) {
  PacketSpec spec;
  spec.profile = profile;
  spec.frame = frame;
  spec.first_column = first_column;
  spec.columns = columns;
  return spec;
}

/// One packet of PACKET_FORMAT.md's layouts.
std::vector<uint8_t> build_packet(const PacketSpec& spec) {
  const bool legacy = spec.profile == "LEGACY";
  const bool rng15 = spec.profile == "RNG15_RFL8_NIR8";
  const size_t pixel_bytes = rng15 ? 4 : 12;
  const size_t column_header = legacy ? 16 : 12;
  const size_t column_bytes = column_header + kBeams * pixel_bytes + (legacy ? 4 : 0);
  const size_t header = legacy ? 0 : 32;
  const size_t footer = legacy ? 0 : 32;
  std::vector<uint8_t> packet(header + static_cast<size_t>(spec.columns) * column_bytes + footer,
                              0);
  if (!legacy) {
    put_le(packet, 0, 1, 2);  // packet type: lidar
    put_le(packet, 2, static_cast<uint64_t>(spec.frame), 2);
  }
  for (int c = 0; c < spec.columns; ++c) {
    const int m = spec.first_column + c;
    const size_t at = header + static_cast<size_t>(c) * column_bytes;
    const bool valid = spec.column_valid(m);
    put_le(packet, at, timestamp_of(m, spec.frame), 8);
    put_le(packet, at + 8, static_cast<uint64_t>(m), 2);
    if (legacy) {
      put_le(packet, at + 10, static_cast<uint64_t>(spec.frame), 2);
      put_le(packet, at + 12, static_cast<uint64_t>(m) * 88, 4);  // encoder count
      put_le(packet, at + column_bytes - 4, valid ? 0xFFFFFFFFu : 0u, 4);
    } else {
      put_le(packet, at + 10, valid ? 1 : 0, 2);
    }
    for (int row = 0; row < kBeams; ++row) {
      const size_t p = at + column_header + static_cast<size_t>(row) * pixel_bytes;
      const uint32_t mm = range_mm_of(row, m, spec.frame);
      const uint32_t word = spec.range_word ? spec.range_word(row, m) : (rng15 ? mm / 8 : mm);
      if (rng15) {
        put_le(packet, p, word, 2);
        packet[p + 2] = reflectivity_of(row, m);
        packet[p + 3] = nir_of(row, m);
      } else {
        put_le(packet, p, word, 4);
        put_le(packet, p + 4, reflectivity_of(row, m), legacy ? 2 : 1);
        put_le(packet, p + 6, signal_of(row, m), 2);
        put_le(packet, p + 8, nir_of(row, m), 2);
      }
    }
  }
  return packet;
}

/// A frame's packets, first column 0, `columns_per_packet` columns each.
std::vector<std::vector<uint8_t>> build_frame(PacketSpec spec) {
  std::vector<std::vector<uint8_t>> packets;
  for (int first = 0; first < kColumns; first += spec.columns) {
    spec.first_column = first;
    packets.push_back(build_packet(spec));
  }
  return packets;
}

OusterMetadata metadata(const json& doc) { return parse_ouster_metadata(doc.dump(), "test"); }

/// Tiny metadata without offsets: no beam azimuths, no beam origin offset, identity
/// lidar-to-sensor transform, so that a point is r (cos phi cos theta, cos phi sin theta,
/// sin phi) with theta = 2 pi (1 - m / W).
json plain_metadata(const std::string& profile, int columns_per_packet = 16) {
  json doc = test::tiny_flat_metadata(profile, kBeams, kColumns, columns_per_packet);
  doc["beam_azimuth_angles"] = std::vector<double>(kBeams, 0.0);
  doc["lidar_origin_to_beam_origin_mm"] = 0.0;
  doc["lidar_to_sensor_transform"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  return doc;
}

/// Feeds a frame of `spec` and then one packet of the next frame; the completed first frame.
Scan assemble_one(OusterFrameAssembler& assembler, const PacketSpec& spec) {
  for (const auto& packet : build_frame(spec)) {
    EXPECT_FALSE(assembler.add_packet(packet.data(), packet.size()).has_value());
  }
  PacketSpec next = spec;
  next.frame = spec.frame + 1;
  const std::vector<uint8_t> packet = build_packet(next);
  std::optional<Scan> scan = assembler.add_packet(packet.data(), packet.size());
  EXPECT_TRUE(scan.has_value());
  return scan ? std::move(*scan) : Scan{};
}

/// The measurement id whose pixel of `row` lands in image column `col` (tiny metadata shifts
/// even rows by 3 columns, odd rows by 0).
int measurement_of(int row, int col) {
  const int shift = row % 2 == 0 ? 3 : 0;
  return ((col - shift) % kColumns + kColumns) % kColumns;
}

void expect_plain_geometry(const Scan& scan, int frame, bool has_signal) {
  ASSERT_EQ(scan.rows, kBeams);
  ASSERT_EQ(scan.cols, kColumns);
  EXPECT_EQ(scan.valid_count(), static_cast<size_t>(kBeams * kColumns));
  EXPECT_EQ(scan.stamp_ns, static_cast<int64_t>(timestamp_of(0, frame)));
  ASSERT_NE(scan.channel("reflectivity"), nullptr);
  ASSERT_NE(scan.channel("nir"), nullptr);
  ASSERT_EQ(scan.channel("signal") != nullptr, has_signal);
  for (int row = 0; row < kBeams; ++row) {
    const double phi = (15.0 - 30.0 * row / (kBeams - 1)) * M_PI / 180.0;
    for (int col = 0; col < kColumns; ++col) {
      const int m = measurement_of(row, col);
      const size_t i = scan.index(row, col);
      const double r = range_mm_of(row, m, frame) / 1000.0;
      const double theta = 2.0 * M_PI * (1.0 - static_cast<double>(m) / kColumns);
      const Eigen::Vector3d expected(r * std::cos(phi) * std::cos(theta),
                                     r * std::cos(phi) * std::sin(theta), r * std::sin(phi));
      ASSERT_EQ(scan.valid[i], 1) << row << " " << col;
      EXPECT_NEAR(static_cast<double>(scan.range_m[i]), r, 1e-6);
      EXPECT_LT((scan.xyz[i].cast<double>() - expected).norm(), 1e-5) << row << " " << col;
      EXPECT_NEAR(static_cast<double>(scan.time_offset_s[i]), m * kColumnPeriodNs * 1e-9, 1e-7);
      EXPECT_EQ(scan.channel("reflectivity")->values[i], reflectivity_of(row, m));
      EXPECT_EQ(scan.channel("nir")->values[i], nir_of(row, m));
      if (has_signal) {
        EXPECT_EQ(scan.channel("signal")->values[i], signal_of(row, m));
      }
    }
  }
}

TEST(OusterFrameAssembler, DecodesRng19Packets) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG19_RFL8_SIG16_NIR16", 8)));
  PacketSpec spec = make_spec("RNG19_RFL8_SIG16_NIR16", 5, 0, 8);
  expect_plain_geometry(assemble_one(assembler, spec), 5, true);
  EXPECT_EQ(assembler.rejected_packets(), 0u);
  EXPECT_EQ(assembler.incomplete_frames(), 0u);
}

TEST(OusterFrameAssembler, DecodesLegacyPackets) {
  OusterFrameAssembler assembler(metadata(plain_metadata("LEGACY")));
  expect_plain_geometry(assemble_one(assembler, make_spec("LEGACY", 9, 0, 16)), 9, true);
  OusterFrameAssembler absent_profile(metadata(plain_metadata("")));  // absent = legacy
  expect_plain_geometry(assemble_one(absent_profile, make_spec("LEGACY", 9, 0, 16)), 9, true);
}

TEST(OusterFrameAssembler, DecodesRng15Packets) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG15_RFL8_NIR8")));
  expect_plain_geometry(assemble_one(assembler, make_spec("RNG15_RFL8_NIR8", 2, 0, 16)), 2, false);
}

TEST(OusterFrameAssembler, RangeBitsAboveTheFieldAreIgnored) {
  // RNG19: 19 bits of range (PACKET_FORMAT.md); legacy 20. Bits above belong to other fields.
  for (const auto& [profile, bits] : {std::make_pair(std::string("RNG19_RFL8_SIG16_NIR16"), 19),
                                      std::make_pair(std::string("LEGACY"), 20)}) {
    OusterFrameAssembler assembler(metadata(plain_metadata(profile)));
    PacketSpec spec = make_spec(profile, 1, 0, 16);
    spec.range_word = [bits = bits](int row, int m) {
      return range_mm_of(row, m, 1) | (0xFFFFFFFFu << bits);
    };
    expect_plain_geometry(assemble_one(assembler, spec), 1, true);
  }
}

TEST(OusterFrameAssembler, OffsetsAndSensorTransform) {
  // The tiny metadata has beam azimuths of +-2 deg, a 15.806 mm beam origin offset and the
  // OS1's lidar_to_sensor_transform. Undo them as PACKET_FORMAT.md describes and the beam's own
  // angles and the reported range must come back.
  const json doc = test::tiny_flat_metadata("RNG19_RFL8_SIG16_NIR16");
  OusterFrameAssembler assembler(metadata(doc));
  const Scan scan = assemble_one(assembler, make_spec("RNG19_RFL8_SIG16_NIR16", 3, 0, 16));
  const double n = 0.015806;
  for (int row = 0; row < kBeams; ++row) {
    const double azimuth = (row % 2 == 0 ? 2.0 : -2.0) * M_PI / 180.0;
    const double phi = (15.0 - 30.0 * row / (kBeams - 1)) * M_PI / 180.0;
    for (int col = 0; col < kColumns; ++col) {
      const int m = measurement_of(row, col);
      const size_t i = scan.index(row, col);
      const Eigen::Vector3d p = scan.xyz[i].cast<double>();
      // The sensor frame flips x and y and lifts z by 36.18 mm.
      const Eigen::Vector3d lidar(-p.x(), -p.y(), p.z() - 0.03618);
      const double theta = 2.0 * M_PI * (1.0 - static_cast<double>(m) / kColumns);
      const Eigen::Vector3d beam = lidar - n * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0);
      const double r = range_mm_of(row, m, 3) / 1000.0;
      EXPECT_NEAR(beam.norm() + n, r, 1e-5);
      EXPECT_NEAR(std::asin(beam.z() / beam.norm()), phi, 1e-5);
      // Ouster's beam azimuth is clockwise: the beam looks at theta - azimuth.
      EXPECT_NEAR(std::remainder(std::atan2(beam.y(), beam.x()) - (theta - azimuth), 2 * M_PI), 0.0,
                  1e-5);
      EXPECT_NEAR(static_cast<double>(scan.range_m[i]), r, 1e-6);
    }
  }
}

TEST(OusterFrameAssembler, BeamToLidarZOffsetLiftsPoints) {
  json flat = plain_metadata("RNG19_RFL8_SIG16_NIR16");
  json nested = test::to_nested_layout(flat);
  nested["beam_intrinsics"]["beam_to_lidar_transform"][11] = 25.0;  // mm
  OusterFrameAssembler plain(metadata(flat));
  OusterFrameAssembler lifted(metadata(nested));
  const Scan a = assemble_one(plain, make_spec("RNG19_RFL8_SIG16_NIR16", 0, 0, 16));
  const Scan b = assemble_one(lifted, make_spec("RNG19_RFL8_SIG16_NIR16", 0, 0, 16));
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_LT((b.xyz[i] - a.xyz[i] - Eigen::Vector3f(0, 0, 0.025f)).norm(), 1e-6f);
  }
}

TEST(OusterFrameAssembler, InvalidColumnsAndZeroRanges) {
  OusterFrameAssembler assembler(metadata(plain_metadata("LEGACY")));
  PacketSpec spec = make_spec("LEGACY", 4, 0, 16);
  spec.column_valid = [](int m) { return m != 10; };
  spec.range_word = [](int row, int m) { return row == 5 ? 0u : range_mm_of(row, m, 4); };
  const Scan scan = assemble_one(assembler, spec);
  size_t expected_valid = 0;
  for (int row = 0; row < kBeams; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const int m = measurement_of(row, col);
      const bool valid = m != 10 && row != 5;
      expected_valid += valid;
      const size_t i = scan.index(row, col);
      EXPECT_EQ(scan.valid[i], valid ? 1 : 0) << row << " " << col;
      if (!valid) {
        EXPECT_EQ(scan.xyz[i], Eigen::Vector3f::Zero());
        EXPECT_EQ(scan.range_m[i], 0.0f);
      }
    }
  }
  EXPECT_EQ(scan.valid_count(), expected_valid);
  // Column 10 never arrived as valid: the frame is incomplete.
  EXPECT_EQ(assembler.incomplete_frames(), 1u);
}

TEST(OusterFrameAssembler, FramesCompleteOnANewFrameIdOrFlush) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG19_RFL8_SIG16_NIR16")));
  PacketSpec spec = make_spec("RNG19_RFL8_SIG16_NIR16", 65535, 0, 16);
  const Scan first = assemble_one(assembler, spec);  // ids wrap: 65535 then 0
  EXPECT_EQ(first.sequence, 0u);
  EXPECT_EQ(assembler.incomplete_frames(), 0u);
  // Frame 0 has one packet so far (columns 0..15); flush hands it out, incomplete.
  std::optional<Scan> second = assembler.flush();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->sequence, 1u);
  EXPECT_EQ(second->valid_count(), static_cast<size_t>(kBeams * 16));
  EXPECT_EQ(assembler.incomplete_frames(), 1u);
  EXPECT_FALSE(assembler.flush().has_value());  // nothing left
}

TEST(OusterFrameAssembler, FrameWithoutValidColumnsIsNotAScan) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG19_RFL8_SIG16_NIR16")));
  PacketSpec spec = make_spec("RNG19_RFL8_SIG16_NIR16", 1, 0, 16);
  spec.column_valid = [](int) { return false; };
  for (const auto& packet : build_frame(spec)) assembler.add_packet(packet.data(), packet.size());
  spec.frame = 2;
  const std::vector<uint8_t> next = build_packet(spec);
  EXPECT_FALSE(assembler.add_packet(next.data(), next.size()).has_value());
  EXPECT_FALSE(assembler.flush().has_value());
}

TEST(OusterFrameAssembler, RejectsWrongSizesAndIgnoresForeignColumns) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG19_RFL8_SIG16_NIR16")));
  std::vector<uint8_t> packet = build_packet(make_spec("RNG19_RFL8_SIG16_NIR16", 1, 0, 16));
  EXPECT_FALSE(assembler.add_packet(packet.data(), packet.size() - 1).has_value());
  packet.push_back(0);
  EXPECT_FALSE(assembler.add_packet(packet.data(), packet.size()).has_value());
  EXPECT_FALSE(assembler.add_packet(nullptr, 0).has_value());
  EXPECT_EQ(assembler.rejected_packets(), 3u);
  // Measurement ids 60..75: those >= 64 lie outside the frame and are ignored.
  const std::vector<uint8_t> straddling =
      build_packet(make_spec("RNG19_RFL8_SIG16_NIR16", 1, 60, 16));
  EXPECT_FALSE(assembler.add_packet(straddling.data(), straddling.size()).has_value());
  std::optional<Scan> scan = assembler.flush();
  ASSERT_TRUE(scan.has_value());
  EXPECT_EQ(scan->valid_count(), static_cast<size_t>(kBeams * 4));
  EXPECT_EQ(assembler.rejected_packets(), 3u);
}

TEST(OusterFrameAssembler, ColumnWindowDefinesACompleteFrame) {
  // Only columns 8..39 lit (PACKET_FORMAT.md: column_window): a frame of those is complete.
  json doc = plain_metadata("RNG19_RFL8_SIG16_NIR16");
  doc["data_format"]["column_window"] = {8, 39};
  OusterFrameAssembler assembler(metadata(doc));
  PacketSpec spec = make_spec("RNG19_RFL8_SIG16_NIR16", 1, 0, 16);
  spec.column_valid = [](int m) { return m >= 8 && m <= 39; };
  const Scan scan = assemble_one(assembler, spec);
  EXPECT_EQ(scan.valid_count(), static_cast<size_t>(kBeams * 32));
  EXPECT_EQ(scan.stamp_ns, static_cast<int64_t>(timestamp_of(8, 1)));  // the earliest lit column
  EXPECT_EQ(assembler.incomplete_frames(), 0u);
}

TEST(OusterFrameAssembler, MovesKeepTheFrameInProgress) {
  OusterFrameAssembler assembler(metadata(plain_metadata("RNG19_RFL8_SIG16_NIR16")));
  const std::vector<uint8_t> packet = build_packet(make_spec("RNG19_RFL8_SIG16_NIR16", 1, 0, 16));
  assembler.add_packet(packet.data(), packet.size());
  OusterFrameAssembler moved(std::move(assembler));
  std::optional<Scan> scan = moved.flush();
  ASSERT_TRUE(scan.has_value());
  EXPECT_EQ(scan->valid_count(), static_cast<size_t>(kBeams * 16));
}

}  // namespace
}  // namespace featsense::slam
