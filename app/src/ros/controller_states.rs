//! The controllers' `state` topics: control_msgs/JointControllerState for position controllers
//! (set point, position, velocity, error, effort, gains) and
//! control_msgs/JointTrajectoryControllerState for trajectory controllers (desired, actual,
//! error per joint), at 50 Hz or the controller's `state_publish_rate`. Built from the joint
//! samples the loop thread already sends for `/joint_states`.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use super::convert::seq_of;
use crate::bridge::events::{ControlUpdate, JointSample, TopicFamily};
use crate::bridge::plan::{ControllerTopic, RosPlan};

enum StatePublisher {
    Position(
        Publisher<msgs::JointControllerState>,
        msgs::JointControllerState,
    ),
    Trajectory(
        Publisher<msgs::JointTrajectoryControllerState>,
        Box<msgs::JointTrajectoryControllerState>,
    ),
}

struct State {
    topic: ControllerTopic,
    publisher: StatePublisher,
    next_s: f64,
}

/// Publishes every controller's `state`.
pub(super) struct ControllerStates {
    states: Vec<State>,
    /// The control update's period (s), for `time_step`.
    last_s: Option<f64>,
}

impl ControllerStates {
    /// Advertises the `state` topic of every controller that has one.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let mut states = Vec::new();
        for topic in &plan.controllers {
            let Some(name) = &topic.state_topic else {
                continue;
            };
            let publisher = if topic.trajectory {
                let joint_names = topic
                    .joints
                    .iter()
                    .filter_map(|&k| plan.joints.get(k).map(|j| j.name.clone()))
                    .collect();
                StatePublisher::Trajectory(
                    node.advertise(name, 10, false)?,
                    Box::new(msgs::JointTrajectoryControllerState {
                        joint_names,
                        ..msgs::JointTrajectoryControllerState::default()
                    }),
                )
            } else {
                let pid = topic.pid.unwrap_or(rover_sim::model::Pid {
                    p: 0.0,
                    i: 0.0,
                    d: 0.0,
                    i_clamp: 0.0,
                });
                StatePublisher::Position(
                    node.advertise(name, 10, false)?,
                    msgs::JointControllerState {
                        p: pid.p,
                        i: pid.i,
                        d: pid.d,
                        i_clamp: pid.i_clamp,
                        antiwindup: true,
                        ..msgs::JointControllerState::default()
                    },
                )
            };
            states.push(State {
                topic: topic.clone(),
                publisher,
                next_s: 0.0,
            });
        }
        Ok(Self {
            states,
            last_s: None,
        })
    }
}

/// Fills a trajectory point's three arrays from `joints` with `value`.
fn fill(
    point: &mut msgs::JointTrajectoryPoint,
    joints: &[usize],
    samples: &[JointSample],
    value: impl Fn(&JointSample) -> (f64, f64),
) {
    point.positions.clear();
    point.velocities.clear();
    for &k in joints {
        let (q, v) = samples.get(k).map_or((0.0, 0.0), &value);
        point.positions.push(q);
        point.velocities.push(v);
    }
}

impl TopicFamily for ControllerStates {
    fn control(&mut self, update: &ControlUpdate) {
        let now_s = update.sample.sim_time_s;
        let time_step = self.last_s.map_or(0.0, |t| now_s - t);
        self.last_s = Some(now_s);
        for state in &mut self.states {
            if now_s + 1e-9 < state.next_s {
                continue;
            }
            state.next_s = now_s + 1.0 / state.topic.state_hz.max(1e-3);
            let joints = &state.topic.joints;
            match &mut state.publisher {
                StatePublisher::Position(publisher, msg) => {
                    let Some(s) = joints.first().and_then(|&k| update.joints.get(k)) else {
                        continue;
                    };
                    msg.header.seq = seq_of(publisher);
                    msg.header.stamp_s = now_s;
                    msg.set_point = s.setpoint;
                    msg.process_value = s.position;
                    msg.process_value_dot = s.velocity_radps;
                    msg.error = s.setpoint - s.position;
                    msg.time_step = time_step;
                    msg.command = s.effort;
                    publisher.publish(msg);
                }
                StatePublisher::Trajectory(publisher, msg) => {
                    msg.header.seq = seq_of(publisher);
                    msg.header.stamp_s = now_s;
                    fill(&mut msg.desired, joints, &update.joints, |s| {
                        (s.setpoint, 0.0)
                    });
                    msg.desired.velocities.clear();
                    fill(&mut msg.actual, joints, &update.joints, |s| {
                        (s.position, s.velocity_radps)
                    });
                    fill(&mut msg.error, joints, &update.joints, |s| {
                        (s.setpoint - s.position, -s.velocity_radps)
                    });
                    msg.error.velocities.clear();
                    publisher.publish(msg.as_ref());
                }
            }
        }
    }
}
