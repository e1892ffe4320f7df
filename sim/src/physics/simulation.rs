//! The simulation: a world and a URDF robot in rapier3d, stepped at a fixed rate, driven by the
//! Gazebo-style diff drive.

use glam::Vec3;
use rapier3d::prelude::*;

use crate::error::{Result, SimError, quoted_list};
use crate::geometry::{Pose, yaw_of};
use crate::model::actuation::Pid;
use crate::model::drive::{DiffDriveConfig, OdometrySource};
use crate::model::person::Person;
use crate::model::robot::{JointId, LinkId, RobotModel};
use crate::model::world::{JointSolver, World, check_step_hz};
use crate::physics::actuators::{Actuators, JointCommand, JointState};
use crate::physics::build::{
    STIFF_MASS_RATIO, STIFF_SOLVER_ITERATIONS, WORLD_GROUP, WorldBodies, add_models, add_robot,
    add_world, joint_mass_ratio, person_body_pose,
};
use crate::physics::controllers::{
    ControllerCommandState, Controllers, GripperState, TrajectoryState,
};
use crate::physics::diff_drive::{
    DiffDriveController, EncoderOdometry, LEFT, Odometry, RIGHT, Twist, WheelSpeeds, wrap_angle,
};
use crate::physics::grasp::Grasped;
use crate::physics::grip_friction::{ContactHooks, FrictionAnchors};
use crate::physics::joints::{BuiltJoint, joint_data_mut};
use crate::physics::trajectory::JointTrajectory;

/// Options that are not part of the world or robot files.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimOptions {
    /// Seed for every random process (sensor noise, ...). Same seed, same run.
    pub seed: u64,
    /// Overrides the diff drive's `cmd_timeout_s` (`Some(0.0)` turns it off).
    pub cmd_timeout_s: Option<f64>,
    /// Overrides the world's physics step rate (Hz).
    pub step_hz: Option<f64>,
    /// Overrides how the world solves the robot's joints (`[physics] joints`).
    pub joints: Option<JointSolver>,
}

/// The robot's state at one diff-drive control update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlSample {
    /// Sim time of the update (s).
    pub sim_time_s: f64,
    /// Ground-truth planar pose and velocity of the base link (world frame).
    pub ground_truth: Odometry,
    /// Odometry from the plugin's configured `odometrySource`.
    pub odometry: Odometry,
    /// The base's height (m), roll and pitch (rad) that go with `odometry` in 3D: with
    /// `odometrySource` world, the base's own (gazebo_ros_diff_drive publishes the model's full
    /// world pose, `parent->WorldPose()`); with encoder, zeros (its odometry is planar).
    pub odometry_z_roll_pitch: [f64; 3],
    /// The cmd_vel in force (zero after a command timeout).
    pub cmd: Twist,
    /// Wheel joint speed targets sent to the motors (rad/s).
    pub wheel_targets_radps: WheelSpeeds,
    /// Measured wheel joint speeds (rad/s).
    pub wheel_measured_radps: WheelSpeeds,
}

#[derive(Debug, Clone, Copy)]
struct WheelJoint {
    joint: BuiltJoint,
    /// [`LEFT`] or [`RIGHT`]: which commanded wheel speed drives it.
    side: usize,
}

/// A running simulation.
pub struct Simulation {
    pub(crate) physics: PhysicsWorld,
    pub(crate) robot: RobotModel,
    pub(crate) world: World,
    pub(crate) link_body: Vec<RigidBodyHandle>,
    pub(crate) body_from_link: Vec<Pose>,
    pub(crate) base: RigidBodyHandle,
    /// Driven wheel joints: the left and right ones first (their speeds are the measured
    /// wheel speeds), then a skid steer's rear wheels. Empty when the robot cannot be driven.
    wheels: Vec<WheelJoint>,
    pub(crate) drive: DiffDriveController,
    pub(crate) encoder: EncoderOdometry,
    step_index: u64,
    dt_s: f64,
    seed: u64,
    /// Kinematic bodies of the people, in world order.
    pub(crate) people: Vec<RigidBodyHandle>,
    /// Bodies of the world objects, in world order.
    pub(crate) objects: Vec<RigidBodyHandle>,
    /// The grasp assist, with `[robot] grasp = "assist"`.
    grasp: Option<crate::physics::grasp::GraspAssist>,
    /// Contacts of `<kp>` links, which give way (rapier's contact hook).
    springs: crate::physics::contact_springs::ContactSprings,
    /// Static friction on the gripper's finger pads.
    anchors: FrictionAnchors,
    /// Link pairs the world's SRDF (`[robot] srdf`) says never collide: the planning scene
    /// does not check them against each other.
    pub(crate) srdf_disabled: Vec<(LinkId, LinkId)>,
    /// Counts placements ([`Simulation::layout_version`]).
    pub(crate) layout: u64,
    /// Relative poses of placed things, kept until the next step.
    pub(crate) placement: PlacementCache,
    /// Bodies of the SDF models' links, in model then link order.
    pub(crate) model_links: Vec<RigidBodyHandle>,
    /// The ground's body (not an obstacle for clearance figures).
    pub(crate) ground: RigidBodyHandle,
    /// Every moving joint as built (joint order; `None` for fixed ones).
    joints: Vec<Option<BuiltJoint>>,
    /// The actuated joints' motors, run every `control_steps` physics steps.
    actuators: Actuators,
    /// The controllers file's controllers (none without one).
    controllers: Controllers,
    control_steps: u64,
}

impl std::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation")
            .field("world", &self.world.name)
            .field("robot", &self.robot.name)
            .field("sim_time_s", &self.sim_time_s())
            .finish_non_exhaustive()
    }
}

/// The actuators of the robot's actuated joints and the controllers file's controllers on
/// them.
fn actuate(
    robot: &RobotModel,
    bodies: (&[Option<BuiltJoint>], &[RigidBodyHandle]),
    physics: &mut PhysicsWorld,
) -> Result<(Actuators, Controllers)> {
    let mut actuators = Actuators::new(robot, bodies, physics);
    let controllers = match &robot.controllers {
        Some(config) => Controllers::new(config, robot, &mut actuators)?,
        None => Controllers::default(),
    };
    Ok((actuators, controllers))
}

impl Simulation {
    /// Builds the physics scene for `robot` in `world`.
    pub fn new(world: World, robot: RobotModel, options: &SimOptions) -> Result<Self> {
        let people = &world.people;
        crate::model::human::check_available(people.iter().any(Person::needs_makehuman))?;
        let drivable = robot.diff_drive.is_some();
        // A robot bolted to the world (a `world` root link: an arm on a table) is not meant to
        // drive; anything else without a drive is told why cmd_vel does nothing.
        if !drivable && !robot.is_anchored() {
            tracing::warn!(
                "{}: robot \"{}\" cannot be driven: it has no libgazebo_ros_diff_drive.so or libgazebo_ros_skid_steer_drive.so plugin and the world gives no [robot.drive]; it is simulated and shown, commands are ignored",
                robot.source.display(),
                robot.name
            );
        }
        let mut drive_config = robot.diff_drive.clone().unwrap_or_default();
        if let Some(timeout) = options.cmd_timeout_s {
            if !(timeout.is_finite() && timeout >= 0.0) {
                return Err(SimError::Setup(format!(
                    "cmd timeout must be zero (off) or a positive number of seconds, found {timeout}"
                )));
            }
            drive_config.cmd_timeout_s = (timeout > 0.0).then_some(timeout);
        }
        let step_hz = options.step_hz.unwrap_or(world.physics.step_hz);
        check_step_hz(step_hz).map_err(SimError::Setup)?;
        let dt_s = 1.0 / step_hz;

        let mut physics = PhysicsWorld::new();
        let g = world.physics.gravity_mps2;
        physics.gravity = Vec3::new(g[0] as f32, g[1] as f32, g[2] as f32);
        physics.integration_parameters.dt = dt_s as f32;
        physics.integration_parameters.num_solver_iterations = world.physics.solver_iterations;
        physics
            .integration_parameters
            .contact_softness
            .natural_frequency = world.physics.contact_hz as f32;

        let WorldBodies {
            ground,
            objects,
            people,
        } = add_world(&mut physics, &world)?;
        let model_links = add_models(&mut physics, &world)?;
        let solver = options.joints.unwrap_or(world.physics.joints);
        let robot_bodies = add_robot(&mut physics, &world, &robot, solver)?;
        let ratio = joint_mass_ratio(&robot, &robot_bodies);
        if solver == JointSolver::Impulse
            && ratio > STIFF_MASS_RATIO
            && physics.integration_parameters.num_solver_iterations < STIFF_SOLVER_ITERATIONS
        {
            // Light wheels on a heavy body (a TurtleBot3's 28 g wheels carry 30x their mass)
            // need more solver iterations, or the joints stretch and the robot rocks.
            tracing::info!(
                "{}: joints connect bodies with a {ratio:.0}:1 mass ratio; using {STIFF_SOLVER_ITERATIONS} solver iterations (world: {})",
                robot.name,
                physics.integration_parameters.num_solver_iterations
            );
            physics.integration_parameters.num_solver_iterations = STIFF_SOLVER_ITERATIONS;
        }

        let wheels = wheel_joints(&robot, &robot_bodies.joints, &drive_config, &mut physics)?;

        let (actuators, controllers) = actuate(
            &robot,
            (&robot_bodies.joints, &robot_bodies.link_body),
            &mut physics,
        )?;
        // ros_control's controlPeriod (default: every physics step), never below the step.
        let control_steps = robot
            .ros_control
            .as_ref()
            .and_then(|r| r.control_period_s)
            .map_or(1, |period| ((period / dt_s).round() as u64).max(1));
        let base = robot_bodies.link_body[robot.root.index()];
        let start = planar(
            physics
                .bodies
                .get(base)
                .map(|b| *b.position())
                .unwrap_or_default(),
        );
        let encoder = EncoderOdometry::new(start, &drive_config);
        let (grasp, anchors) = crate::physics::grip_friction::grip(
            &robot,
            (&robot_bodies.link_body, objects.len() + model_links.len()),
            world.robot.grasp,
            &mut physics,
        )?;
        Self {
            physics,
            anchors,
            springs: robot_bodies.springs,
            link_body: robot_bodies.link_body,
            body_from_link: robot_bodies.body_from_link,
            base,
            wheels,
            drive: DiffDriveController::new(drive_config).with_step(dt_s),
            encoder,
            step_index: 0,
            dt_s,
            seed: options.seed,
            people,
            objects,
            grasp,
            layout: 0,
            placement: PlacementCache::default(),
            model_links,
            ground,
            joints: robot_bodies.joints,
            actuators,
            controllers,
            control_steps,
            srdf_disabled: crate::description::srdf::srdf_disabled_collisions(&world, &robot)?,
            robot,
            world,
        }
        .with_start_pose()
    }

    /// Sets cmd_vel (takes effect at the next control update). Non-finite values are rejected and
    /// the last valid command stays in force.
    pub fn set_cmd_vel(&mut self, cmd: Twist) -> Result<()> {
        let now = self.sim_time_s();
        self.drive.set_command(cmd, now)
    }

    /// Advances one physics step. When the diff drive's control loop ran at the start of this
    /// step, returns the robot's state at that moment.
    pub fn step(&mut self) -> Option<ControlSample> {
        let now = self.sim_time_s();
        let sample = if self.drive.update(now) {
            let targets = self.drive.wheel_targets_radps();
            for wheel in &self.wheels {
                let target = targets[wheel.side];
                if let Some(data) = joint_data_mut(&mut self.physics, wheel.joint.handle) {
                    data.set_motor_velocity(JointAxis::AngX, target as f32, WHEEL_MOTOR_GAIN);
                }
            }
            Some(self.sample(now))
        } else {
            None
        };
        // Walking people: their kinematic bodies move to where their path puts them at the end
        // of this step (rapier derives their velocity, so contacts push correctly).
        let next_t = (self.step_index + 1) as f64 * self.dt_s;
        for (person, handle) in self.world.people.iter().zip(&self.people) {
            if person.moves()
                && let Some(body) = self.physics.bodies.get_mut(*handle)
            {
                body.set_next_kinematic_position(person_body_pose(person, next_t));
            }
        }
        if self.step_index.is_multiple_of(self.control_steps) {
            let period_s = self.control_steps as f64 * self.dt_s;
            self.controllers
                .update(&self.robot, &mut self.actuators, now);
            self.actuators.update(&mut self.physics, period_s);
        }
        self.actuators.apply_efforts(&mut self.physics, self.dt_s);
        if self.springs.is_empty() && self.anchors.is_empty() {
            self.physics.step();
        } else {
            let hooks = ContactHooks {
                springs: &self.springs,
                anchors: &self.anchors,
            };
            self.physics.step_with_events(&hooks, &());
        }
        if !self.anchors.is_empty() {
            self.anchors
                .update(&self.physics, [&self.objects, &self.model_links]);
        }
        if let Some(grasp) = &mut self.grasp
            && let Some(event) =
                grasp.update(&mut self.physics, [&self.objects, &self.model_links], now)
        {
            // Logged with the controllers' events (Simulation::drain_controller_events).
            self.controllers.note(event);
        }
        self.placement.clear();
        self.step_index += 1;
        let measured = self.wheel_speeds_radps();
        self.encoder.integrate(measured, self.dt_s);
        sample
    }

    fn sample(&self, now: f64) -> ControlSample {
        let odometry_z_roll_pitch = match self.drive.config().odometry_source {
            OdometrySource::World => {
                let base = self.world_from_base();
                let (_, pitch, roll) = base.rotation.to_euler(glam::EulerRot::ZYX);
                [base.translation.z, roll, pitch].map(f64::from)
            }
            OdometrySource::Encoder => [0.0; 3],
        };
        ControlSample {
            sim_time_s: now,
            ground_truth: self.ground_truth(),
            odometry: self.odometry(),
            odometry_z_roll_pitch,
            cmd: self.drive.command(),
            wheel_targets_radps: self.drive.wheel_targets_radps(),
            wheel_measured_radps: self.wheel_speeds_radps(),
        }
    }

    /// Distance (m) along a ray from `origin` in direction `dir` (unit, world frame) to the
    /// first surface of the world (ground, objects, walls, models, people), not the robot
    /// itself; `None` when nothing is hit within `max_m`.
    pub fn cast_world_ray(&self, origin: Vec3, dir: Vec3, max_m: f32) -> Option<f32> {
        self.cast_world_ray_past_people(origin, dir, max_m, &[])
    }

    /// As [`Simulation::cast_world_ray`], but through the physics capsules of the people
    /// `skip` marks (world order): a range sensor that sees those people's posed bodies
    /// instead.
    pub(crate) fn cast_world_ray_past_people(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_m: f32,
        skip: &[bool],
    ) -> Option<f32> {
        let skipped = |c: &Collider| {
            c.parent().is_some_and(|body| {
                self.people
                    .iter()
                    .zip(skip)
                    .any(|(handle, s)| *s && *handle == body)
            })
        };
        let keep = |_: ColliderHandle, c: &Collider| !skipped(c);
        let filter = QueryFilter::default()
            .groups(InteractionGroups::new(
                Group::ALL,
                WORLD_GROUP,
                InteractionTestMode::And,
            ))
            .predicate(&keep);
        let ray = Ray::new(origin, dir);
        self.physics
            .cast_ray(&ray, max_m, true, filter)
            .map(|(_, toi)| toi)
    }

    /// The smallest distance (m) between the robot's collision shapes and the world's
    /// obstacles (objects, walls, SDF models; not the ground, not people), looking no further
    /// than `within_m`: returns `within_m` when nothing is closer. 0 when touching.
    pub fn obstacle_clearance_m(&self, within_m: f32) -> f32 {
        let mut best = within_m;
        let obstacles = QueryFilter::default().groups(InteractionGroups::new(
            Group::ALL,
            WORLD_GROUP,
            InteractionTestMode::And,
        ));
        let query = self.physics.query_pipeline_with_filter(obstacles);
        for (_, robot_collider) in self.physics.colliders.iter() {
            let is_robot = robot_collider
                .parent()
                .is_some_and(|p| self.link_body.contains(&p));
            if !is_robot {
                continue;
            }
            let mut aabb = robot_collider.compute_aabb();
            aabb.mins -= Vec3::splat(best);
            aabb.maxs += Vec3::splat(best);
            for (_, other) in query.intersect_aabb_conservative(aabb) {
                let parent = other.parent();
                if parent == Some(self.ground) || parent.is_some_and(|p| self.people.contains(&p)) {
                    continue;
                }
                if let Ok(d) = rapier3d::parry::query::distance(
                    robot_collider.position(),
                    robot_collider.shape(),
                    other.position(),
                    other.shape(),
                ) {
                    best = best.min(d.distance.max(0.0));
                }
            }
        }
        best
    }

    /// Pose of person `index` (world order) now: feet on the ground, x facing where they look.
    pub fn world_from_person(&self, index: usize) -> Pose {
        self.world
            .people
            .get(index)
            .map_or(Pose::IDENTITY, |p| p.world_from_person(self.sim_time_s()))
    }

    /// Where person `index` (world order) is in their gait now (rad; 0 standing): see
    /// [`crate::model::person::Person::gait_phase_rad`].
    pub fn person_gait_phase_rad(&self, index: usize) -> f64 {
        self.world
            .people
            .get(index)
            .map_or(0.0, |p| p.gait_phase_rad(self.sim_time_s()))
    }
}

// Commanding the robot's joints and controllers (ros_control's commands, trajectories, the gripper).
impl Simulation {
    /// Commands a joint by name (a controller's command, a script step, a key). Errors: no
    /// such joint, a joint without an actuator, a non-finite value (the command is dropped and
    /// the last one stays in force). Positions outside the joint's limits stop at the limit.
    pub fn command_joint(&mut self, name: &str, command: JointCommand) -> Result<()> {
        let id = self.joint_named(name)?;
        self.actuators.command(&self.robot, id, command)
    }

    /// Gives an actuated joint its own PID gains (instead of the inertia-derived hold).
    pub fn set_joint_pid(&mut self, name: &str, pid: Pid) -> Result<()> {
        let id = self.joint_named(name)?;
        if self.actuators.of(id).is_none() {
            return Err(SimError::Setup(format!(
                "joint \"{name}\" has no actuator (it is fixed, passive, a drive wheel or mimics another joint)"
            )));
        }
        self.actuators.set_pid(id, pid);
        Ok(())
    }

    /// Sends a command to a single-joint controller of the robot's controllers file (what its
    /// `command` topic carries: a position, velocity or effort, per its type).
    pub fn command_controller(&mut self, name: &str, value: f64) -> Result<()> {
        self.controllers
            .command(name, value, &self.robot, &mut self.actuators)
    }

    /// Starts `trajectory` on the joint trajectory controller `name`; the outcome (goal
    /// reached, a tolerance violated) comes from [`Simulation::drain_controller_events`].
    pub fn follow_trajectory(&mut self, name: &str, trajectory: &JointTrajectory) -> Result<()> {
        let now = self.sim_time_s();
        self.controllers
            .follow(name, trajectory, &self.robot, (&mut self.actuators, now))
    }

    /// Sends a command to the gripper controller `name` (control_msgs/GripperCommand: the
    /// finger joint's position, and the most effort, 0 or less for its `<limit effort>`); what
    /// came of it is [`Simulation::gripper_state`].
    pub fn command_gripper(&mut self, name: &str, position: f64, max_effort: f64) -> Result<()> {
        let now = self.sim_time_s();
        self.controllers.command_gripper(
            name,
            (position, max_effort),
            &self.robot,
            (&mut self.actuators, now),
        )
    }

    /// What the grasp assist holds (`[robot] grasp = "assist"`): a world object or a model's
    /// link, by its index.
    pub fn grasp_assist_holds(&self) -> Option<Grasped> {
        self.grasp.as_ref().and_then(|g| g.held())
    }

    /// The state of the gripper controller `name`.
    pub fn gripper_state(&self, name: &str) -> Option<&GripperState> {
        self.controllers.gripper_state(name)
    }

    /// This simulation with its joints moving to the world's `[robot] pose`, when it names one.
    fn with_start_pose(mut self) -> Result<Self> {
        if let Some(name) = self.world.robot.pose.clone() {
            self.go_to_named_pose(&name)
                .map_err(|e| SimError::Setup(format!("[robot] pose = \"{name}\": {e}")))?;
        }
        Ok(self)
    }

    /// Moves every joint of the controllers file's pose `name` there (each at its own pace,
    /// within its limits).
    pub fn go_to_named_pose(&mut self, name: &str) -> Result<()> {
        let config = self.robot.controllers.as_ref();
        let Some(pose) = config.and_then(|c| c.named_pose(name)).cloned() else {
            let known: Vec<String> = config
                .map(|c| c.named_poses.iter().map(|p| p.name.clone()).collect())
                .unwrap_or_default();
            return Err(SimError::Setup(format!(
                "no named pose \"{name}\"; known: {}",
                if known.is_empty() {
                    "none (give `named_poses` in a controllers file)".to_owned()
                } else {
                    quoted_list(known.iter())
                }
            )));
        };
        for (joint, q) in &pose.joints {
            self.command_joint(joint, JointCommand::Position(*q))?;
        }
        Ok(())
    }

    /// Calls `f` with each controller event since the last call (a trajectory reached its goal
    /// or violated a tolerance), oldest first.
    pub fn drain_controller_events(&mut self, mut f: impl FnMut(&str)) {
        for event in self.controllers.drain_events() {
            f(&event);
        }
    }

    /// The state of the joint trajectory controller `name` (its `state` topic).
    pub fn trajectory_state(&self, name: &str) -> Option<&TrajectoryState> {
        self.controllers.trajectory_state(name)
    }

    /// The joint and last command of the single-joint controller `name` (its `state` topic).
    pub fn controller_command_state(&self, name: &str) -> Option<ControllerCommandState> {
        self.controllers.command_state(name)
    }

    /// The position the actuator of `joint` holds now (rad or m): where a position command
    /// has brought the setpoint so far. `None` for joints without an actuator.
    pub fn joint_setpoint(&self, joint: JointId) -> Option<f64> {
        self.actuators
            .of(joint)
            .map(|_| self.actuators.setpoint(joint))
    }

    /// Where the command of `joint`'s actuator sends it (rad or m): a position command's target
    /// (reached at the actuator's pace), a trajectory's sample, else where it is held. `None`
    /// for joints without an actuator.
    pub fn joint_target(&self, joint: JointId) -> Option<f64> {
        self.actuators
            .of(joint)
            .map(|_| self.actuators.target(joint))
    }

    fn joint_named(&self, name: &str) -> Result<JointId> {
        self.robot.joint_id(name).ok_or_else(|| {
            SimError::Setup(format!(
                "robot \"{}\" has no joint \"{name}\"; its moving joints: {}",
                self.robot.name,
                quoted_list(self.moving_joints().map(|id| &self.robot.joint(id).name))
            ))
        })
    }

    /// The joints that move in the scene (continuous, revolute, prismatic), joint order.
    pub fn moving_joints(&self) -> impl Iterator<Item = JointId> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.is_some())
            .map(|(i, _)| JointId(i))
    }

    /// The state of a moving joint now; `None` for fixed joints.
    pub fn joint_state(&self, joint: JointId) -> Option<JointState> {
        let built = self.joints.get(joint.index())?.as_ref()?;
        Some(JointState {
            position: built.position(&self.physics.bodies),
            velocity: built.velocity(&self.physics.bodies),
            effort: self.actuators.of(joint).map_or(0.0, |a| a.effort),
        })
    }
}

// Reading the simulation back: time, the robot and world, poses, odometry, joint states.
impl Simulation {
    /// Sim time (s): physics steps taken times the step length.
    pub fn sim_time_s(&self) -> f64 {
        self.step_index as f64 * self.dt_s
    }

    /// Physics steps taken so far.
    pub fn step_index(&self) -> u64 {
        self.step_index
    }

    /// The fixed physics step (s).
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// The seed this run was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The robot being simulated.
    pub fn robot(&self) -> &RobotModel {
        &self.robot
    }

    /// The world being simulated.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Whether the robot's base can be driven (it has driven wheels: a diff drive or a skid
    /// steer).
    pub fn can_drive(&self) -> bool {
        !self.wheels.is_empty()
    }

    /// The diff drive controller (configuration, command in force).
    pub fn drive(&self) -> &DiffDriveController {
        &self.drive
    }

    /// Pose of the robot's root (base) link in the world.
    pub fn world_from_base(&self) -> Pose {
        self.world_from_link(self.robot.root)
    }

    /// Pose of a link of the robot in the world.
    pub fn world_from_link(&self, link: LinkId) -> Pose {
        let index = link.index();
        let body = self
            .physics
            .bodies
            .get(self.link_body[index])
            .map(|b| *b.position())
            .unwrap_or_default();
        body * self.body_from_link[index]
    }

    /// Every link's world pose, in URDF order, into `out` (cleared first; no allocation once
    /// `out` has the capacity).
    pub fn link_poses_into(&self, out: &mut Vec<Pose>) {
        out.clear();
        out.extend(
            self.robot
                .link_ids()
                .map(|(id, _)| self.world_from_link(id)),
        );
    }

    /// World pose of every SDF model link (models in world order, then their links) into
    /// `out` (cleared first; no allocation once `out` has the capacity).
    pub fn model_link_poses_into(&self, out: &mut Vec<Pose>) {
        out.clear();
        out.extend(self.model_links.iter().map(|h| {
            self.physics
                .bodies
                .get(*h)
                .map_or(Pose::IDENTITY, |b| *b.position())
        }));
    }

    /// Where model link `index` (in [`Self::model_link_poses_into`]'s order) has its centre of
    /// mass now (world frame, m); `None` for no such link.
    pub fn model_link_centre(&self, index: usize) -> Option<glam::Vec3> {
        let body = self.physics.bodies.get(*self.model_links.get(index)?)?;
        Some(body.center_of_mass())
    }

    /// Ground-truth planar pose and velocity of the base link.
    pub fn ground_truth(&self) -> Odometry {
        let Some(body) = self.physics.bodies.get(self.base) else {
            return Odometry::default();
        };
        let mut odo = planar(*body.position());
        let forward = body.rotation() * Vec3::X;
        odo.linear_mps = f64::from(body.linvel().dot(forward));
        odo.angular_radps = f64::from(body.angvel().z);
        odo
    }

    /// Odometry from the configured source (`world` = ground truth, `encoder` = integrated wheels).
    pub fn odometry(&self) -> Odometry {
        match self.drive.config().odometry_source {
            OdometrySource::World => self.ground_truth(),
            OdometrySource::Encoder => self.encoder.odometry(),
        }
    }

    /// Encoder odometry, whatever the configured source.
    pub fn encoder_odometry(&self) -> Odometry {
        self.encoder.odometry()
    }

    /// Measured left/right wheel joint speeds (rad/s): the child's angular velocity relative to
    /// its parent, about the joint axis.
    pub fn wheel_speeds_radps(&self) -> WheelSpeeds {
        let mut out = [0.0; 2];
        for w in self.wheels.iter().take(2) {
            out[w.side] = w.joint.velocity(&self.physics.bodies);
        }
        out
    }
}

/// Velocity motor gain (N m s/rad): high enough that the motor holds the target speed until it
/// saturates at `wheelTorque`, like Gazebo's joint velocity constraint with `fmax`.
const WHEEL_MOTOR_GAIN: f32 = 50.0;

/// The driven wheel joints (left and right, then a skid steer's extra ones), their motors set
/// up as the diff-drive plugin drives them; none when the robot cannot be driven.
fn wheel_joints(
    robot: &RobotModel,
    joints: &[Option<BuiltJoint>],
    drive_config: &DiffDriveConfig,
    physics: &mut PhysicsWorld,
) -> Result<Vec<WheelJoint>> {
    let wheel = |name: &str, side: usize| -> Result<WheelJoint> {
        let id = robot.joint_id(name).ok_or_else(|| {
            SimError::Setup(format!(
                "diff drive joint \"{name}\" missing from the robot"
            ))
        })?;
        let joint = joints[id.index()].ok_or_else(|| {
            SimError::Setup(format!("diff drive joint \"{name}\" is not a wheel joint"))
        })?;
        Ok(WheelJoint { joint, side })
    };
    let mut wheels = Vec::new();
    if robot.diff_drive.is_some() {
        wheels.push(wheel(&drive_config.left_joint, LEFT)?);
        wheels.push(wheel(&drive_config.right_joint, RIGHT)?);
        for name in &drive_config.extra_left_joints {
            wheels.push(wheel(name, LEFT)?);
        }
        for name in &drive_config.extra_right_joints {
            wheels.push(wheel(name, RIGHT)?);
        }
    }
    for w in &wheels {
        if let Some(data) = joint_data_mut(physics, w.joint.handle) {
            data.set_motor_model(JointAxis::AngX, MotorModel::ForceBased)
                .set_motor_velocity(JointAxis::AngX, 0.0, WHEEL_MOTOR_GAIN)
                .set_motor_max_force(JointAxis::AngX, drive_config.wheel_torque_nm as f32);
        }
    }
    Ok(wheels)
}

pub(crate) fn planar(pose: Pose) -> Odometry {
    Odometry {
        x_m: f64::from(pose.translation.x),
        y_m: f64::from(pose.translation.y),
        yaw_rad: wrap_angle(yaw_of(pose.rotation)),
        linear_mps: 0.0,
        angular_radps: 0.0,
    }
}

/// Where placed things were, relative to their own frame, when first placed since the last
/// step (`physics/placement.rs` places; a step forgets).
#[derive(Debug, Default)]
pub(crate) struct PlacementCache {
    /// Every robot body (once) relative to the base link.
    pub(crate) robot: Option<Vec<(RigidBodyHandle, Pose)>>,
    /// Per placed model (its index): every link relative to the model's frame.
    pub(crate) models: Vec<(usize, Vec<Pose>)>,
}

impl PlacementCache {
    /// Forgets the cached poses (physics moved things).
    pub(crate) fn clear(&mut self) {
        if self.robot.is_some() || !self.models.is_empty() {
            *self = Self::default();
        }
    }
}
