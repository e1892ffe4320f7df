//! What drives a robot's joints, as ros_control describes it: `<transmission>` elements (a
//! joint, its hardware interface, the reduction) and the `libgazebo_ros_control.so` plugin.

/// A ros_control hardware interface: what a controller commands on a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HardwareInterface {
    /// `hardware_interface/PositionJointInterface`: a position target (rad or m).
    Position,
    /// `hardware_interface/VelocityJointInterface`: a velocity target (rad/s or m/s).
    Velocity,
    /// `hardware_interface/EffortJointInterface`: a torque (N m) or force (N).
    Effort,
}

impl HardwareInterface {
    /// Reads `hardware_interface/PositionJointInterface` (also without the namespace, as old
    /// URDFs write it). `JointStateInterface` and unknown names give `None`.
    pub fn parse(name: &str) -> Option<Self> {
        let short = name.trim().rsplit('/').next().unwrap_or("");
        match short {
            "PositionJointInterface" => Some(Self::Position),
            "VelocityJointInterface" => Some(Self::Velocity),
            "EffortJointInterface" => Some(Self::Effort),
            _ => None,
        }
    }

    /// The interface's name in ros_control.
    pub fn name(self) -> &'static str {
        match self {
            Self::Position => "hardware_interface/PositionJointInterface",
            Self::Velocity => "hardware_interface/VelocityJointInterface",
            Self::Effort => "hardware_interface/EffortJointInterface",
        }
    }
}

/// One joint of a `<transmission>` and how it is driven.
#[derive(Debug, Clone, PartialEq)]
pub struct Transmission {
    /// `<transmission name>`.
    pub name: String,
    /// The joint it drives.
    pub joint: String,
    /// The command interface (the first of position, velocity, effort listed).
    pub interface: HardwareInterface,
    /// `<mechanicalReduction>` of the transmission's first actuator (1 when absent); rover
    /// drives joints directly, so it is kept for reference and not applied.
    pub reduction: f64,
    /// Line of the `<transmission>` in the description.
    pub line: Option<u32>,
}

/// The `libgazebo_ros_control.so` plugin: where the controllers' topics live and how often
/// they run.
#[derive(Debug, Clone, PartialEq)]
pub struct RosControlPlugin {
    /// `robotNamespace` (empty: the root namespace, `/`).
    pub namespace: String,
    /// `controlPeriod` (s); `None`: every physics step.
    pub control_period_s: Option<f64>,
    /// `robotSimType` (default `gazebo_ros_control/DefaultRobotHWSim`); other hardware
    /// simulations (PAL's) are driven the same way.
    pub sim_type: String,
    /// Line of the `<plugin>`.
    pub line: Option<u32>,
}

impl Default for RosControlPlugin {
    fn default() -> Self {
        Self {
            namespace: String::new(),
            control_period_s: None,
            sim_type: "gazebo_ros_control/DefaultRobotHWSim".to_owned(),
            line: None,
        }
    }
}

/// PID gains in the joint's own units: p in N m/rad (N/m), i in N m/(rad s), d in N m s/rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pid {
    /// Proportional gain.
    pub p: f64,
    /// Integral gain.
    pub i: f64,
    /// Derivative gain.
    pub d: f64,
    /// Bound on the integral term's effort (N m or N); 0 = the effort limit.
    /// (The default hold's integral may reach four effort limits: it only
    /// shifts the motor's target, whose force the limit caps.)
    pub i_clamp: f64,
}
