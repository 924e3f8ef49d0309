#pragma once
/// One .db3 file of a ROS 2 bag (rosbag2's sqlite3 storage): the tables `topics` (id, name,
/// type, serialization_format, offered_qos_profiles) and `messages` (id, topic_id,
/// timestamp in ns, data), read through libsqlite3, read-only.

#include <memory>
#include <string>

#include "rosbag/message_log.hpp"

namespace featsense::slam {

/// Opens `path` and reads its topics and message counts. Throws InputError naming the file
/// where it is no SQLite database, lacks the tables, or is damaged where the topics are.
std::unique_ptr<MessageLog> open_sqlite_bag_file(const std::string& path);

}  // namespace featsense::slam
