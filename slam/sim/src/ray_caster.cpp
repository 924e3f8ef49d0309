// The only file that speaks Embree.
#include "featsense/slam/sim/ray_caster.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include <stdexcept>
#include <string>

namespace featsense::slam {

struct RayCaster::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Eigen::Vector3f> normals;  ///< unit, one per triangle

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

RayCaster::RayCaster(const mesh::TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr)
    throw std::runtime_error("ray tracer: cannot create an Embree device (error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust traversal: rays that graze shared edges of the welded walls must not slip through.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.vertices.size()));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), mesh.triangles.size()));
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    throw std::runtime_error("ray tracer: out of memory for the mesh");
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) vertices[3 * i + static_cast<size_t>(k)] = mesh.vertices[i][k];
  }
  impl_->normals.resize(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Eigen::Vector3i& t = mesh.triangles[i];
    for (int k = 0; k < 3; ++k)
      indices[3 * i + static_cast<size_t>(k)] = static_cast<unsigned>(t[k]);
    const Eigen::Vector3f n =
        (mesh.vertices[static_cast<size_t>(t[1])] - mesh.vertices[static_cast<size_t>(t[0])])
            .cross(mesh.vertices[static_cast<size_t>(t[2])] -
                   mesh.vertices[static_cast<size_t>(t[0])]);
    impl_->normals[i] = n.norm() > 0.0f ? n.normalized() : Eigen::Vector3f::UnitZ();
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl_->scene);
  if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE)
    throw std::runtime_error("ray tracer: building the scene failed");
}

RayCaster::~RayCaster() = default;

RayHit RayCaster::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = ray.origin.x();
  rh.ray.org_y = ray.origin.y();
  rh.ray.org_z = ray.origin.z();
  rh.ray.dir_x = ray.direction.x();
  rh.ray.dir_y = ray.direction.y();
  rh.ray.dir_z = ray.direction.z();
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = ray.max_distance_m;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  RayHit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.distance_m = rh.ray.tfar;
  hit.triangle = static_cast<int32_t>(rh.hit.primID);
  const Eigen::Vector3f& n = impl_->normals[rh.hit.primID];
  hit.normal = n.dot(ray.direction) > 0.0f ? Eigen::Vector3f(-n) : n;
  return hit;
}

void RayCaster::intersect(const std::vector<Ray>& rays, std::vector<RayHit>* hits) const {
  hits->resize(rays.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i)
                        (*hits)[i] = intersect(rays[i]);
                    });
}

}  // namespace featsense::slam
