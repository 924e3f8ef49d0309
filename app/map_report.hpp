#pragma once
// report.json of `featsense map` and `featsense demo` (keys in DESIGN.md, "Names that
// scripts rely on"): what went in, what came out, how long each stage took.

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "map_pipeline.hpp"

namespace featsense::app {

struct MapRunSummary {
  const config::Config* config = nullptr;
  const slam::SourceInfo* input = nullptr;
  std::string backend;         ///< "cuda" or "cpu"
  std::string backend_reason;  ///< why that backend
  std::string poses;           ///< where the poses came from
  const PipelineResult* pipeline = nullptr;
  storage::ShiftingMapStats map;
  size_t map_chunks = 0;        ///< chunks in the store at the end
  size_t continued_chunks = 0;  ///< chunks of the map that was continued
  size_t device_memory_bytes = 0;
  std::vector<double> final_flush_ms;
};

/// The report; `eval` and `mesh` sections are added by the caller when there are some.
nlohmann::json map_report_json(const MapRunSummary& summary);

/// Peak resident memory of this process so far, MB.
double peak_rss_mb();

}  // namespace featsense::app
