#include "live_view.hpp"

#include <cmath>
#include <cstring>
#include <utility>

#include "featsense/viewer_export/viewer_mesh_binary.hpp"

namespace featsense::app {
namespace {

void append_bytes(std::string& out, const void* data, size_t bytes) {
  out.append(static_cast<const char*>(data), bytes);
}

void append_u32(std::string& out, uint32_t value) { append_bytes(out, &value, sizeof(value)); }
void append_i32(std::string& out, int32_t value) { append_bytes(out, &value, sizeof(value)); }

/// A latency for JSON: null where there is none yet.
nlohmann::json milliseconds(double ms) {
  return std::isfinite(ms) ? nlohmann::json(std::round(ms * 10.0) / 10.0) : nlohmann::json();
}

}  // namespace

LiveView::LiveView(std::string name) : name_(std::move(name)) {}

void LiveView::take(mapping::MapPreview preview) {
  // Encoded outside the lock: the page's requests are not held up by it.
  std::vector<std::pair<storage::ChunkKey, ChunkEntry>> encoded;
  encoded.reserve(preview.chunks.size());
  for (const mapping::ChunkMesh& chunk : preview.chunks) {
    ChunkEntry entry;
    entry.triangles = chunk.mesh.triangles.size();
    if (entry.triangles > 0) entry.mesh = viewer_export::encode_viewer_mesh(chunk.mesh, {});
    encoded.emplace_back(chunk.key, std::move(entry));
  }
  std::vector<float> positions;
  for (const Eigen::Isometry3d& pose : preview.new_poses.poses) {
    for (int k = 0; k < 3; ++k) positions.push_back(static_cast<float>(pose.translation()[k]));
  }
  preview.chunks.clear();
  preview.new_poses = {};

  std::lock_guard<std::mutex> lock(mutex_);
  ++version_;
  for (auto& [key, entry] : encoded) {
    ChunkEntry& kept = chunks_[key];
    triangles_ = triangles_ - kept.triangles + entry.triangles;
    chunks_with_surface_ =
        chunks_with_surface_ - (kept.triangles > 0 ? 1 : 0) + (entry.triangles > 0 ? 1 : 0);
    entry.version = version_;
    kept = std::move(entry);
  }
  path_.insert(path_.end(), positions.begin(), positions.end());
  latest_ = std::move(preview);
}

void LiveView::set_finished() {
  std::lock_guard<std::mutex> lock(mutex_);
  finished_ = true;
}

nlohmann::json LiveView::status(size_t path_from) const {
  std::lock_guard<std::mutex> lock(mutex_);
  nlohmann::json status;
  status["name"] = name_;
  status["version"] = version_;
  status["finished"] = finished_;
  status["frames_read"] = latest_.frames_read;
  status["frames_mapped"] = latest_.frames_mapped;
  status["integrations_skipped"] = latest_.integrations_skipped;
  status["pose_latency_ms"] = milliseconds(latest_.pose_latency_ms);
  status["integration_latency_ms"] = milliseconds(latest_.integration_latency_ms);
  status["meshing_ms"] = milliseconds(latest_.meshing_ms);
  status["chunks"] = chunks_with_surface_;  // those with a surface
  status["chunks_waiting"] = latest_.chunks_waiting;
  status["triangles"] = triangles_;
  if (latest_.has_latest_pose) {
    const Eigen::Vector3d p = latest_.latest_pose.translation();
    const Eigen::Vector3d forward = latest_.latest_pose.linear().col(0);
    status["pose"] = {{"position_m", {p.x(), p.y(), p.z()}},
                      {"forward", {forward.x(), forward.y(), forward.z()}},
                      {"stamp_ns", latest_.latest_stamp_ns}};
  }
  const size_t poses = path_.size() / 3;
  status["path_length"] = poses;
  nlohmann::json path = nlohmann::json::array();
  for (size_t i = std::min(path_from, poses); i < poses; ++i)
    path.push_back({path_[3 * i], path_[3 * i + 1], path_[3 * i + 2]});
  status["path_from"] = std::min(path_from, poses);
  status["path_m"] = std::move(path);
  return status;
}

std::string LiveView::changes_since(uint64_t since) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string out;
  append_bytes(out, kLiveMeshMagic, sizeof(kLiveMeshMagic));
  append_u32(out, static_cast<uint32_t>(version_));
  const size_t count_at = out.size();
  append_u32(out, 0);
  uint32_t count = 0;
  for (const auto& [key, entry] : chunks_) {
    if (entry.version <= since) continue;
    append_i32(out, key.x);
    append_i32(out, key.y);
    append_i32(out, key.z);
    append_u32(out, static_cast<uint32_t>(entry.mesh.size()));
    out += entry.mesh;
    ++count;
  }
  std::memcpy(&out[count_at], &count, sizeof(count));
  return out;
}

}  // namespace featsense::app
