#pragma once
/// sensor_msgs/Imu in either encoding (ROS 1 or CDR): the header's stamp, the angular velocity
/// and the linear acceleration; the orientation and the covariances are skipped.

#include <Eigen/Core>

#include <memory>

#include "featsense/slam/imu_sample.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_scan_decoder.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// The sample of one sensor_msgs/Imu in the message's own frame, stamped with its header's
/// stamp. Throws SerializationError.
ImuSample imu_message(ByteView message, MessageEncoding encoding);

/// The decoder of a sensor_msgs/Imu topic: each sample turned into the sensor frame by
/// `imu_to_sensor`.
std::unique_ptr<ImuMessageDecoder> make_imu_message_decoder(MessageEncoding encoding,
                                                            const Eigen::Matrix3d& imu_to_sensor);

}  // namespace featsense::slam
