// libFuzzer target: arbitrary bytes as a pcap capture of an Ouster OS1-128 (the path of
// open_ouster_pcap: pcap records -> link layer -> IPv4 reassembly -> UDP -> frame assembly),
// and the same bytes as raw lidar packets of small legacy and RNG19 sensors, so that every
// packet decoder sees them.
//
// The OS1-128 metadata is the shared recording's JSON, read once: from $FEATSENSE_FUZZ_META,
// else from ../shared/data beside the source tree.

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "featsense/slam/io/ouster_frame_assembler.hpp"
#include "featsense/slam/scan_source.hpp"
#include "ouster/pcap_udp_reader.hpp"

namespace {

using featsense::slam::InputError;
using featsense::slam::OusterFrameAssembler;
using featsense::slam::OusterMetadata;

OusterMetadata os1_metadata() {
  const char* from_env = std::getenv("FEATSENSE_FUZZ_META");
  const std::string path = from_env != nullptr ? from_env
                                               : FEATSENSE_SOURCE_DIR
                               "/../shared/data/ouster/OS-1-128_v2.3.0_1024x10.json";
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file) {
    std::fprintf(stderr, "fuzz_pcap: cannot read %s (set FEATSENSE_FUZZ_META)\n", path.c_str());
    std::abort();
  }
  return featsense::slam::parse_ouster_metadata(text.str(), path);
}

/// The metadata with the frame narrowed to its first 128 columns: packets keep their size and
/// layout (they do not depend on columns_per_frame), ids of 128 and more take the path of
/// foreign columns, and a frame costs an eighth of the memory, which under the sanitizers
/// multiplies the executions per second about five times.
OusterMetadata narrowed(OusterMetadata metadata) {
  metadata.columns_per_frame = 128;
  metadata.column_window = {0, 127};
  return metadata;
}

/// A 16-beam, 64-column sensor of `profile` in the flat metadata layout.
OusterMetadata small_metadata(const std::string& profile) {
  std::string altitudes;
  std::string azimuths;
  std::string shifts;
  for (int i = 0; i < 16; ++i) {
    const std::string sep = i == 0 ? "" : ",";
    altitudes += sep + std::to_string(15 - 2 * i);
    azimuths += sep + (i % 2 == 0 ? "2.1" : "-2.1");
    shifts += sep + (i % 2 == 0 ? "60" : "0");  // large shifts make destaggering wrap
  }
  const std::string json = R"({"beam_altitude_angles": [)" + altitudes +
                           R"(], "beam_azimuth_angles": [)" + azimuths +
                           R"(], "lidar_origin_to_beam_origin_mm": 15.8,
      "lidar_to_sensor_transform": [-1,0,0,0, 0,-1,0,0, 0,0,1,36.18, 0,0,0,1],
      "lidar_mode": "64x10", "prod_line": "OS-1-16",
      "data_format": {"pixels_per_column": 16, "columns_per_packet": 16,
        "columns_per_frame": 64, "column_window": [60, 10], "pixel_shift_by_row": [)" +
                           shifts + R"(], "udp_profile_lidar": ")" + profile + R"("}})";
  return featsense::slam::parse_ouster_metadata(json, "small " + profile);
}

/// Feeds a capture through the pcap reader into `assembler`.
void decode_capture(const std::string& bytes, OusterFrameAssembler& assembler) {
  std::istringstream in(bytes);
  featsense::slam::detail::PcapUdpReader reader(in, "fuzz input");
  const size_t packet_size = assembler.metadata().packet_size();
  while (std::optional<featsense::slam::detail::UdpDatagram> datagram = reader.next()) {
    if (datagram->size == packet_size) assembler.add_packet(datagram->payload, datagram->size);
  }
}

/// Feeds `data` as consecutive raw packets of the assembler's size (the last one short, and
/// therefore rejected).
void decode_raw_packets(const uint8_t* data, size_t size, OusterFrameAssembler& assembler) {
  const size_t packet_size = assembler.metadata().packet_size();
  for (size_t at = 0; at < size; at += packet_size) {
    assembler.add_packet(data + at, std::min(packet_size, size - at));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Built once: the geometry tables of a 128 x 1024 sensor take far longer than one input.
  // Each input ends with flush(), so no frame carries over into the next input.
  static OusterFrameAssembler os1_full(os1_metadata());
  static OusterFrameAssembler os1(narrowed(os1_metadata()));
  static OusterFrameAssembler legacy(small_metadata("LEGACY"));
  static OusterFrameAssembler rng19(small_metadata("RNG19_RFL8_SIG16_NIR16"));

  // One input in eight (by its length) takes the full-width frame.
  OusterFrameAssembler& capture_assembler = size % 8 == 0 ? os1_full : os1;
  try {
    decode_capture(std::string(reinterpret_cast<const char*>(data), size), capture_assembler);
  } catch (const InputError&) {
    // A bad global header: the expected outcome for most byte strings.
  }
  capture_assembler.flush();
  decode_raw_packets(data, size, legacy);
  legacy.flush();
  decode_raw_packets(data, size, rng19);
  rng19.flush();
  return 0;
}
