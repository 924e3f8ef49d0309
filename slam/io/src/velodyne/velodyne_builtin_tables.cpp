// The built-in laser tables: each laser's vertical angle and azimuth offset in degrees, in
// the order of the lasers in a packet. The values are those of the makers' user manuals
// (laser tables of the VLP-16, VLP-32C, HDL-32E and VLS-128), as also listed in radians by
// the calibration files of tier4/nebula (Apache-2.0) that the tests use; the azimuth column
// is nebula's rot_correction, which is the manual's offset with the opposite sign.

#include <cmath>

#include "featsense/slam/scan_source.hpp"
#include "velodyne/velodyne_calibration.hpp"

namespace featsense::slam {
namespace {

struct BuiltinLaser {
  double vert_deg;
  double rot_deg;
};

/// VLP-16, laser by laser (its number in the packet).
constexpr BuiltinLaser kVlp16[] = {
    {-15.0, 0.0}, {1.0, 0.0},  {-13.0, 0.0}, {3.0, 0.0},  {-11.0, 0.0}, {5.0, 0.0},
    {-9.0, 0.0},  {7.0, 0.0},  {-7.0, 0.0},  {9.0, 0.0},  {-5.0, 0.0},  {11.0, 0.0},
    {-3.0, 0.0},  {13.0, 0.0}, {-1.0, 0.0},  {15.0, 0.0},
};

/// VLP-32C, laser by laser (its number in the packet).
constexpr BuiltinLaser kVlp32c[] = {
    {-25.0, -1.4},  {-1.0, 4.2},   {-1.667, -1.4}, {-15.639, 1.4}, {-11.31, -1.4}, {0.0, 1.4},
    {-0.667, -4.2}, {-8.843, 1.4}, {-7.254, -1.4}, {0.333, 4.2},   {-0.333, -1.4}, {-6.148, 1.4},
    {-5.333, -4.2}, {1.333, 1.4},  {0.667, -4.2},  {-4.0, 1.4},    {-4.667, -1.4}, {1.667, 4.2},
    {1.0, -1.4},    {-3.667, 4.2}, {-3.333, -4.2}, {3.333, 1.4},   {2.333, -1.4},  {-2.667, 1.4},
    {-3.0, -1.4},   {7.0, 1.4},    {4.667, -1.4},  {-2.333, 4.2},  {-2.0, -4.2},   {15.0, 1.4},
    {10.333, -1.4}, {-1.333, 1.4},
};

/// HDL-32E, laser by laser (its number in the packet).
constexpr BuiltinLaser kHdl32e[] = {
    {-30.67, 0.0}, {-9.33, 0.0}, {-29.33, 0.0}, {-8.0, 0.0}, {-28.0, 0.0}, {-6.67, 0.0},
    {-26.67, 0.0}, {-5.33, 0.0}, {-25.33, 0.0}, {-4.0, 0.0}, {-24.0, 0.0}, {-2.67, 0.0},
    {-22.67, 0.0}, {-1.33, 0.0}, {-21.33, 0.0}, {0.0, 0.0},  {-20.0, 0.0}, {1.33, 0.0},
    {-18.67, 0.0}, {2.67, 0.0},  {-17.33, 0.0}, {4.0, 0.0},  {-16.0, 0.0}, {5.33, 0.0},
    {-14.67, 0.0}, {6.67, 0.0},  {-13.33, 0.0}, {8.0, 0.0},  {-12.0, 0.0}, {9.33, 0.0},
    {-10.67, 0.0}, {10.67, 0.0},
};

/// VLS-128, laser by laser (its number in the packet).
constexpr BuiltinLaser kVls128[] = {
    {-11.742, -6.354}, {-1.99, -4.548}, {3.4, -2.732},     {-5.29, -0.911},  {-0.78, 0.911},
    {4.61, 2.732},     {-4.08, 4.548},  {1.31, 6.354},     {-6.5, -6.354},   {-1.11, -4.548},
    {4.28, -2.732},    {-4.41, -0.911}, {0.1, 0.911},      {6.48, 2.732},    {-3.2, 4.548},
    {2.19, 6.354},     {-3.86, -6.354}, {1.53, -4.548},    {-9.244, -2.732}, {-1.77, -0.911},
    {2.74, 0.911},     {-5.95, 2.732},  {-0.56, 4.548},    {4.83, 6.354},    {-2.98, -6.354},
    {2.41, -4.548},    {-6.28, -2.732}, {-0.89, -0.911},   {3.62, 0.911},    {-5.07, 2.732},
    {0.32, 4.548},     {7.58, 6.354},   {-0.34, -6.354},   {5.18, -4.548},   {-3.64, -2.732},
    {1.75, -0.911},    {-25.0, 0.911},  {-2.43, 2.732},    {2.96, 4.548},    {-5.73, 6.354},
    {0.54, -6.354},    {9.7, -4.548},   {-2.76, -2.732},   {2.63, -0.911},   {-7.65, 0.911},
    {-1.55, 2.732},    {3.84, 4.548},   {-4.85, 6.354},    {3.18, -6.354},   {-5.51, -4.548},
    {-0.12, -2.732},   {5.73, -0.911},  {-4.3, 0.911},     {1.09, 2.732},    {-16.042, 4.548},
    {-2.21, 6.354},    {4.06, -6.354},  {-4.63, -4.548},   {0.76, -2.732},   {15.0, -0.911},
    {-3.42, 0.911},    {1.97, 2.732},   {-6.85, 4.548},    {-1.33, 6.354},   {-5.62, -6.354},
    {-0.23, -4.548},   {5.43, -2.732},  {-3.53, -0.911},   {0.98, 0.911},    {-19.582, 2.732},
    {-2.32, 4.548},    {3.07, 6.354},   {-4.74, -6.354},   {0.65, -4.548},   {11.75, -2.732},
    {-2.65, -0.911},   {1.86, 0.911},   {-7.15, 2.732},    {-1.44, 4.548},   {3.95, 6.354},
    {-2.1, -6.354},    {3.29, -4.548},  {-5.4, -2.732},    {-0.01, -0.911},  {4.5, 0.911},
    {-4.19, 2.732},    {1.2, 4.548},    {-13.565, 6.354},  {-1.22, -6.354},  {4.17, -4.548},
    {-4.52, -2.732},   {0.87, -0.911},  {6.08, 0.911},     {-3.31, 2.732},   {2.08, 4.548},
    {-6.65, 6.354},    {1.42, -6.354},  {-10.346, -4.548}, {-1.88, -2.732},  {3.51, -0.911},
    {-6.06, 0.911},    {-0.67, 2.732},  {4.72, 4.548},     {-3.97, 6.354},   {2.3, -6.354},
    {-6.39, -4.548},   {-1.0, -2.732},  {4.39, -0.911},    {-5.18, 0.911},   {0.21, 2.732},
    {6.98, 4.548},     {-3.09, 6.354},  {4.98, -6.354},    {-3.75, -4.548},  {1.64, -2.732},
    {-8.352, -0.911},  {-2.54, 0.911},  {2.85, 2.732},     {-5.84, 4.548},   {-0.45, 6.354},
    {8.43, -6.354},    {-2.87, -4.548}, {2.52, -2.732},    {-6.17, -0.911},  {-1.66, 0.911},
    {3.73, 2.732},     {-4.96, 4.548},  {0.43, 6.354},
};
template <size_t N>
VelodyneCalibration from_table(const BuiltinLaser (&table)[N], VelodyneModel model) {
  VelodyneCalibration calibration;
  calibration.origin = "built-in " + velodyne_name(model) + " table";
  for (const BuiltinLaser& laser : table) {
    VelodyneLaser out;
    out.vert_rad = laser.vert_deg * M_PI / 180.0;
    out.rot_rad = laser.rot_deg * M_PI / 180.0;
    calibration.lasers.push_back(out);
  }
  return calibration;
}

}  // namespace

VelodyneCalibration builtin_velodyne_calibration(VelodyneModel model) {
  switch (model) {
    case VelodyneModel::kVlp16:
      return from_table(kVlp16, model);
    case VelodyneModel::kVlp32c:
      return from_table(kVlp32c, model);
    case VelodyneModel::kHdl32e:
      return from_table(kHdl32e, model);
    case VelodyneModel::kVls128:
      return from_table(kVls128, model);
    case VelodyneModel::kHdl64e:
      break;
  }
  throw InputError(
      "the HDL-64E has no built-in laser table: each unit is calibrated at the factory; set "
      "sensor.calibration to its calibration YAML");
}

}  // namespace featsense::slam
