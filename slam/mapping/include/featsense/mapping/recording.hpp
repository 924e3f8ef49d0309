#pragma once
// Recordings as a mapping run opens them: with the sensor settings of the run's configuration,
// and again from their start for a second pass or for a session of a saved map mapped again.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::mapping {

/// The reader options that `config` sets (sensor.*), with the Ouster metadata file and the
/// bag topic where given.
slam::SourceOptions source_options(const config::Config& config,
                                   const std::optional<std::string>& meta_path = std::nullopt,
                                   const std::optional<std::string>& topic = std::nullopt);

/// Opens the recording at `path` (any supported format) as `config` says; an empty path is
/// the built-in example (an OS1-128, or sensor.preset, moving through a box room). Throws
/// slam::InputError.
std::unique_ptr<slam::ScanSource> open_recording(
    const std::string& path, const config::Config& config,
    const std::optional<std::string>& meta_path = std::nullopt,
    const std::optional<std::string>& topic = std::nullopt);

/// Opens a recording again from its start (the same scans); empty where it cannot be.
using SourceReopener = std::function<std::unique_ptr<slam::ScanSource>()>;

}  // namespace featsense::mapping
