#pragma once
/// The map refinement as a stage of the pipeline: placed scans in, final placements out, in
/// the same order, a stretch (refine.distance) at a time. The clouds the refinement needs are
/// made as their scans come (refinement_cloud); the motion over the scan (column_T_map_sensor)
/// moves with its pose. The first scan, placed before any motion was known, is held until the
/// second gives the motion, then deskewed with it, for the map and for the refinement's first
/// target. Not thread-safe: one caller, scans in order.

#include <optional>
#include <vector>

#include "featsense/slam/refine/segment_refiner.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"

namespace featsense::slam::refine {

class PlacementRefiner {
 public:
  explicit PlacementRefiner(const RefineSettings& settings);

  /// Takes the next placed scan (the scan is read, not kept) and gives the placements that
  /// became final with it, oldest first: none while a stretch fills. `without_cloud`: the
  /// caller is behind (a live sensor), so no cloud is made for the scan; a stretch without
  /// clouds passes with the last stretch's correction instead of a registration.
  std::vector<ScanPlacement> add(const Scan& scan, ScanPlacement placement,
                                 bool without_cloud = false);

  /// The placements still held, refined as a last, shorter stretch.
  std::vector<ScanPlacement> finish();

  size_t held() const { return placements_.size(); }
  const RefineCounts& counts() const { return refiner_.counts(); }
  /// Per cloud made: milliseconds.
  const std::vector<double>& cloud_ms() const { return cloud_ms_; }
  /// Clouds the refinement would have made but was told to go without.
  size_t clouds_skipped() const { return clouds_skipped_; }

 private:
  void hold(const Scan& scan, ScanPlacement placement, bool without_cloud,
            std::vector<ScanPlacement>& out);
  void release(std::vector<ScanPlacement>& out);

  RefineSettings settings_;
  SegmentRefiner refiner_;
  std::vector<ScanPlacement> placements_;  ///< held, in the refiner's order
  /// The first scan while its motion is unknown.
  std::optional<Scan> first_scan_;
  std::optional<ScanPlacement> first_placement_;
  bool started_ = false;
  std::vector<double> cloud_ms_;
  size_t clouds_skipped_ = 0;
};

}  // namespace featsense::slam::refine
