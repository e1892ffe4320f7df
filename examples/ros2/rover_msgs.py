"""The ROS 2 messages the examples use, declared for Cyclone DDS's Python binding.

A ROS 2 node gets these from its packages (geometry_msgs, darknet_ros_msgs); a plain
Cyclone DDS participant declares them itself, under the DDS type names rmw_cyclonedds_cpp
gives them (``geometry_msgs::msg::dds_::Twist_``), field for field as in the .msg files.
Topics are ROS names with ``rt`` in front: ``/cmd_vel`` is ``rt/cmd_vel``.
"""

from dataclasses import dataclass

import cyclonedds.idl.types as types
from cyclonedds.idl import IdlStruct


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: types.int32
    nanosec: types.uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: types.float64
    y: types.float64
    z: types.float64


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3
    angular: Vector3


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: types.float64
    y: types.float64
    z: types.float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: types.float64
    y: types.float64
    z: types.float64
    w: types.float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point
    orientation: Quaternion


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose
    covariance: types.array[types.float64, 36]


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist
    covariance: types.array[types.float64, 36]


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header
    child_frame_id: str
    pose: PoseWithCovariance
    twist: TwistWithCovariance


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3
    rotation: Quaternion


@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    header: Header
    child_frame_id: str
    transform: Transform


@dataclass
class TFMessage(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    """``/tf`` and ``/tf_static``."""

    transforms: types.sequence[TransformStamped]


@dataclass
class BoundingBox(IdlStruct, typename="darknet_ros_msgs::msg::dds_::BoundingBox_"):
    """darknet_ros's ROS 2 branch: ROS 1's ``Class`` is ``class_id``, last."""

    probability: types.float64
    xmin: types.int64
    ymin: types.int64
    xmax: types.int64
    ymax: types.int64
    id: types.int16
    class_id: str


@dataclass
class BoundingBoxes(IdlStruct, typename="darknet_ros_msgs::msg::dds_::BoundingBoxes_"):
    header: Header
    image_header: Header
    bounding_boxes: types.sequence[BoundingBox]


def topic_name(ros_name):
    """A ROS 2 topic's DDS name: ``/cmd_vel`` -> ``rt/cmd_vel``."""
    return "rt/" + ros_name.lstrip("/")
