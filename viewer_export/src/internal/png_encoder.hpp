#pragma once
// The one PNG writer of the viewer_export room (8-bit RGBA, zlib): no image library needed.

#include <cstdint>
#include <string>
#include <vector>

namespace featsense::viewer_export {

/// Writes `rgba` (rows from the top, 4 bytes a pixel) to `path`. Throws std::runtime_error
/// when the file cannot be written.
void write_rgba_png(const std::string& path, const std::vector<uint8_t>& rgba, int width,
                    int height);

}  // namespace featsense::viewer_export
