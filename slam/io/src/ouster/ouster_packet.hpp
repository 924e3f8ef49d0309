#pragma once
// The byte layout of one Ouster lidar packet (a UDP payload) per profile, and bounds-checked
// access to its columns and pixels (PACKET_FORMAT.md).

#include <cstddef>
#include <cstdint>
#include <optional>

#include "featsense/slam/io/ouster_metadata.hpp"

namespace featsense::slam::detail {

/// Offsets and sizes in bytes of one packet of a given profile and geometry.
struct OusterPacketLayout {
  OusterProfile profile = OusterProfile::kLegacy;
  int columns = 0;          ///< columns per packet
  int pixels = 0;           ///< pixels per column
  size_t header_bytes = 0;  ///< packet header (0 in the legacy format)
  size_t column_header_bytes = 0;
  size_t pixel_bytes = 0;
  size_t column_bytes = 0;  ///< column header + pixels (+ the legacy status word)
  size_t footer_bytes = 0;  ///< packet footer (0 in the legacy format)
  size_t packet_bytes = 0;

  static OusterPacketLayout of(const OusterMetadata& metadata);
};

/// One decoded return of a pixel; range in millimetres (0 = no return).
struct OusterPixel {
  uint32_t range_mm = 0;
  uint16_t reflectivity = 0;
  uint16_t signal = 0;  ///< 0 where the profile has no signal channel
  uint16_t nir = 0;
};

/// The header of one column.
struct OusterColumnHeader {
  uint64_t timestamp_ns = 0;
  uint16_t measurement_id = 0;
  uint16_t frame_id = 0;  ///< the packet's frame id (legacy: the column's own)
  bool valid = false;     ///< the sensor marked the column as holding data
};

/// Who sent a packet, from its header: the unit's serial number and its initialization id.
struct OusterPacketSender {
  uint64_t serial = 0;
  uint64_t initialization_id = 0;
};

/// The sender of a lidar packet of `profile` (`size` bytes); nullopt in the legacy format,
/// whose packets have no header, or where the packet is shorter than one.
std::optional<OusterPacketSender> ouster_packet_sender(OusterProfile profile, const uint8_t* data,
                                                       size_t size);

/// A view of one packet whose size has been checked against its layout; every accessor stays
/// inside the packet for any column index < layout.columns and pixel index < layout.pixels.
class OusterPacketView {
 public:
  /// Points the view at a packet; false (view unchanged) unless `data` is set and `size`
  /// equals layout.packet_bytes.
  bool reset(const OusterPacketLayout& layout, const uint8_t* data, size_t size);

  /// The packet's frame id (legacy: that of its first valid column).
  uint16_t frame_id() const;
  OusterColumnHeader column(int column) const;
  /// All layout.pixels pixels of a column into `out` (one profile dispatch per column).
  void column_pixels(int column, OusterPixel* out) const;

 private:
  const uint8_t* column_start(int column) const {
    return data_ + layout_->header_bytes + static_cast<size_t>(column) * layout_->column_bytes;
  }

  const OusterPacketLayout* layout_ = nullptr;
  const uint8_t* data_ = nullptr;
};

}  // namespace featsense::slam::detail
