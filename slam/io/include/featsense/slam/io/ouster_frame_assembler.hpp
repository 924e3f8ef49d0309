#pragma once
/// Decodes Ouster lidar packets and assembles them into destaggered Scans, one per frame
/// id. Shared by the pcap reader and the ROS bag reader (raw PacketMsg topics).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::slam {

class OusterFrameAssembler {
 public:
  explicit OusterFrameAssembler(OusterMetadata metadata);
  ~OusterFrameAssembler();
  OusterFrameAssembler(OusterFrameAssembler&&) noexcept;
  OusterFrameAssembler& operator=(OusterFrameAssembler&&) noexcept;

  /// Feeds one lidar packet (a whole UDP payload). Returns a completed scan when this packet
  /// starts a new frame id and the previous frame had any valid column. A packet of the wrong
  /// size is rejected (returns nullopt, counted in rejected_packets()).
  std::optional<Scan> add_packet(const uint8_t* data, size_t size);
  /// The frame in progress, if it has any valid column (call at the end of the input).
  std::optional<Scan> flush();

  size_t rejected_packets() const { return rejected_packets_; }
  /// Frames whose columns were not all received (returned anyway, missing columns invalid).
  size_t incomplete_frames() const { return incomplete_frames_; }
  const OusterMetadata& metadata() const { return metadata_; }

 private:
  OusterMetadata metadata_;
  size_t rejected_packets_ = 0;
  size_t incomplete_frames_ = 0;
  // Frame in progress, precomputed per-pixel geometry and so on: the implementation's.
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace featsense::slam
