#pragma once
// What `featsense live --view` serves while the map is made: the latest mesh of every chunk
// (from the pass's preview, slam/mapping map_preview.hpp), the path so far, the latest pose
// and the run's figures. The page asks for what changed since the version it holds, so a
// refresh sends the chunks re-meshed since then, not the whole map.
//
// The changes' binary (/live/mesh.bin?since=V), little-endian, 4-byte aligned:
//   bytes 0..7   magic "FSLIVE1" and a zero byte
//   uint32       the version it brings the page to
//   uint32       chunk count c
//   c times:     int32 chunk x, y, z; uint32 byte length L; L bytes of the chunk's mesh in the
//                viewer's binary (viewer_export/viewer_mesh_binary.hpp, no layers), L = 0
//                where the chunk holds no surface any more

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "featsense/mapping/map_preview.hpp"

namespace featsense::app {

inline constexpr char kLiveMeshMagic[8] = {'F', 'S', 'L', 'I', 'V', 'E', '1', '\0'};

class LiveView {
 public:
  /// `name`: what the page's title says (the output folder).
  explicit LiveView(std::string name);

  /// A refresh of the pass (any thread).
  void take(mapping::MapPreview preview);
  /// The run has ended (the page says so and stops asking).
  void set_finished();

  /// The run's figures, the latest pose and the path from its `path_from`-th position on.
  nlohmann::json status(size_t path_from) const;
  /// The chunks changed after version `since` (all of them for 0), as the binary above.
  std::string changes_since(uint64_t since) const;

 private:
  struct ChunkEntry {
    uint64_t version = 0;
    std::string mesh;  ///< the viewer's binary; empty: no surface
    size_t triangles = 0;
  };

  mutable std::mutex mutex_;
  std::string name_;
  uint64_t version_ = 0;
  std::map<storage::ChunkKey, ChunkEntry> chunks_;
  size_t triangles_ = 0;
  size_t chunks_with_surface_ = 0;
  std::vector<float> path_;     ///< x, y, z of each final pose
  mapping::MapPreview latest_;  ///< without chunks and poses
  bool finished_ = false;
};

}  // namespace featsense::app
