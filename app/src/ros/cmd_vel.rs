//! `/cmd_vel` in (geometry_msgs/Twist on the drive's `commandTopic`): rover input, like a key.

use anyhow::Result;
use rover_core::{Action, InputSource};
use rover_ros1::msgs;
use rover_ros1::{Node, Subscriber};
use rover_sim::physics::Twist;

use crate::bridge::RosPlan;

/// `/cmd_vel` as rover input: the newest command since the last poll, as manual input (it
/// takes control from the follower; `--cmd-timeout` applies).
#[derive(Debug)]
pub struct RosCmdVel {
    sub: Subscriber<msgs::Twist>,
}

impl RosCmdVel {
    /// Subscribes to the plan's command topic.
    pub(super) fn subscribe(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            sub: node.subscribe(&plan.cmd_topic, 10)?,
        })
    }
}

impl InputSource for RosCmdVel {
    fn poll(&mut self) -> Option<Action> {
        self.sub
            .latest()
            .map(|t| Action::CmdVel(Twist::new(t.linear.x, t.angular.z)))
    }
}
