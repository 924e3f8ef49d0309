#pragma once
// A recording read back whole by the public opener, for the writers' round-trip tests.

#include <filesystem>
#include <vector>

#include "featsense/slam/io/open_scan_source.hpp"

namespace featsense::test {

struct ReadBack {
  std::vector<slam::Scan> scans;
  slam::ReadStats stats;
  slam::SourceInfo info;
};

/// Every scan of the recording at `path`, with no minimum range (the writers' scans keep
/// every return), and what the reader said of it.
inline ReadBack read_back(const std::filesystem::path& path) {
  slam::SourceOptions options;
  options.min_range_m = 0.0;
  const auto source = slam::open_scan_source(path.string(), options);
  ReadBack out;
  while (auto scan = source->next()) out.scans.push_back(std::move(*scan));
  out.stats = source->stats();
  out.info = source->info();
  return out;
}

}  // namespace featsense::test
