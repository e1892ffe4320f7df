#!/usr/bin/env python3
"""A real rclpy node (rmw_fastrtps_cpp) that checks `rover --ros2` as ROS 2's own tools would.

    python3 peer.py CHECK...     (CHECK: graph, params, parameter_events, topics, trajectory,
                                  arm_car_trajectory, gripper, camera_rate, publish_images)

Run by app/tests/rclpy.rs with a distribution's venv and the interface packages set-up built
(scripts/ros2/peers.py). The checks run in order, one node; their findings are printed as one
JSON object on the last line, and the Rust test asserts on it. Nothing here decides pass or
fail.
"""

import json
import math
import sys
import time

import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data


def spin_until(node, future, timeout_s):
    rclpy.spin_until_future_complete(node, future, timeout_sec=timeout_s)
    return future.result() if future.done() else None


def spin_for(node, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.02)


def graph(node):
    names = []
    end = time.monotonic() + 20
    while time.monotonic() < end:
        names = node.get_node_names_and_namespaces()
        if ("rover", "/") in names:
            break
        spin_for(node, 0.2)
    topics = dict(node.get_topic_names_and_types())
    return {"nodes": [list(n) for n in names], "topics": {k: v for k, v in topics.items()}}


def params(node):
    client = AsyncParameterClient(node, "rover")
    out = {"ready": client.wait_for_services(timeout_sec=20.0)}
    listed = spin_until(node, client.list_parameters(), 10)
    out["list"] = sorted(listed.result.names) if listed else None
    got = spin_until(node, client.get_parameters(["use_sim_time"]), 10)
    if got:
        out["use_sim_time"] = [got.values[0].type, got.values[0].bool_value]
    # The URDF: larger than one RTPS DATA (rover sends it in its own datagrams); compared
    # with /robot_description (transient local, through RustDDS's writer).
    from std_msgs.msg import String
    published = []
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(String, "/robot_description",
                             lambda m: published.append(m.data), latched)
    got = spin_until(node, client.get_parameters(["robot_description"]), 10)
    end = time.monotonic() + 10
    while time.monotonic() < end and not published:
        rclpy.spin_once(node, timeout_sec=0.1)
    if got:
        value = got.values[0]
        out["robot_description"] = [value.type, len(value.string_value),
                                    value.string_value.lstrip()[:60]]
        out["robot_description_is_the_topics"] = bool(published) and \
            value.string_value == published[0]
    types = spin_until(node, client.get_parameter_types(["use_sim_time", "robot_description"]), 10)
    out["types"] = list(types.types) if types else None
    described = spin_until(node, client.describe_parameters(["use_sim_time"]), 10)
    if described:
        d = described.descriptors[0]
        out["describe"] = {"name": d.name, "type": d.type, "read_only": d.read_only,
                           "description": d.description}
    set_ = spin_until(node, client.set_parameters([Parameter("use_sim_time", value=False)]), 10)
    if set_:
        r = set_.results[0]
        out["set"] = {"successful": r.successful, "reason": r.reason}
    return out


def parameter_events(node):
    """Listens on /parameter_events (started before rover) for rover's declaration."""
    from rcl_interfaces.msg import ParameterEvent

    events = []
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(ParameterEvent, "/parameter_events",
                             lambda e: events.append(e) if e.node == "/rover" else None, qos)
    end = time.monotonic() + 30
    while time.monotonic() < end and not events:
        rclpy.spin_once(node, timeout_sec=0.1)
    spin_for(node, 2.0)  # no second declaration to this node
    return {"events": [{"node": e.node,
                        "new": sorted((p.name, p.value.type) for p in e.new_parameters),
                        "changed": len(e.changed_parameters),
                        "deleted": len(e.deleted_parameters)} for e in events]}


def topics(node):
    """Each topic of docs/ROS2.md's table, subscribed with its real type and QoS."""
    from darknet_ros_msgs.msg import BoundingBoxes, ObjectCount
    from gazebo_msgs.msg import ContactsState, ModelStates
    from nav_msgs.msg import Odometry
    from rcl_interfaces.msg import Log
    from rosgraph_msgs.msg import Clock
    from geometry_msgs.msg import Vector3Stamped
    from sensor_msgs.msg import CameraInfo, Image, Imu, JointState, LaserScan, NavSatFix
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    rosout = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.TRANSIENT_LOCAL)
    table = [
        ("/clock", Clock, reliable, "reliable"),
        ("/odom", Odometry, reliable, "reliable"),
        ("/tf", TFMessage, reliable, "reliable"),
        ("/tf_static", TFMessage, latched, "reliable, transient local"),
        ("/robot_description", String, latched, "reliable, transient local"),
        ("/joint_states", JointState, reliable, "reliable"),
        ("/camera/image_raw", Image, qos_profile_sensor_data, "best effort"),
        ("/camera/camera_info", CameraInfo, qos_profile_sensor_data, "best effort"),
        ("/darknet_ros/bounding_boxes", BoundingBoxes, reliable, "reliable"),
        ("/darknet_ros/found_object", ObjectCount, reliable, "reliable"),
        ("/darknet_ros/detection_image", Image, latched, "reliable, transient local"),
        ("/gazebo/model_states", ModelStates, reliable, "reliable"),
        ("/rover/status", String, reliable, "reliable"),
        ("/scan", LaserScan, qos_profile_sensor_data, "best effort"),
        ("/imu", Imu, qos_profile_sensor_data, "best effort"),
        ("/ground_truth/state", Odometry, reliable, "reliable"),
        ("/fix", NavSatFix, qos_profile_sensor_data, "best effort"),
        ("/fix_velocity", Vector3Stamped, qos_profile_sensor_data, "best effort"),
        ("/bumper_states", ContactsState, reliable, "reliable"),
        ("/rosout", Log, rosout, "reliable, transient local"),
    ]
    counts, last, rover_log = {}, {}, []

    def keep(name):
        def callback(message):
            if name == "/rosout":
                if message.name != "rover":
                    return  # other nodes' lines (this one's)
                rover_log.append([message.level, message.msg, message.file, message.line])
            counts[name] = counts.get(name, 0) + 1
            last[name] = message
        return callback

    for name, kind, qos, _ in table:
        node.create_subscription(kind, name, keep(name), qos)
    spin_for(node, 10.0)
    # The counts are the 10 s window's. A topic silent in it gets 10 s more to show it reaches
    # this subscription at all: a reliable 900 kB detection image, deserialized here beside 13
    # other subscriptions, comes at 0.5 Hz on 2 busy cores and may miss the window.
    window = dict(counts)
    end = time.monotonic() + 10.0
    while time.monotonic() < end and any(counts.get(n, 0) == 0 for n, *_ in table):
        rclpy.spin_once(node, timeout_sec=0.02)
    sample = {}
    if "/odom" in last:
        o = last["/odom"]
        sample["/odom"] = [o.header.frame_id, o.child_frame_id]
    if "/camera/image_raw" in last:
        i = last["/camera/image_raw"]
        sample["/camera/image_raw"] = [i.width, i.height, i.encoding, len(i.data)]
    if "/darknet_ros/bounding_boxes" in last:
        b = last["/darknet_ros/bounding_boxes"].bounding_boxes
        sample["/darknet_ros/bounding_boxes"] = [x.class_id for x in b]
    if "/gazebo/model_states" in last:
        sample["/gazebo/model_states"] = list(last["/gazebo/model_states"].name)
    if "/tf_static" in last:
        sample["/tf_static"] = len(last["/tf_static"].transforms)
    if "/scan" in last:
        sample["/scan"] = len(last["/scan"].ranges)
    if "/ground_truth/state" in last:
        m = last["/ground_truth/state"]
        sample["/ground_truth/state"] = [m.header.frame_id, m.child_frame_id,
                                         m.pose.pose.position.z]
    if "/fix" in last:
        m = last["/fix"]
        sample["/fix"] = [m.header.frame_id, m.latitude, m.longitude, m.status.service,
                          m.position_covariance_type]
    if "/bumper_states" in last:
        m = last["/bumper_states"]
        sample["/bumper_states"] = [m.header.frame_id, len(m.states)]
    if "/imu" in last:
        m = last["/imu"]
        sample["/imu"] = [m.header.frame_id, m.linear_acceleration.z, m.orientation.w]
    sample["/rosout"] = rover_log[:20]
    return {"table": [[n, k.__module__.split(".")[0] + "/msg/" + k.__name__, q,
                       window.get(n, 0), counts.get(n, 0) > 0]
                      for n, k, _, q in table], "sample": sample}


def _joints(node):
    from sensor_msgs.msg import JointState
    latest = {}

    def callback(message):
        latest.update(zip(message.name, message.position))

    node.create_subscription(JointState, "/joint_states", callback, 10)
    return latest


def _trajectory(node, action, names, to_goal, cancelled):
    """FollowJointTrajectory on `action` over the joints `names`: `to_goal` (points: positions
    and whole seconds from the start) to its end, an unknown joint, and `cancelled` cancelled
    1 s in."""
    from builtin_interfaces.msg import Duration
    from control_msgs.action import FollowJointTrajectory
    from trajectory_msgs.msg import JointTrajectoryPoint

    joints = _joints(node)
    client = ActionClient(node, FollowJointTrajectory, action)
    out = {"server": client.wait_for_server(timeout_sec=20.0)}

    def goal(points, joint_names=names):
        g = FollowJointTrajectory.Goal()
        g.trajectory.joint_names = joint_names
        for q, t in points:
            p = JointTrajectoryPoint()
            p.positions = q
            p.time_from_start = Duration(sec=t)
            g.trajectory.points.append(p)
        return g

    def run(label, g, cancel_after_s=None):
        feedback = []
        handle = spin_until(node, client.send_goal_async(g, feedback_callback=feedback.append), 10)
        entry = {"accepted": bool(handle and handle.accepted)}
        out[label] = entry
        if not entry["accepted"]:
            return
        result_future = handle.get_result_async()
        if cancel_after_s is not None:
            spin_for(node, cancel_after_s)
            cancelled = spin_until(node, handle.cancel_goal_async(), 5)
            entry["cancel_return_code"] = cancelled.return_code if cancelled else None
            entry["at_cancel"] = [joints.get(n, math.nan) for n in names]
        result = spin_until(node, result_future, 15)
        if result:
            entry["status"] = result.status
            entry["error_code"] = result.result.error_code
            entry["error_string"] = result.result.error_string
        entry["feedback"] = len(feedback)
        if feedback:
            f = feedback[len(feedback) // 2].feedback
            entry["feedback_names"] = list(f.joint_names)
        entry["at_end"] = [joints.get(n, math.nan) for n in names]
        if cancel_after_s is not None:
            spin_for(node, 2.0)
            entry["after_cancel"] = [joints.get(n, math.nan) for n in names]

    run("to_goal", goal(to_goal))
    run("unknown_joint", goal([([0.1], 2)], joint_names=["no_such_joint"]))
    run("cancelled", goal(cancelled), cancel_after_s=1.0)
    out["final"] = [joints.get(n, math.nan) for n in names]
    return out


def trajectory(node):
    """FollowJointTrajectory on TIAGo's arm (assets/controllers/tiago_no_hand.yaml)."""
    return _trajectory(node, "/arm_controller/follow_joint_trajectory",
                       ["arm_%d_joint" % i for i in range(1, 8)],
                       [([0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0], 2),
                        ([0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0], 4)],
                       [([1.2, -0.5, -0.2, 1.0, -1.0, 0.5, 0.0], 6)])


def arm_car_trajectory(node):
    """FollowJointTrajectory on the arm car's arm, under /arm
    (assets/controllers/my_robot_arm_trajectory.yaml)."""
    return _trajectory(node, "/arm/arm_controller/follow_joint_trajectory",
                       ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                        "wrist_pitch_joint", "wrist_roll_joint"],
                       [([0.3, 0.4, 0.5, 0.2, 0.0], 2), ([0.0, 0.7, 0.9, 0.4, 0.0], 4)],
                       [([0.8, 0.2, 0.3, 0.0, 0.5], 5)])


def gripper(node):
    """GripperCommand on the test grasper: close on the ball, then open."""
    from control_msgs.action import GripperCommand

    client = ActionClient(node, GripperCommand, "/gripper_controller/gripper_cmd")
    out = {"server": client.wait_for_server(timeout_sec=20.0)}
    for label, position, effort in [("close", 0.05, 5.0), ("open", 0.0, 0.0)]:
        g = GripperCommand.Goal()
        g.command.position, g.command.max_effort = position, effort
        feedback = []
        handle = spin_until(node, client.send_goal_async(g, feedback_callback=feedback.append), 10)
        entry = {"accepted": bool(handle and handle.accepted)}
        out[label] = entry
        if entry["accepted"]:
            result = spin_until(node, handle.get_result_async(), 15)
            if result:
                r = result.result
                entry.update(status=result.status, position=r.position, effort=r.effort,
                             stalled=r.stalled, reached_goal=r.reached_goal)
            entry["feedback"] = len(feedback)
    return out


def camera_rate(node):
    """Best-effort images counted side by side for 10 s, raw (no Python deserialization):
    rover's camera and an rclpy publisher's identical images (`publish_images`), both 30 Hz
    on their stamps. Besides the counts, what each stream's stamps say was sent from its first
    received to its last, and the share delivered: the images received over those (a publisher that
    sends fewer, on a loaded machine, is not counted against its transport)."""
    import struct
    from sensor_msgs.msg import Image

    stamps = {"/camera/image_raw": [], "/peer/image_raw": []}

    def keep(name):
        def callback(raw):
            # The CDR encapsulation (4 bytes), then the header's stamp: sec, nanosec.
            sec, nanosec = struct.unpack_from("<iI", raw, 4)
            stamps[name].append(sec + nanosec * 1e-9)
        return callback

    for name in stamps:
        node.create_subscription(Image, name, keep(name), qos_profile_sensor_data, raw=True)
    spin_for(node, 2.0)  # discovery
    for name in stamps:
        stamps[name].clear()
    spin_for(node, 10.0)

    def sent(ts, rate_hz=30.0):
        ts = sorted(set(ts))
        return round((ts[-1] - ts[0]) * rate_hz) + 1 if ts else 0

    def delivered(ts):
        return len(set(ts)) / sent(ts) if len(set(ts)) >= 2 else 0.0

    return {"counts": {name: len(ts) for name, ts in stamps.items()},
            "sent": {name: sent(ts) for name, ts in stamps.items()},
            "delivered": {name: delivered(ts) for name, ts in stamps.items()}}


def publish_images(node):
    """640x480 rgb8 images, as rover's camera sends them, at 30 Hz for 40 s on /peer/image_raw
    (best effort, SensorDataQoS)."""
    from sensor_msgs.msg import Image

    publisher = node.create_publisher(Image, "/peer/image_raw", qos_profile_sensor_data)
    image = Image()
    image.header.frame_id = "camera_link_optical"
    image.width, image.height, image.encoding, image.step = 640, 480, "rgb8", 640 * 3
    image.data = bytes(640 * 480 * 3)
    sent, start = 0, time.monotonic()
    while time.monotonic() - start < 40.0:
        # Stamped by its number at 30 Hz, so the subscriber can tell what it missed.
        image.header.stamp.sec, image.header.stamp.nanosec = sent // 30, (sent % 30) * 33333333
        publisher.publish(image)
        sent += 1
        next_at = start + sent / 30.0
        while time.monotonic() < next_at:
            rclpy.spin_once(node, timeout_sec=max(0.0, next_at - time.monotonic()))
    return {"sent": sent}


def cloud(node):
    """/velodyne_points from the VLP-16 car: its fields, shape and rings, read from the bytes."""
    import math
    import struct
    from sensor_msgs.msg import PointCloud2
    got = []
    node.create_subscription(PointCloud2, "/velodyne_points", got.append,
                             qos_profile_sensor_data)
    spin_for(node, 5.0)
    if not got:
        return {"clouds": 0}
    m = got[-1]
    rings, ranges = set(), []
    for i in range(0, m.width * m.height):
        x, y, z = struct.unpack_from("<fff", m.data, i * m.point_step)
        rings.add(struct.unpack_from("<H", m.data, i * m.point_step + 20)[0])
        ranges.append(math.sqrt(x * x + y * y + z * z))
    return {"clouds": len(got), "frame": m.header.frame_id,
            "fields": [[f.name, f.offset, f.datatype, f.count] for f in m.fields],
            "shape": [m.height, m.width, m.point_step, m.row_step, m.is_dense,
                      m.is_bigendian],
            "rings": len(rings), "range": [min(ranges), max(ranges)]}


def main():
    rclpy.init()
    node = Node("rover_test_peer")
    from rclpy.utilities import get_rmw_implementation_identifier
    out = {"rmw": get_rmw_implementation_identifier()}
    checks = {"graph": graph, "params": params, "parameter_events": parameter_events,
              "topics": topics, "trajectory": trajectory,
              "arm_car_trajectory": arm_car_trajectory, "gripper": gripper,
              "camera_rate": camera_rate, "publish_images": publish_images,
              "cloud": cloud}
    for check in sys.argv[1:]:
        out[check] = checks[check](node)
    print(json.dumps(out), flush=True)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
