// Packets -> destaggered frames. Each valid column of a packet is written straight into the
// scan of its frame (at its destaggered image column), so a frame costs one pass over its
// pixels; time offsets are filled in when the frame completes and its earliest column is known.

#include "featsense/slam/io/ouster_frame_assembler.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "ouster/ouster_geometry.hpp"
#include "ouster/ouster_packet.hpp"

namespace featsense::slam {

struct OusterFrameAssembler::State {
  explicit State(const OusterMetadata& metadata)
      : layout(detail::OusterPacketLayout::of(metadata)),
        geometry(metadata),
        rows(metadata.pixels_per_column),
        cols(metadata.columns_per_frame),
        has_signal(metadata.profile != OusterProfile::kRng15Rfl8Nir8) {
    // Shifts normalised into [0, cols) so that the image column is one add and one compare.
    for (int shift : metadata.pixel_shift_by_row) {
      shift_by_row.push_back(((shift % cols) + cols) % cols);
    }
    const auto [first, last] = metadata.column_window;
    window_columns = first <= last ? last - first + 1 : cols - first + last + 1;
    pixels.resize(static_cast<size_t>(rows));
    column_timestamp_ns.assign(static_cast<size_t>(cols), 0);
    column_received.assign(static_cast<size_t>(cols), 0);
  }

  void start_frame(uint16_t id) {
    frame_id = id;
    in_progress = true;
    received_columns = 0;
    std::fill(column_received.begin(), column_received.end(), uint8_t{0});
    scan = Scan::allocate(rows, cols);
    // All channels first: adding one may move the others.
    scan.add_channel("reflectivity");
    scan.add_channel("nir");
    if (has_signal) scan.add_channel("signal");
    reflectivity = &scan.channel("reflectivity")->values;
    nir = &scan.channel("nir")->values;
    signal = has_signal ? &scan.channel("signal")->values : nullptr;
  }

  /// Writes the valid columns of a checked packet into the frame in progress.
  void add_columns(const detail::OusterPacketView& view) {
    for (int c = 0; c < layout.columns; ++c) {
      const detail::OusterColumnHeader header = view.column(c);
      // Columns outside the frame would index past the image: ignore them.
      if (!header.valid || header.measurement_id >= cols) continue;
      const int m = header.measurement_id;
      const size_t mi = static_cast<size_t>(m);
      if (!column_received[mi]) ++received_columns;
      column_received[mi] = 1;
      column_timestamp_ns[mi] = header.timestamp_ns;
      view.column_pixels(c, pixels.data());
      for (int row = 0; row < rows; ++row) {
        const detail::OusterPixel& pixel = pixels[static_cast<size_t>(row)];
        int image_col = m + shift_by_row[static_cast<size_t>(row)];
        if (image_col >= cols) image_col -= cols;
        const size_t i = scan.index(row, image_col);
        (*reflectivity)[i] = pixel.reflectivity;
        (*nir)[i] = pixel.nir;
        if (signal) (*signal)[i] = pixel.signal;
        if (pixel.range_mm == 0) {  // no return
          scan.invalidate(i);
          continue;
        }
        const float range_m = static_cast<float>(pixel.range_mm) * 1.0e-3f;
        scan.xyz[i] = range_m * geometry.direction(row, m) + geometry.offset(row, m);
        scan.range_m[i] = range_m;
        scan.valid[i] = 1;
      }
    }
  }

  /// Ends the frame in progress; the scan when it holds any valid column.
  std::optional<Scan> finish_frame(size_t* incomplete_frames) {
    in_progress = false;
    if (received_columns == 0) return std::nullopt;
    uint64_t stamp = std::numeric_limits<uint64_t>::max();
    for (int m = 0; m < cols; ++m) {
      const size_t mi = static_cast<size_t>(m);
      if (column_received[mi]) stamp = std::min(stamp, column_timestamp_ns[mi]);
    }
    scan.stamp_ns = static_cast<int64_t>(stamp);
    for (int row = 0; row < rows; ++row) {
      const int shift = shift_by_row[static_cast<size_t>(row)];
      for (int image_col = 0; image_col < cols; ++image_col) {
        int m = image_col - shift;
        if (m < 0) m += cols;
        const size_t mi = static_cast<size_t>(m);
        if (!column_received[mi]) continue;
        scan.time_offset_s[scan.index(row, image_col)] =
            static_cast<float>(static_cast<double>(column_timestamp_ns[mi] - stamp) * 1.0e-9);
      }
    }
    if (received_columns < window_columns) ++*incomplete_frames;
    scan.sequence = frames_emitted++;
    return std::move(scan);
  }

  const detail::OusterPacketLayout layout;
  const detail::OusterPixelGeometry geometry;
  const int rows;
  const int cols;
  const bool has_signal;
  std::vector<int> shift_by_row;  ///< in [0, cols)
  int window_columns = 0;         ///< columns a complete frame holds

  detail::OusterPacketView packet;
  std::vector<detail::OusterPixel> pixels;  ///< the column being decoded
  bool in_progress = false;
  uint16_t frame_id = 0;
  int received_columns = 0;
  std::vector<uint64_t> column_timestamp_ns;  ///< by measurement id
  std::vector<uint8_t> column_received;       ///< by measurement id
  Scan scan;
  std::vector<float>* reflectivity = nullptr;  ///< channels of `scan`
  std::vector<float>* nir = nullptr;
  std::vector<float>* signal = nullptr;
  uint64_t frames_emitted = 0;
};

OusterFrameAssembler::OusterFrameAssembler(OusterMetadata metadata)
    : metadata_(std::move(metadata)), state_(std::make_unique<State>(metadata_)) {}

OusterFrameAssembler::~OusterFrameAssembler() = default;
OusterFrameAssembler::OusterFrameAssembler(OusterFrameAssembler&&) noexcept = default;
OusterFrameAssembler& OusterFrameAssembler::operator=(OusterFrameAssembler&&) noexcept = default;

std::optional<Scan> OusterFrameAssembler::add_packet(const uint8_t* data, size_t size) {
  State& s = *state_;
  if (!s.packet.reset(s.layout, data, size)) {
    ++rejected_packets_;
    return std::nullopt;
  }
  const uint16_t frame_id = s.packet.frame_id();
  std::optional<Scan> completed;
  if (s.in_progress && frame_id != s.frame_id) completed = s.finish_frame(&incomplete_frames_);
  if (!s.in_progress) s.start_frame(frame_id);
  s.add_columns(s.packet);
  return completed;
}

std::optional<Scan> OusterFrameAssembler::flush() {
  State& s = *state_;
  if (!s.in_progress) return std::nullopt;
  return s.finish_frame(&incomplete_frames_);
}

}  // namespace featsense::slam
