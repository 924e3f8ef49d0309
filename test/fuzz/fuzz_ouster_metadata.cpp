// libFuzzer target: arbitrary text as Ouster metadata JSON. Anything but a clean InputError (an
// escaped exception of another type, a crash, a sanitizer report) is a finding; metadata that
// parses must also give a sensor model and a packet size without trouble.

#include <cstddef>
#include <cstdint>
#include <string>

#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const featsense::slam::OusterMetadata metadata =
        featsense::slam::parse_ouster_metadata(text, "fuzz input");
    static_cast<void>(metadata.packet_size());
    static_cast<void>(metadata.sensor_model());
  } catch (const featsense::slam::InputError&) {
    // The expected outcome for most inputs.
  }
  return 0;
}
