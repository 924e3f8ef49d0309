#pragma once
/// The size of a seekable input, for readers that check every length against it.

#include <cstdint>
#include <istream>
#include <string>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

/// The bytes of `stream`, which is left at its start. Throws InputError naming `origin`
/// where the size cannot be told (not a file) or is 0.
inline uint64_t nonempty_stream_size(std::istream& stream, const std::string& origin) {
  stream.clear();
  stream.seekg(0, std::ios::end);
  const std::streamoff end = stream.tellg();
  if (!stream || end < 0) throw InputError(origin + ": cannot tell its size (not a file?)");
  stream.seekg(0);
  if (end == 0) throw InputError(origin + ": empty file");
  return static_cast<uint64_t>(end);
}

}  // namespace featsense::slam
