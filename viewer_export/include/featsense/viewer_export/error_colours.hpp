#pragma once
/// Colours for a mesh's signed distance to its reference (mesh_error.glb, mesh_error.png):
/// a diverging map, white on the reference, red in front of it, blue behind it.
///
/// Linear in each half and saturated at a fixed distance rather than at the mesh's own
/// extremes, so that the same colour means the same error in every map: 10 cm is about a voxel
/// and a half at the default 6.4 cm, the largest completeness threshold of the evaluation.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

#include "featsense/viewer_export/plan_view.hpp"

namespace featsense::viewer_export {

/// The distance (metres) at and beyond which the colour is pure red or pure blue.
inline constexpr float kErrorSaturationM = 0.10f;

/// The colour of a signed distance (metres, positive in front of the reference): white at 0,
/// (255, 0, 0) at +saturation and beyond, (0, 0, 255) at -saturation and beyond. A distance that
/// is not a number (a vertex the comparison did not reach) is mid grey, which the map never
/// gives otherwise.
std::array<uint8_t, 3> signed_distance_colour(float signed_distance_m,
                                              float saturation_m = kErrorSaturationM);

/// signed_distance_colour for each value, in the form MeshAttributes::colors takes.
std::vector<Eigen::Matrix<uint8_t, 3, 1>> signed_distance_colours(
    const std::vector<float>& signed_distance_m, float saturation_m = kErrorSaturationM);

/// The plan view's colours for these distances (mesh_error.png), with the legend's ramp from
/// -saturation (blue, behind) to +saturation (red, in front).
PlanVertexColours signed_distance_plan_colours(const std::vector<float>& signed_distance_m,
                                               float saturation_m = kErrorSaturationM);

}  // namespace featsense::viewer_export
