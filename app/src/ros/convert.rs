//! Message parts the ROS 1 encoders share.

use rover_ros1::msgs::Header;
use rover_ros1::{Message, Publisher};

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
