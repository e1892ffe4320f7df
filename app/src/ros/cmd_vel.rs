//! `/cmd_vel` in (geometry_msgs/Twist on the drive's `commandTopic`, or TwistStamped where a
//! ros_gz_bridge map says so): rover input, like a key.

use anyhow::Result;
use rover_core::{Action, InputSource};
use rover_ros1::msgs;
use rover_ros1::{Node, Subscriber};
use rover_sim::physics::Twist;

use crate::bridge::RosPlan;

/// The command topic's subscriber, of the plan's type.
#[derive(Debug)]
enum Sub {
    Twist(Subscriber<msgs::Twist>),
    Stamped(Subscriber<msgs::TwistStamped>),
}

/// `/cmd_vel` as rover input: the newest command since the last poll, as manual input (it
/// takes control from the follower; `--cmd-timeout` applies).
#[derive(Debug)]
pub struct RosCmdVel {
    sub: Sub,
}

impl RosCmdVel {
    /// Subscribes to the plan's command topic.
    pub(super) fn subscribe(node: &Node, plan: &RosPlan) -> Result<Self> {
        let sub = if plan.cmd_stamped {
            Sub::Stamped(node.subscribe(&plan.cmd_topic, 10)?)
        } else {
            Sub::Twist(node.subscribe(&plan.cmd_topic, 10)?)
        };
        Ok(Self { sub })
    }
}

impl InputSource for RosCmdVel {
    fn poll(&mut self) -> Option<Action> {
        let t = match &self.sub {
            Sub::Twist(s) => s.latest()?,
            Sub::Stamped(s) => s.latest()?.twist,
        };
        Some(Action::CmdVel(Twist::new(t.linear.x, t.angular.z)))
    }
}
