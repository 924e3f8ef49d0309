#pragma once
/// POSIX file operations for crash safety; every failure throws with the path and the cause.

#include <filesystem>
#include <string>

namespace featsense::storage::detail {

/// "<what> <path>: <strerror(errno)>" as a std::runtime_error.
[[noreturn]] void throw_errno(const std::string& what, const std::filesystem::path& path);

/// fsync of a file's data and metadata.
void sync_file(const std::filesystem::path& path);
/// fsync of a directory, so that a rename or a new entry in it survives a crash.
void sync_directory(const std::filesystem::path& directory);
/// rename(2) of `from` over `to` (atomic on POSIX), then the directory synced.
void replace_file(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace featsense::storage::detail
