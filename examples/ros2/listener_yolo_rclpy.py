#!/usr/bin/env python3
"""The YOLO-car tutorial's listener_yolo node (part 6) as a real ROS 2 node, in rclpy.

It prints the first box's class of every darknet_ros message and, when it is a person,
publishes a Twist of 0.1 m/s forward on /cmd_vel. Run it beside ``rover --ros2`` with a ROS 2
install (or rover's test set-up: scripts/ros2/peers.py) and darknet_ros_msgs built for ROS 2
(scripts/ros2/interfaces/darknet_ros_msgs, darknet_ros's ROS 2 layout):

    python3 examples/ros2/listener_yolo_rclpy.py

Differences from the rospy original, both ROS 2's: the box's class is ``class_id``, and the
publisher is created once, before the first message, instead of in every callback (a new
publisher's first message may reach nobody).
"""

import rclpy
from rclpy.node import Node
from darknet_ros_msgs.msg import BoundingBoxes
from geometry_msgs.msg import Twist


class Listener(Node):
    def __init__(self):
        super().__init__("topic_subscriber")
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_subscription(BoundingBoxes, "/darknet_ros/bounding_boxes", self.callback, 10)

    def callback(self, data):
        if not data.bounding_boxes:
            return
        print(data.bounding_boxes[0].class_id, flush=True)
        if data.bounding_boxes[0].class_id == "person":
            twist = Twist()
            twist.linear.x = 0.1
            self.pub.publish(twist)
            print("go on", flush=True)


def main():
    rclpy.init()
    node = Listener()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
