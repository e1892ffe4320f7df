//! A robot: links, joints, the drive and sensors it carries. Plain data; loaded by
//! `description` (URDF, xacro, the `<gazebo>` extensions), simulated by `physics`.

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Result, SimError, quoted_list as names};
use crate::geometry::{Pose, Rgba, Shape};
use crate::model::actuation::{RosControlPlugin, Transmission};
use crate::model::controllers::ControllerConfig;
use crate::model::drive::{DiffDriveConfig, DriveSpec};
use crate::model::mesh::MeshData;
use crate::model::sensors::{
    BumperConfig, CameraConfig, GpsConfig, ImuConfig, ImuPlugin, JointStatePublisherConfig,
    LaserConfig, LidarConfig, P3dConfig,
};

/// Mass properties of a link, from its `<inertial>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertial {
    /// Mass (kg).
    pub mass_kg: f32,
    /// Pose of the centre of mass and inertia frame in the link frame.
    pub link_from_inertial: Pose,
    /// Inertia tensor about the centre of mass, in the inertial frame: ixx, ixy, ixz, iyy, iyz, izz (kg m^2).
    pub inertia: [f32; 6],
}

/// Something drawn for a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Visual {
    /// Pose of the shape in the link frame.
    pub link_from_shape: Pose,
    /// The shape.
    pub shape: Shape,
    /// Colour from the URDF material (grey when none is given).
    pub color: Rgba,
    /// Whether the description gave the colour; when not, a mesh file's own material colour
    /// is shown (see [`Visual::display_color`]).
    pub color_given: bool,
    /// A diffuse texture the description's material gives a mesh (an SDF `<material><script>`
    /// naming an OGRE material with a `texture`), drawn over the mesh's own materials.
    pub texture: Option<PathBuf>,
}

impl Visual {
    /// The colour to draw `mesh` (this visual's triangles) in: the description's colour, else
    /// the mesh file's material, else grey.
    pub fn display_color(&self, mesh: &MeshData) -> Rgba {
        match (self.color_given, mesh.color) {
            (false, Some(c)) => c,
            _ => self.color,
        }
    }
}

/// A collision shape of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// Pose of the shape in the link frame.
    pub link_from_shape: Pose,
    /// The shape.
    pub shape: Shape,
}

/// A URDF link.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Link name.
    pub name: String,
    /// Mass properties; `None` when the URDF gives no `<inertial>`.
    pub inertial: Option<Inertial>,
    /// Visual shapes.
    pub visuals: Vec<Visual>,
    /// Collision shapes.
    pub collisions: Vec<Collision>,
    /// Friction coefficient from `<gazebo reference="link"><mu1>`/`<mu2>` (the smaller one).
    pub friction: Option<f32>,
    /// Contact stiffness (N/m) from `<gazebo reference="link"><kp>`: its contacts give way by
    /// the robot's weight over this before they push (ODE's soft contact, where the stiffer
    /// contacts beside it carry the load); `None`: as hard as rapier holds contacts.
    pub contact_kp_n_per_m: Option<f32>,
}

/// Kind of a URDF joint that rover simulates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// Rigidly welded.
    Fixed,
    /// Rotation about the axis without limits.
    Continuous,
    /// Rotation about the axis between limits (rad).
    Revolute {
        /// Lower limit (rad).
        lower_rad: f32,
        /// Upper limit (rad).
        upper_rad: f32,
    },
    /// Translation along the axis between limits (m).
    Prismatic {
        /// Lower limit (m).
        lower_m: f32,
        /// Upper limit (m).
        upper_m: f32,
    },
    /// No constraint: the child moves freely.
    Floating,
}

/// A link of a [`RobotModel`]: its place in [`RobotModel::links`] (URDF order), which is also
/// its place in every per-link list (link poses). Made only by the model that owns the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LinkId(pub(crate) usize);

impl LinkId {
    /// Position in [`RobotModel::links`] and in per-link lists.
    pub fn index(self) -> usize {
        self.0
    }
}

/// A joint of a [`RobotModel`]: its place in [`RobotModel::joints`] (URDF order). Made only
/// by the model that owns the joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId(pub(crate) usize);

impl JointId {
    /// Position in [`RobotModel::joints`] and in per-joint lists.
    pub fn index(self) -> usize {
        self.0
    }
}

/// A URDF joint between two links of its [`RobotModel`].
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Kind and limits.
    pub kind: JointKind,
    /// Parent link.
    pub parent: LinkId,
    /// Child link.
    pub child: LinkId,
    /// Joint origin: the child link frame expressed in the parent link frame at zero position.
    pub parent_from_child: Pose,
    /// Unit axis in the joint (= child link) frame.
    pub axis: Vec3,
    /// Viscous damping from `<dynamics damping>` (N m s/rad, or N s/m for a prismatic joint).
    pub damping: f32,
    /// Coulomb friction from `<dynamics friction>` (N m, or N for a prismatic joint).
    pub friction: f32,
    /// `<limit effort>`: the most torque (N m) or force (N) an actuator may apply; `None`
    /// when the URDF gives none.
    pub effort_limit: Option<f32>,
    /// `<limit velocity>`: the fastest the joint may be driven (rad/s or m/s); `None` when
    /// the URDF gives none.
    pub velocity_limit: Option<f32>,
    /// `<mimic>`: this joint follows another one.
    pub mimic: Option<Mimic>,
}

/// A URDF `<mimic joint multiplier offset>`: position = multiplier x the other joint's + offset.
#[derive(Debug, Clone, PartialEq)]
pub struct Mimic {
    /// The joint followed.
    pub joint: JointId,
    /// Factor on the followed joint's position.
    pub multiplier: f32,
    /// Added to the product (rad or m).
    pub offset: f32,
}

impl Joint {
    /// Whether the joint moves (continuous, revolute or prismatic): the ones an actuator can
    /// drive and `/joint_states` lists.
    pub fn is_moving(&self) -> bool {
        matches!(
            self.kind,
            JointKind::Continuous | JointKind::Revolute { .. } | JointKind::Prismatic { .. }
        )
    }

    /// The position limits (rad or m), for revolute and prismatic joints.
    pub fn position_limits(&self) -> Option<(f32, f32)> {
        match self.kind {
            JointKind::Revolute {
                lower_rad,
                upper_rad,
            } => Some((lower_rad, upper_rad)),
            JointKind::Prismatic { lower_m, upper_m } => Some((lower_m, upper_m)),
            _ => None,
        }
    }
}

/// A robot loaded from URDF.
#[derive(Debug, Clone)]
pub struct RobotModel {
    /// `<robot name>`.
    pub name: String,
    /// The file it came from.
    pub source: PathBuf,
    /// Links in file order.
    pub links: Vec<Link>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// The root link (the one that is no joint's child).
    pub root: LinkId,
    /// The `libgazebo_ros_diff_drive.so` plugin, if present.
    pub diff_drive: Option<DiffDriveConfig>,
    /// Camera sensors (`<sensor type="camera">`).
    pub cameras: Vec<CameraConfig>,
    /// 2D laser scanners (`<sensor type="ray">` with one vertical sample).
    pub lasers: Vec<LaserConfig>,
    /// 3D lidars (`<sensor type="ray">` with several vertical samples).
    pub lidars: Vec<LidarConfig>,
    /// IMUs (`<sensor type="imu">` with `libgazebo_ros_imu_sensor.so`, or the model plugin
    /// `libgazebo_ros_imu.so`).
    pub imus: Vec<ImuConfig>,
    /// Ground-truth pose publishers (`libgazebo_ros_p3d.so`).
    pub p3ds: Vec<P3dConfig>,
    /// GPS receivers (`libhector_gazebo_ros_gps.so`).
    pub gpss: Vec<GpsConfig>,
    /// Bumpers (`<sensor type="contact">` with `libgazebo_ros_bumper.so`).
    pub bumpers: Vec<BumperConfig>,
    /// Gazebo sensors and plugins in the file that rover does not simulate (contact sensors,
    /// Gazebo's own GPS sensor, ...).
    pub not_simulated: Vec<String>,
    /// gz-sim's JointStatePublisher system: where the joints' states go (`None`: gazebo_ros's
    /// `/joint_states`).
    pub joint_state_publisher: Option<JointStatePublisherConfig>,
    /// `<transmission>`s: which joints an actuator drives, through which ros_control
    /// hardware interface.
    pub transmissions: Vec<Transmission>,
    /// The `libgazebo_ros_control.so` plugin, if present.
    pub ros_control: Option<RosControlPlugin>,
    /// The controllers file the robot runs (`--controllers`, a world's `controllers`): which
    /// controller drives which joint. `None`: every actuated joint holds its pose and takes
    /// commands by joint name.
    pub controllers: Option<ControllerConfig>,
    /// The URDF text the model was read from (xacro already expanded): what ROS tools expect in
    /// `/robot_description`.
    pub description: String,
}

impl RobotModel {
    /// Drives the robot's wheels `spec` names like gazebo_ros_diff_drive (replacing a drive
    /// plugin from the URDF). Separation and diameter default to what the URDF says: the
    /// distance between the two joints and the left wheel's collision cylinder or sphere.
    pub fn set_drive(&mut self, spec: &DriveSpec) -> Result<()> {
        let setup =
            |m: String| SimError::Setup(format!("[robot.drive] for \"{}\": {m}", self.name));
        let joint = |name: &str| {
            self.joint_id(name).ok_or_else(|| {
                setup(format!(
                    "no joint \"{name}\"; joints in this robot: {}",
                    names(self.joints.iter().map(|j| &j.name))
                ))
            })
        };
        let (left, right) = (joint(&spec.left_joint)?, joint(&spec.right_joint)?);
        let poses = self.root_from_links();
        let separation = match spec.wheel_separation_m {
            Some(s) => s,
            None => f64::from(
                poses[self.joint(left).child.index()]
                    .translation
                    .distance(poses[self.joint(right).child.index()].translation),
            ),
        };
        let diameter = match spec.wheel_diameter_m {
            Some(d) => d,
            None => {
                let wheel = self.link(self.joint(left).child);
                let radius = wheel.collisions.iter().find_map(|c| match c.shape {
                    Shape::Cylinder { radius_m, .. } | Shape::Sphere { radius_m } => {
                        Some(f64::from(radius_m))
                    }
                    _ => None,
                });
                2.0 * radius.ok_or_else(|| {
                    setup(format!(
                        "cannot tell the diameter of wheel link \"{}\" (no cylinder or sphere collision); give wheel_diameter_m",
                        wheel.name
                    ))
                })?
            }
        };
        for (what, v) in [
            ("wheel_separation_m", separation),
            ("wheel_diameter_m", diameter),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(setup(format!(
                    "{what} is {v}; expected a positive number of metres"
                )));
            }
        }
        let mut config = DiffDriveConfig {
            name: "rover_drive".to_owned(),
            left_joint: spec.left_joint.clone(),
            right_joint: spec.right_joint.clone(),
            wheel_separation_m: separation,
            wheel_diameter_m: diameter,
            ..DiffDriveConfig::default()
        };
        if let Some(t) = spec.wheel_torque_nm {
            config.wheel_torque_nm = t;
        }
        if let Some(a) = spec.wheel_acceleration_mps2 {
            if !(a.is_finite() && a >= 0.0) {
                return Err(setup(format!(
                    "wheel_acceleration_mps2 is {a}; expected 0 (unlimited) or a positive number of m/s^2"
                )));
            }
            config.wheel_acceleration_mps2 = a;
        }
        tracing::info!(
            "{}: driving joints \"{}\" and \"{}\" (wheel separation {separation:.3} m, diameter {diameter:.3} m)",
            self.name,
            spec.left_joint,
            spec.right_joint
        );
        self.diff_drive = Some(config);
        self.validate_plugins(&self.source.clone())
    }

    /// Makes the camera sensor called `name` (its `<sensor name>` or plugin `cameraName`) the
    /// one rover renders (the first); the others stay listed after it.
    pub fn select_camera(&mut self, name: &str) -> Result<()> {
        let Some(i) = self
            .cameras
            .iter()
            .position(|c| c.name == name || c.camera_name == name)
        else {
            return Err(SimError::Setup(format!(
                "robot \"{}\" has no camera \"{name}\"; its cameras: {}",
                self.name,
                names(self.cameras.iter().map(|c| &c.name))
            )));
        };
        let chosen = self.cameras.remove(i);
        self.cameras.insert(0, chosen);
        Ok(())
    }

    /// Whether the robot is bolted to the world: its root link is called `world`, which
    /// Gazebo anchors (most arm descriptions, UR5 among them).
    pub fn is_anchored(&self) -> bool {
        self.link(self.root).name == "world"
    }

    /// The joints an actuator drives (joint order): those with a `<transmission>`, and every
    /// revolute and prismatic joint (held in place when nothing else commands it), except the
    /// drive's wheels and `<mimic>` joints. Continuous joints without a transmission (casters)
    /// stay passive.
    pub fn actuated_joints(&self) -> Vec<JointId> {
        let wheels: Vec<&str> = self.diff_drive.as_ref().map_or(Vec::new(), |d| {
            [&d.left_joint, &d.right_joint]
                .into_iter()
                .chain(&d.extra_left_joints)
                .chain(&d.extra_right_joints)
                .map(String::as_str)
                .collect()
        });
        self.joints
            .iter()
            .enumerate()
            .filter(|(_, j)| {
                j.is_moving()
                    && j.mimic.is_none()
                    && !wheels.contains(&j.name.as_str())
                    && (matches!(
                        j.kind,
                        JointKind::Revolute { .. } | JointKind::Prismatic { .. }
                    ) || self.transmissions.iter().any(|t| t.joint == j.name))
            })
            .map(|(i, _)| JointId(i))
            .collect()
    }

    /// The link called `name`.
    pub fn link_id(&self, name: &str) -> Option<LinkId> {
        self.links.iter().position(|l| l.name == name).map(LinkId)
    }

    /// The joint called `name`.
    pub fn joint_id(&self, name: &str) -> Option<JointId> {
        self.joints.iter().position(|j| j.name == name).map(JointId)
    }

    /// A link of this model.
    pub fn link(&self, id: LinkId) -> &Link {
        &self.links[id.0]
    }

    /// A joint of this model.
    pub fn joint(&self, id: JointId) -> &Joint {
        &self.joints[id.0]
    }

    /// Every joint with its id, in URDF order.
    pub fn joint_ids(&self) -> impl Iterator<Item = (JointId, &Joint)> {
        self.joints.iter().enumerate().map(|(i, j)| (JointId(i), j))
    }

    /// Every link with its id, in URDF order.
    pub fn link_ids(&self) -> impl Iterator<Item = (LinkId, &Link)> {
        self.links.iter().enumerate().map(|(i, l)| (LinkId(i), l))
    }

    /// Pose of every link in the root link's frame with all joints at zero.
    pub fn root_from_links(&self) -> Vec<Pose> {
        let mut poses = vec![None; self.links.len()];
        poses[self.root.0] = Some(Pose::IDENTITY);
        let mut pending = true;
        while pending {
            pending = false;
            for j in &self.joints {
                if let (Some(parent), None) = (poses[j.parent.0], poses[j.child.0]) {
                    poses[j.child.0] = Some(parent * j.parent_from_child);
                    pending = true;
                }
            }
        }
        poses.into_iter().map(|p| p.unwrap_or_default()).collect()
    }

    pub(crate) fn validate_plugins(&self, path: &Path) -> Result<()> {
        if let Some(dd) = &self.diff_drive {
            let file = dd.plugin.filename();
            let (left, right) = (
                dd.plugin.joint_parameter(false),
                dd.plugin.joint_parameter(true),
            );
            let (rear_left, rear_right) = match dd.plugin {
                crate::model::DrivePlugin::GazeboRos => ("leftRearJoint", "rightRearJoint"),
                crate::model::DrivePlugin::GzSim => (left, right),
            };
            let extras = dd
                .extra_left_joints
                .iter()
                .map(|j| (rear_left, j))
                .chain(dd.extra_right_joints.iter().map(|j| (rear_right, j)));
            for (role, name) in [(left, &dd.left_joint), (right, &dd.right_joint)]
                .into_iter()
                .chain(extras)
            {
                let Some(id) = self.joint_id(name) else {
                    return Err(SimError::invalid(
                        path,
                        dd.line,
                        format!(
                            "<plugin filename=\"{file}\"> <{role}>{name}</{role}>: no such joint; joints in this robot: {}",
                            names(self.joints.iter().map(|j| &j.name))
                        ),
                    ));
                };
                let joint = self.joint(id);
                if !matches!(
                    joint.kind,
                    JointKind::Continuous | JointKind::Revolute { .. }
                ) {
                    return Err(SimError::invalid(
                        path,
                        dd.line,
                        format!(
                            "<plugin filename=\"{file}\"> <{role}>{name}</{role}>: the joint is {}, expected a continuous or revolute wheel joint",
                            kind_name(&joint.kind)
                        ),
                    ));
                }
            }
            if dd.left_joint == dd.right_joint {
                return Err(SimError::invalid(
                    path,
                    dd.line,
                    format!(
                        "<plugin filename=\"{file}\">: {left} and {right} are both \"{}\"; expected two different wheel joints",
                        dd.left_joint
                    ),
                ));
            }
        }
        for (what, link, line) in self.sensor_links() {
            if self.link_id(link).is_none() {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "{what}: no such link; links in this robot: {}",
                        names(self.links.iter().map(|l| &l.name))
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Every link a sensor names: what names it (for the error), the link, the line.
    fn sensor_links(&self) -> Vec<(String, &str, Option<u32>)> {
        let mut out = Vec::new();
        for l in &self.lasers {
            let what = format!("<gazebo reference=\"{}\"> <sensor type=\"ray\">", l.link);
            out.push((what, l.link.as_str(), l.line));
        }
        for l in &self.lidars {
            let what = format!(
                "<gazebo reference=\"{}\"> <sensor type=\"ray\">",
                l.rays.link
            );
            out.push((what, l.rays.link.as_str(), l.rays.line));
        }
        for i in &self.imus {
            let element = match i.plugin {
                ImuPlugin::Sensor => "<sensor type=\"imu\">",
                ImuPlugin::Model => "<plugin filename=\"libgazebo_ros_imu.so\"> <bodyName>",
            };
            out.push((format!("{element} \"{}\"", i.link), i.link.as_str(), i.line));
        }
        for p in &self.p3ds {
            let links = std::iter::once(("bodyName", &p.link))
                .chain(p.reference_link.iter().map(|l| ("frameName", l)));
            for (element, link) in links {
                let what =
                    format!("<plugin filename=\"libgazebo_ros_p3d.so\"> <{element}> \"{link}\"");
                out.push((what, link.as_str(), p.line));
            }
        }
        for g in &self.gpss {
            let what = format!(
                "<plugin filename=\"libhector_gazebo_ros_gps.so\"> <bodyName> \"{}\"",
                g.link
            );
            out.push((what, g.link.as_str(), g.line));
        }
        for b in &self.bumpers {
            let what = format!(
                "<gazebo reference=\"{}\"> <sensor type=\"contact\">",
                b.link
            );
            out.push((what, b.link.as_str(), b.line));
            if let Some(frame) = &b.reference_link {
                let what = format!(
                    "<plugin filename=\"libgazebo_ros_bumper.so\"> <frameName> \"{frame}\""
                );
                out.push((what, frame.as_str(), b.line));
            }
        }
        for c in &self.cameras {
            let what = format!("<gazebo reference=\"{}\"> <sensor type=\"camera\">", c.link);
            out.push((what, c.link.as_str(), c.line));
        }
        out
    }
}

fn kind_name(kind: &JointKind) -> &'static str {
    match kind {
        JointKind::Fixed => "fixed",
        JointKind::Continuous => "continuous",
        JointKind::Revolute { .. } => "revolute",
        JointKind::Prismatic { .. } => "prismatic",
        JointKind::Floating => "floating",
    }
}
