#include "keyframe_records.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <stdexcept>

namespace featsense::storage::detail {

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "journal payloads are little-endian");
static_assert(sizeof(TrajectoryPose) == 8 * sizeof(double), "a pose is 8 doubles");

class ByteWriter {
 public:
  template <typename T>
  void put(const T& value) {
    put_bytes(&value, sizeof(T));
  }
  void put_bytes(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const uint8_t*>(data);
    bytes_.insert(bytes_.end(), bytes, bytes + size);
  }
  void put_string(const std::string& text) {
    put(static_cast<uint32_t>(text.size()));
    put_bytes(text.data(), text.size());
  }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

/// Reads a payload front to back; every read past its end throws, naming `source`.
class ByteReader {
 public:
  ByteReader(const std::vector<uint8_t>& bytes, const std::filesystem::path& source,
             const char* what)
      : bytes_(bytes), source_(source), what_(what) {}
  template <typename T>
  T get() {
    T value{};
    get_bytes(&value, sizeof(T));
    return value;
  }
  void get_bytes(void* data, std::size_t size) {
    if (size > bytes_.size() - position_) damaged();
    if (size > 0) std::memcpy(data, bytes_.data() + position_, size);
    position_ += size;
  }
  std::string get_string() {
    const uint32_t length = get<uint32_t>();
    if (length > bytes_.size() - position_) damaged();  // before allocating
    std::string text(length, '\0');
    get_bytes(text.data(), text.size());
    return text;
  }
  void expect_end() const {
    if (position_ != bytes_.size()) damaged();
  }

 private:
  [[noreturn]] void damaged() const {
    throw std::runtime_error(std::string("damaged ") + what_ + " record in " + source_.string());
  }
  const std::vector<uint8_t>& bytes_;
  const std::filesystem::path& source_;
  const char* what_;
  std::size_t position_ = 0;
};

std::string describe(const KeyframeKey& key) {
  return "keyframe " + std::to_string(key.index) + " of session " + std::to_string(key.session);
}

bool finite_pose(const TrajectoryPose& pose) {
  for (const double v : {pose.t_s, pose.x, pose.y, pose.z, pose.qx, pose.qy, pose.qz, pose.qw})
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

void check_keyframe(const StoredKeyframe& keyframe, const std::filesystem::path& path) {
  const std::string where = describe(keyframe.key()) + " for " + path.string();
  const std::size_t cells = std::size_t{keyframe.descriptor_rows} * keyframe.descriptor_cols;
  if (keyframe.descriptor.size() != cells)
    throw std::invalid_argument(where + ": descriptor holds " +
                                std::to_string(keyframe.descriptor.size()) + " values, not " +
                                std::to_string(keyframe.descriptor_rows) + " x " +
                                std::to_string(keyframe.descriptor_cols));
  if (keyframe.cloud_cm.size() % 3 != 0)
    throw std::invalid_argument(where + ": cloud holds " +
                                std::to_string(keyframe.cloud_cm.size()) +
                                " values, not whole x y z points");
  if (keyframe.points() > UINT32_MAX)
    throw std::invalid_argument(where + ": more than 2^32 points");
  if (!finite_pose(keyframe.pose))
    throw std::invalid_argument(where + ": stamp or pose is not finite");
}

void check_sessions(const std::vector<MapSession>& sessions, const std::filesystem::path& path) {
  std::set<uint32_t> ids;
  for (const MapSession& session : sessions) {
    const std::string where = "session " + std::to_string(session.id) + " for " + path.string();
    if (!ids.insert(session.id).second)
      throw std::invalid_argument(where + ": two sessions have this id");
    if (!std::isfinite(session.first_stamp_s) || !std::isfinite(session.last_stamp_s))
      throw std::invalid_argument(where + ": a stamp is not finite");
  }
}

ChunkKey record_key_of(const KeyframeKey& key) {
  return {static_cast<int32_t>(key.session), static_cast<int32_t>(key.index), 0};
}

KeyframeKey keyframe_key_of_record(const ChunkKey& record_key) {
  return {static_cast<uint32_t>(record_key.x), static_cast<uint32_t>(record_key.y)};
}

std::vector<uint8_t> encode_keyframe(const StoredKeyframe& keyframe) {
  ByteWriter out;
  out.put(keyframe.session);
  out.put(keyframe.index);
  out.put(keyframe.pose);
  out.put(keyframe.descriptor_rows);
  out.put(keyframe.descriptor_cols);
  out.put(static_cast<uint32_t>(keyframe.points()));
  out.put_bytes(keyframe.descriptor.data(), keyframe.descriptor.size() * sizeof(float));
  out.put_bytes(keyframe.cloud_cm.data(), keyframe.points() * 3 * sizeof(int16_t));
  return out.take();
}

StoredKeyframe decode_keyframe(const std::vector<uint8_t>& payload,
                               const std::filesystem::path& source) {
  ByteReader in(payload, source, "keyframe");
  StoredKeyframe keyframe;
  keyframe.session = in.get<uint32_t>();
  keyframe.index = in.get<uint32_t>();
  keyframe.pose = in.get<TrajectoryPose>();
  keyframe.descriptor_rows = in.get<uint16_t>();
  keyframe.descriptor_cols = in.get<uint16_t>();
  const uint32_t points = in.get<uint32_t>();
  keyframe.descriptor.resize(std::size_t{keyframe.descriptor_rows} * keyframe.descriptor_cols);
  in.get_bytes(keyframe.descriptor.data(), keyframe.descriptor.size() * sizeof(float));
  // Checked against the payload's size before allocating: a damaged count must not allocate.
  if (std::size_t{points} * 3 * sizeof(int16_t) > payload.size())
    throw std::runtime_error("damaged keyframe record in " + source.string());
  keyframe.cloud_cm.resize(std::size_t{points} * 3);
  in.get_bytes(keyframe.cloud_cm.data(), keyframe.cloud_cm.size() * sizeof(int16_t));
  in.expect_end();
  return keyframe;
}

std::vector<uint8_t> encode_sessions(const std::vector<MapSession>& sessions) {
  ByteWriter out;
  out.put(static_cast<uint32_t>(sessions.size()));
  for (const MapSession& session : sessions) {
    out.put(session.id);
    out.put(session.scans);
    out.put(session.first_stamp_s);
    out.put(session.last_stamp_s);
    out.put_string(session.input);
    out.put_string(session.format);
    out.put_string(session.placement);
  }
  return out.take();
}

std::vector<MapSession> decode_sessions(const std::vector<uint8_t>& payload,
                                        const std::filesystem::path& source) {
  ByteReader in(payload, source, "sessions");
  const uint32_t count = in.get<uint32_t>();
  std::vector<MapSession> sessions;
  for (uint32_t i = 0; i < count; ++i) {
    MapSession session;
    session.id = in.get<uint32_t>();
    session.scans = in.get<uint64_t>();
    session.first_stamp_s = in.get<double>();
    session.last_stamp_s = in.get<double>();
    session.input = in.get_string();
    session.format = in.get_string();
    session.placement = in.get_string();
    sessions.push_back(std::move(session));
  }
  in.expect_end();
  return sessions;
}

std::string keyframe_name(const KeyframeKey& key) {
  return "s" + std::to_string(key.session) + "_k" + std::to_string(key.index);
}

std::optional<KeyframeKey> parse_keyframe_name(const std::string& name) {
  KeyframeKey key;
  int consumed = 0;
  if (std::sscanf(name.c_str(), "s%u_k%u%n", &key.session, &key.index, &consumed) != 2 ||
      static_cast<std::size_t>(consumed) != name.size() || keyframe_name(key) != name)
    return std::nullopt;
  return key;
}

std::string session_name(uint32_t id) { return "s" + std::to_string(id); }

}  // namespace featsense::storage::detail
