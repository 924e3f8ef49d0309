#include "featsense/mapping/merge_maps.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "featsense/mapping/map_store.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/slam/loops/session_links.hpp"

namespace featsense::mapping {
namespace {

using slam::loops::MapKeyframe;

SavedMap read_map_to_merge(const std::string& path, const config::Config& config) {
  SavedMap saved = read_saved_map(path);
  if (saved.keyframes.empty()) {
    throw std::runtime_error(path +
                             " keeps no keyframes (made with given poses, with loop closure off or "
                             "by an older featsense): maps are merged by their keyframes");
  }
  const std::string why = why_sessions_cannot_be_read(saved, config);
  if (!why.empty()) {
    throw std::runtime_error("merge maps every session again from its input, and in " + path + " " +
                             why);
  }
  return saved;
}

}  // namespace

MergeResult merge_maps(const std::string& first_path, const std::string& second_path,
                       const std::filesystem::path& output, config::Config config,
                       const RunEvents& events) {
  const SavedMap first = read_map_to_merge(first_path, config);
  const SavedMap second = read_map_to_merge(second_path, config);
  config = with_map_geometry(std::move(config), first.metadata, first_path, events);

  // B's keyframes, in order, against A's: the first that is confirmed places B.
  slam::loops::RelocalizeSettings settings = slam::loops::relocalize_from_config(config);
  slam::loops::Relocalizer relocalizer(first.keyframes, settings);
  for (const MapKeyframe& keyframe : second.keyframes) {
    if (relocalizer.add_keyframe(keyframe.stamp_ns, keyframe.T_map_sensor, keyframe.travelled_m,
                                 keyframe.cloud.points()))
      break;
  }
  MergeResult result;
  result.tried = relocalizer.counts();
  if (!relocalizer.placement()) {
    result.why = second_path + " could not be placed in " + first_path + ": none of its " +
                 std::to_string(second.keyframes.size()) + " keyframes matched the " +
                 std::to_string(first.keyframes.size()) + " of " + first_path + " (" +
                 std::to_string(result.tried.candidates) + " candidates, " +
                 std::to_string(result.tried.verified) +
                 " verified); the maps may show different places. Nothing written.";
    return result;
  }
  const slam::loops::Relocalization& placement = *relocalizer.placement();
  result.placement = placement;

  // Both maps' sessions in one graph, B's numbered after A's and placed by the match.
  uint32_t offset = 0;
  for (const SavedSession& s : first.sessions) offset = std::max(offset, s.session.id + 1);
  std::vector<MapKeyframe> keyframes = first.keyframes;
  const size_t first_second = keyframes.size();
  for (MapKeyframe keyframe : second.keyframes) {
    keyframe.session += offset;
    keyframe.T_map_sensor = placement.T_map_session * keyframe.T_map_sensor;
    keyframes.push_back(std::move(keyframe));
  }
  slam::loops::SessionLinkSettings link_settings;
  link_settings.loop = settings.loop;
  result.links.linked = slam::loops::link_sessions(keyframes, link_settings, std::nullopt);
  result.links.keyframes = keyframe_ids(keyframes);
  const slam::loops::SessionLinkResult& linked = result.links.linked;
  char text[200];
  std::snprintf(text, sizeof text,
                " (%zu keyframes agreeing, fitness %.1f mm); %zu links between the sessions",
                placement.agreeing, 1000.0 * placement.fitness_m, linked.links.size());
  events.info(second_path + " placed in " + first_path + text);

  result.sessions = session_remaps(first, keyframes, 0, 0, Eigen::Isometry3d::Identity(),
                                   linked.poses, "; merged with " + second_path);
  for (SessionRemap& remap :
       session_remaps(second, keyframes, first_second, offset, placement.T_map_session,
                      linked.poses, "; merged into " + first_path + " (relocalized)"))
    result.sessions.push_back(std::move(remap));
  const PassSettings replay = pass_settings(config);
  const std::filesystem::path partial = std::filesystem::path(output.string() + ".partial");
  build_then_replace(partial, output, [&] {
    result.reintegration = remap_sessions_where_moved(first, result.sessions, partial, replay,
                                                      config, first.metadata.sensor, events);
  });
  return result;
}

}  // namespace featsense::mapping
