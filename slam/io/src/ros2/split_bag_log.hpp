#pragma once
/// A bag split over several files (rosbag2 starts a new file at a size or duration limit):
/// one message log whose topics are those of all files and whose messages come file by
/// file, in the order given.

#include <memory>
#include <vector>

#include "rosbag/message_log.hpp"

namespace featsense::slam {

/// `files` in recording order; at least one.
std::unique_ptr<MessageLog> join_bag_files(std::vector<std::unique_ptr<MessageLog>> files);

}  // namespace featsense::slam
