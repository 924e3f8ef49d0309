#pragma once
/// imu.csv: the IMU's samples of a folder of scans written by `featsense simulate`
/// (slam/io/src/cloud/SEQUENCE_FORMAT.md): a header line `stamp_ns,ax,ay,az,gx,gy,gz`, then
/// one sample per line: stamp in ns (the frames' clock), specific force in m/s^2, angular
/// velocity in rad/s, both in the sensor frame.

#include <string>
#include <vector>

#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam {

inline constexpr const char* kImuCsvHeader = "stamp_ns,ax,ay,az,gx,gy,gz";

/// Appends one sample's line (with its newline) to `out`; round-trips doubles exactly.
void append_imu_csv_line(const ImuSample& sample, std::string* out);

/// The samples of imu.csv text. A wrong header is an InputError naming `origin`; a line that
/// does not hold a stamp and six finite numbers is skipped and described in `skipped` (one
/// entry per line, at most the first few, `skipped_count` counts them all).
std::vector<ImuSample> parse_imu_csv(const std::string& text, const std::string& origin,
                                     std::vector<std::string>* skipped, size_t* skipped_count);

}  // namespace featsense::slam
