#!/usr/bin/env python3
"""The YOLO-car tutorial's listener_yolo node (part 6), ported to ROS 2's wire.

The tutorial's rospy node prints the first box's class of every darknet_ros message and,
when it is a person, publishes a Twist of 0.1 m/s forward on /cmd_vel. This port does the
same over DDS with Cyclone DDS's Python binding (``pip install cyclonedds``), no ROS 2
install needed; an rclpy version is in docs/ROS2.md. Run it beside ``rover --ros2``:

    python3 examples/ros2/listener_yolo.py          # ROS_DOMAIN_ID as rover's (0 by default)

Differences from the original, both ROS 2's: the box's class is ``class_id`` (darknet_ros's
ROS 2 messages), and the publisher is created once, before the first message, instead of in
every callback (a new publisher's first message may reach nobody).
"""

import os
import sys

from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rover_msgs import BoundingBoxes, Twist, Vector3, topic_name  # noqa: E402


def main():
    participant = DomainParticipant(int(os.environ.get("ROS_DOMAIN_ID", "0")))
    # rclpy's default QoS: reliable, keep last 10.
    qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10))
    boxes = DataReader(
        participant, Topic(participant, topic_name("/darknet_ros/bounding_boxes"), BoundingBoxes), qos=qos
    )
    cmd_vel = DataWriter(participant, Topic(participant, topic_name("/cmd_vel"), Twist), qos=qos)
    # Like rospy.spin(): until the process is stopped.
    for data in boxes.take_iter(timeout=duration(infinite=True)):
        if not data.bounding_boxes:
            continue
        print(data.bounding_boxes[0].class_id, flush=True)
        if data.bounding_boxes[0].class_id == "person":
            cmd_vel.write(Twist(linear=Vector3(0.1, 0.0, 0.0), angular=Vector3(0.0, 0.0, 0.0)))
            print("go on", flush=True)


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        pass
