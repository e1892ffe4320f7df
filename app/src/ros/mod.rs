//! The ROS 1 bridge (`rover --ros`): the shared bridge (app/src/bridge/: the plan, the
//! observer, the publishing thread, the topic families) on ROS 1's wire (rover-ros1: TCPROS
//! and the master's XML-RPC). Here are the encoders, one file per topic family, each
//! implementing its family's wire trait with ROS 1's messages and publishers (`clock.rs`,
//! `odom.rs`, `tf.rs`, `joint_states.rs`, `camera.rs`, `detections.rs` (darknet_ros and the
//! ground truth), `laser.rs`, `cloud.rs`, `imu.rs`, `p3d.rs`, `gps.rs`, `bumper.rs`, `arm.rs`, `status.rs`); `controller_states.rs`, the controllers'
//! `state` topics, which only ROS 1 carries (their control_msgs layouts differ between ROS 2
//! distributions); `actions.rs`, actionlib's `follow_joint_trajectory` for each trajectory
//! controller, and `gripper.rs`, `gripper_cmd` for each gripper controller (what a goal
//! means is the shared bridge's, app/src/bridge/action_goals.rs);
//! and the input half: `cmd_vel.rs`, `controllers.rs` (the controllers' `command` topics) and
//! the arm's task (`arm.rs`), as rover input.
//!
//! Stamps are sim time; `/robot_description` (and `/use_sim_time`) are parameters.

mod actions;
mod arm;
mod bumper;
mod camera;
mod clock;
mod cloud;
mod cmd_vel;
mod controller_states;
mod controllers;
mod convert;
mod detections;
mod gps;
mod gripper;
mod imu;
mod joint_states;
mod laser;
mod model_states;
mod odom;
mod p3d;
mod status;
mod tf;

use anyhow::{Context, Result};
use rover_core::{Action, InputSource};
use rover_ros1::{Node, NodeOptions, Value};
use rover_sim::model::RobotModel;

pub(crate) use crate::bridge::RosPlan;
pub use cmd_vel::RosCmdVel;
use controllers::ControllerCommands;

use crate::bridge::action_intake;
use crate::bridge::tf as tf_family;
use crate::bridge::{Backlog, Bridge, Transport, arm as arm_family, camera as camera_family};
use crate::bridge::{clock as clock_family, darknet, joint_states as joint_states_family};
use crate::bridge::{laser as laser_family, odom as odom_family, status as status_family};

/// `--ros` settings.
#[derive(Debug, Clone)]
pub struct RosOptions {
    /// Node name (`rover` -> `/rover`).
    pub name: String,
    /// Also set `/use_sim_time` so ROS nodes follow `/clock`.
    pub sim_time: bool,
    /// The run measures ground truth (`--ground-truth`): publish it on
    /// `/rover/ground_truth/bounding_boxes`.
    pub ground_truth: bool,
}

/// ROS 1's encoders, advertised on `node`.
struct Ros1<'a> {
    node: &'a Node,
}

impl Transport for Ros1<'_> {
    fn clock(&mut self) -> Result<Box<dyn clock_family::ClockWire>> {
        Ok(Box::new(clock::Clock::advertise(self.node)?))
    }

    fn odom(&mut self, plan: &RosPlan) -> Result<Box<dyn odom_family::OdomWire>> {
        Ok(Box::new(odom::Odom::advertise(self.node, plan)?))
    }

    fn tf(&mut self) -> Result<Box<dyn tf_family::TfWire>> {
        Ok(Box::new(tf::Tf::advertise(self.node)?))
    }

    fn joint_states(
        &mut self,
        plan: &RosPlan,
    ) -> Result<Box<dyn joint_states_family::JointStatesWire>> {
        Ok(Box::new(joint_states::JointStates::advertise(
            self.node, plan,
        )?))
    }

    fn camera(&mut self, plan: &RosPlan) -> Result<Box<dyn camera_family::CameraWire>> {
        Ok(Box::new(camera::Camera::advertise(self.node, plan)?))
    }

    fn darknet(&mut self) -> Result<Box<dyn darknet::DarknetWire>> {
        Ok(Box::new(detections::Darknet::advertise(self.node)?))
    }

    fn laser(&mut self, plan: &RosPlan) -> Result<Box<dyn laser_family::ScanWire>> {
        Ok(Box::new(laser::Laser::advertise(self.node, plan)?))
    }

    fn p3d(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::p3d::P3dWire>> {
        Ok(Box::new(p3d::P3d::advertise(self.node, plan)?))
    }

    fn gps(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::gps::GpsWire>> {
        Ok(Box::new(gps::Gps::advertise(self.node, plan)?))
    }

    fn bumper(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::bumper::BumperWire>> {
        Ok(Box::new(bumper::Bumper::advertise(self.node, plan)?))
    }

    fn cloud(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::cloud::CloudWire>> {
        Ok(Box::new(cloud::Clouds::advertise(self.node, plan)?))
    }

    fn imu(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::imu::ImuWire>> {
        Ok(Box::new(imu::Imu::advertise(self.node, plan)?))
    }

    fn arm(&mut self, plan: &RosPlan) -> Result<Box<dyn arm_family::ArmWire>> {
        Ok(Box::new(arm::Arm::advertise(self.node, plan)?))
    }

    fn ground_truth(&mut self) -> Result<Box<dyn darknet::BoxesWire>> {
        let topic = crate::bridge::ground_truth::GROUND_TRUTH_TOPIC;
        Ok(Box::new(detections::Boxes::advertise(
            self.node,
            topic,
            "ground_truth",
        )?))
    }

    fn status(&mut self) -> Result<Box<dyn status_family::StatusWire>> {
        Ok(Box::new(status::Status::advertise(self.node)?))
    }

    fn model_states(&mut self) -> Result<Box<dyn crate::bridge::model_states::ModelStatesWire>> {
        Ok(Box::new(model_states::ModelStates::advertise(self.node)?))
    }
}

/// The input half of the bridge: `/cmd_vel`, the controllers' `command` topics and the arm's
/// task.
#[derive(Debug)]
pub struct RosInput {
    cmd_vel: RosCmdVel,
    controllers: ControllerCommands,
    arm: arm::ArmTaskInput,
    /// Trajectories of the goals the action servers accepted (and stops for cancelled ones).
    actions: action_intake::GoalCommands,
}

impl InputSource for RosInput {
    fn poll(&mut self) -> Option<Action> {
        self.cmd_vel
            .poll()
            .or_else(|| self.controllers.poll())
            .or_else(|| self.arm.poll())
            .or_else(|| self.actions.poll())
    }
}

/// The observer half of the bridge: the shared bridge, its thread publishing on ROS 1.
pub(crate) type RosBridge = Bridge<()>;

impl Bridge<()> {
    /// Starts the node (registering with `ROS_MASTER_URI` as soon as a master answers),
    /// advertises the robot's topics, sets `/robot_description` (and `/use_sim_time`), and
    /// subscribes to its command topic.
    pub fn start(options: &RosOptions, robot: &RobotModel) -> Result<(Self, RosInput)> {
        let node_options = NodeOptions::from_env(&options.name)?;
        let node = Node::start(node_options).context("starting the ROS node")?;
        let plan = RosPlan::for_robot(robot);
        node.set_param("robot_description", Value::from(robot.description.as_str()))?;
        if options.sim_time {
            node.set_param("use_sim_time", Value::Bool(true))?;
        }
        let mut families =
            crate::bridge::families(&mut Ros1 { node: &node }, &plan, options.ground_truth)?;
        families.push(Box::new(controller_states::ControllerStates::advertise(
            &node, &plan,
        )?));
        let mut servers = actions::trajectory_servers(&node, &plan)?;
        servers.extend(gripper::gripper_servers(&node, &plan, robot)?);
        let (actions, goal_commands) = action_intake::intake(servers);
        families.push(Box::new(actions));
        let cmd = RosCmdVel::subscribe(&node, &plan)?;
        let controllers = ControllerCommands::subscribe(&node, &plan)?;
        let arm_task = arm::ArmTaskInput::subscribe(&node)?;
        for c in &plan.controllers {
            tracing::info!(
                "ROS: controller {} takes {} on {}",
                c.name,
                if c.trajectory {
                    "trajectory_msgs/JointTrajectory"
                } else {
                    "std_msgs/Float64"
                },
                c.command_topic
            );
        }
        tracing::info!(
            "ROS: node {} at {}; master {}; cmd_vel on {}, odometry on {}{}",
            node.name(),
            node.uri(),
            node.master_uri(),
            plan.cmd_topic,
            plan.odom_topic,
            plan.image_topic
                .as_deref()
                .map(|t| format!(", camera on {t}"))
                .unwrap_or_default()
        );
        let bridge = Bridge::spawn(
            "ROS",
            "ros-bridge",
            &plan,
            robot,
            Backlog::Drop,
            families,
            move |families| {
                // Unregisters from the master; the publishers go after.
                drop(node);
                drop(families);
            },
        )?;
        Ok((
            bridge,
            RosInput {
                cmd_vel: cmd,
                controllers,
                arm: arm_task,
                actions: goal_commands,
            },
        ))
    }
}
