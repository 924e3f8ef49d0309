#pragma once
// A Mapper that continues a saved map without given poses: the recording's odometry runs in
// a frame of its own while its keyframes are matched against the map's (relocalizer.hpp);
// nothing is written until it is placed. Placed, its keyframes join the map's in one pose
// graph with links between the sessions (session_links.hpp). Where the links move the map's
// earlier keyframes enough to change the map (map_policy.hpp) and every earlier input can be
// read again, the whole map is made again from the inputs with the corrected poses (into a
// new file that replaces the old one once complete); otherwise the earlier map stays as it is
// and the recording is mapped into it with its corrected poses.

#include <memory>
#include <vector>

#include "featsense/mapping/mapper.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/slam/loops/relocalizer.hpp"

namespace featsense::mapping {

class Mapper::Continuation {
 public:
  /// Checks the request and reads the saved map (whose voxel size and tau the Mapper then
  /// adopts: saved_metadata()).
  Continuation(const MapperSettings& settings, const RunEvents& events);

  const storage::MapMetadata& saved_metadata() const { return saved_.metadata; }
  const slam::loops::RelocalizeSettings& relocalize_settings() const { return settings_; }
  /// The relocalization as a stage of the first pass.
  RelocalizeStage stage() { return RelocalizeStage{relocalizer_.get(), max_scans_}; }

  /// After the first pass: placed (else RelocalizationFailed or Interrupted), linked, and
  /// mapped. Fills `result`.
  void finish(Mapper& mapper, MapResult& result);

 private:
  /// The recording placed in the map: every keyframe (the map's, then its own from
  /// `first_new`), its session id and its description as the map will keep it.
  struct Placed {
    std::vector<slam::loops::MapKeyframe> keyframes;
    size_t first_new = 0;
    uint32_t session_id = 0;
    SessionDescription session;
  };
  /// Where it was placed and how the links moved the sessions (the report and the final
  /// poses filled); throws where it was not placed.
  Placed place(const Mapper& mapper, MapResult& result);
  /// The mapping pass: into the saved map, or every session again into a new one.
  void map_placed(Mapper& mapper, MapResult& result, const Placed& placed);

  SavedMap saved_;
  slam::loops::RelocalizeSettings settings_;
  std::unique_ptr<slam::loops::Relocalizer> relocalizer_;
  size_t max_scans_ = 0;
};

}  // namespace featsense::mapping
