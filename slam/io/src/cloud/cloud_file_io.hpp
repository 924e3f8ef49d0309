#pragma once
// Reading one scan file into a Scan: the steps the single-file and folder sources share.

#include <filesystem>
#include <string>
#include <vector>

#include "featsense/slam/io/cloud_files.hpp"

namespace featsense::slam::cloud {

enum class CloudFormat { kPcd, kPly, kKittiBin };

/// The whole file; throws InputError when it cannot be read.
std::string read_file_bytes(const std::filesystem::path& path);

/// The file decoded by its format; throws InputError.
DecodedCloud decode_cloud_file(const std::filesystem::path& path, CloudFormat format);

/// One line for the counts organize() or the organized path produced, and a warning for
/// each count that suggests a wrong sensor model.
std::string describe(const OrganizeStats& stats, std::vector<std::string>* warnings,
                     const std::string& origin);

}  // namespace featsense::slam::cloud
