#pragma once
/// An MCAP file as a message log: channels grouped by topic, their schema's name as the
/// type, messages in file order. The topics and counts come from the summary section where
/// the file has one with statistics, else from a scan of the whole file (a recording that was
/// cut off before its summary).

#include <memory>
#include <string>

#include "rosbag/message_log.hpp"

namespace featsense::slam {

/// Throws InputError where `path` is no MCAP file. Damage met while cataloguing becomes the
/// catalog's warnings.
std::unique_ptr<MessageLog> open_mcap_file(const std::string& path);

}  // namespace featsense::slam
