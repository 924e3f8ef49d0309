#include "ouster/ouster_packet.hpp"

#include "ouster/byte_order.hpp"

namespace featsense::slam::detail {
namespace {

// Layout constants of PACKET_FORMAT.md.
constexpr size_t kLegacyColumnsPerPacket = 16;
constexpr size_t kLegacyColumnHeaderBytes = 16;  // u64 timestamp, u16 id, u16 frame, u32 encoder
constexpr size_t kLegacyStatusBytes = 4;         // u32 status after the pixels
constexpr size_t kLegacyPixelBytes = 12;
constexpr uint32_t kLegacyValidStatus = 0xFFFFFFFFu;
constexpr size_t kPacketHeaderBytes = 32;
constexpr size_t kPacketFooterBytes = 32;
constexpr size_t kColumnHeaderBytes = 12;  // u64 timestamp, u16 measurement id, u16 status
constexpr size_t kRng19PixelBytes = 12;
constexpr size_t kRng15PixelBytes = 4;
constexpr uint32_t kRng19Mask = (1u << 19) - 1;
constexpr uint32_t kRng15Mask = (1u << 15) - 1;
constexpr uint32_t kLegacyRangeMask = (1u << 20) - 1;
constexpr uint32_t kRng15UnitMm = 8;  // the low-data-rate profile counts in 8 mm steps

}  // namespace

OusterPacketLayout OusterPacketLayout::of(const OusterMetadata& metadata) {
  OusterPacketLayout layout;
  layout.profile = metadata.profile;
  layout.pixels = metadata.pixels_per_column;
  const size_t pixels = static_cast<size_t>(metadata.pixels_per_column);
  switch (metadata.profile) {
    case OusterProfile::kLegacy:
      // The legacy format always packs 16 columns, whatever the metadata says.
      layout.columns = static_cast<int>(kLegacyColumnsPerPacket);
      layout.column_header_bytes = kLegacyColumnHeaderBytes;
      layout.pixel_bytes = kLegacyPixelBytes;
      layout.column_bytes =
          kLegacyColumnHeaderBytes + pixels * kLegacyPixelBytes + kLegacyStatusBytes;
      break;
    case OusterProfile::kRng19Rfl8Sig16Nir16:
    case OusterProfile::kRng15Rfl8Nir8:
      layout.columns = metadata.columns_per_packet;
      layout.header_bytes = kPacketHeaderBytes;
      layout.footer_bytes = kPacketFooterBytes;
      layout.column_header_bytes = kColumnHeaderBytes;
      layout.pixel_bytes =
          metadata.profile == OusterProfile::kRng15Rfl8Nir8 ? kRng15PixelBytes : kRng19PixelBytes;
      layout.column_bytes = kColumnHeaderBytes + pixels * layout.pixel_bytes;
      break;
  }
  layout.packet_bytes = layout.header_bytes +
                        static_cast<size_t>(layout.columns) * layout.column_bytes +
                        layout.footer_bytes;
  return layout;
}

bool OusterPacketView::reset(const OusterPacketLayout& layout, const uint8_t* data, size_t size) {
  if (data == nullptr || size != layout.packet_bytes || layout.columns < 1) return false;
  layout_ = &layout;
  data_ = data;
  return true;
}

std::optional<OusterPacketSender> ouster_packet_sender(OusterProfile profile, const uint8_t* data,
                                                       size_t size) {
  // The header: u16 packet type, u16 frame id, u24 init id, u40 serial (PACKET_FORMAT.md).
  if (profile == OusterProfile::kLegacy || data == nullptr || size < 12) return std::nullopt;
  OusterPacketSender sender;
  sender.initialization_id = load_le_bytes(data + 4, 3);
  sender.serial = load_le_bytes(data + 7, 5);
  return sender;
}

uint16_t OusterPacketView::frame_id() const {
  if (layout_->profile == OusterProfile::kLegacy) {
    // Each legacy column carries its own frame id; take the first valid column's, as
    // columns outside the column window may hold stale headers.
    for (int c = 0; c < layout_->columns; ++c) {
      const OusterColumnHeader header = column(c);
      if (header.valid) return header.frame_id;
    }
    return column(0).frame_id;
  }
  return load_le<uint16_t>(data_ + 2);  // after the u16 packet type
}

OusterColumnHeader OusterPacketView::column(int column) const {
  const uint8_t* start = column_start(column);
  OusterColumnHeader header;
  header.timestamp_ns = load_le<uint64_t>(start);
  header.measurement_id = load_le<uint16_t>(start + 8);
  if (layout_->profile == OusterProfile::kLegacy) {
    header.frame_id = load_le<uint16_t>(start + 10);
    const uint8_t* status = start + layout_->column_bytes - kLegacyStatusBytes;
    header.valid = load_le<uint32_t>(status) == kLegacyValidStatus;
  } else {
    header.frame_id = load_le<uint16_t>(data_ + 2);
    header.valid = (load_le<uint16_t>(start + 10) & 1u) != 0;
  }
  return header;
}

namespace {

/// Pixel decoders of PACKET_FORMAT.md, one per profile; `p` points at the pixel's first byte.
OusterPixel legacy_pixel(const uint8_t* p) {
  OusterPixel out;
  out.range_mm = load_le<uint32_t>(p) & kLegacyRangeMask;
  out.reflectivity = load_le<uint16_t>(p + 4);
  out.signal = load_le<uint16_t>(p + 6);
  out.nir = load_le<uint16_t>(p + 8);
  return out;
}

OusterPixel rng19_pixel(const uint8_t* p) {
  OusterPixel out;
  out.range_mm = load_le<uint32_t>(p) & kRng19Mask;
  out.reflectivity = p[4];
  out.signal = load_le<uint16_t>(p + 6);
  out.nir = load_le<uint16_t>(p + 8);
  return out;
}

OusterPixel rng15_pixel(const uint8_t* p) {
  OusterPixel out;
  out.range_mm = (load_le<uint16_t>(p) & kRng15Mask) * kRng15UnitMm;
  out.reflectivity = p[2];
  out.nir = p[3];
  return out;
}

template <OusterPixel (*Decode)(const uint8_t*)>
void decode_pixels(const uint8_t* first, size_t stride, int count, OusterPixel* out) {
  for (int i = 0; i < count; ++i) out[i] = Decode(first + static_cast<size_t>(i) * stride);
}

}  // namespace

void OusterPacketView::column_pixels(int column, OusterPixel* out) const {
  const uint8_t* first = column_start(column) + layout_->column_header_bytes;
  const size_t stride = layout_->pixel_bytes;
  switch (layout_->profile) {
    case OusterProfile::kLegacy:
      return decode_pixels<legacy_pixel>(first, stride, layout_->pixels, out);
    case OusterProfile::kRng19Rfl8Sig16Nir16:
      return decode_pixels<rng19_pixel>(first, stride, layout_->pixels, out);
    case OusterProfile::kRng15Rfl8Nir8:
      return decode_pixels<rng15_pixel>(first, stride, layout_->pixels, out);
  }
}

}  // namespace featsense::slam::detail
