//! rover's types as ROS message parts, shared by the topic families.

use rover_ros1::msgs::{Header, Quaternion, TransformStamped, Vector3};
use rover_ros1::{Message, Publisher};
use rover_sim::Pose;

/// A vector as `geometry_msgs/Vector3`.
pub(super) fn vec3(v: glam::Vec3) -> Vector3 {
    Vector3 {
        x: f64::from(v.x),
        y: f64::from(v.y),
        z: f64::from(v.z),
    }
}

/// A rotation as `geometry_msgs/Quaternion`.
pub(super) fn quat(q: glam::Quat) -> Quaternion {
    Quaternion {
        x: f64::from(q.x),
        y: f64::from(q.y),
        z: f64::from(q.z),
        w: f64::from(q.w),
    }
}

/// `parent_from_child` as the transform from frame `parent` to frame `child`.
pub(super) fn transform(
    parent: &str,
    child: &str,
    stamp_s: f64,
    parent_from_child: Pose,
) -> TransformStamped {
    TransformStamped {
        header: Header {
            seq: 0,
            stamp_s,
            frame_id: parent.to_owned(),
        },
        child_frame_id: child.to_owned(),
        translation: vec3(parent_from_child.translation),
        rotation: quat(parent_from_child.rotation),
    }
}

/// A header in `frame_id`, to be numbered and stamped when published.
pub(super) fn header(frame_id: &str) -> Header {
    Header {
        seq: 0,
        stamp_s: 0.0,
        frame_id: frame_id.to_owned(),
    }
}

/// A per-topic sequence number, as roscpp and rospy set `header.seq`: messages published so far.
pub(super) fn seq_of<T: Message>(p: &Publisher<T>) -> u32 {
    p.published() as u32
}
