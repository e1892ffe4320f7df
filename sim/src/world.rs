//! World files: a small, strict TOML format (documented in docs/WORLDS.md).

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{Result, SimError};
use crate::geometry::{Pose, Rgba, pose_from_position_yaw};
use crate::tomlfile;

/// Default physics step rate (Hz); see docs/WORLDS.md for why.
pub const DEFAULT_STEP_HZ: f64 = 200.0;

/// A loaded and validated world.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// World name (defaults to the file stem).
    pub name: String,
    /// The file it came from.
    pub source: PathBuf,
    /// Free-text description.
    pub description: String,
    /// Where and which robot to spawn.
    pub robot: RobotSpawn,
    /// Physics settings.
    pub physics: Physics,
    /// The ground plane.
    pub ground: Ground,
    /// Boxes, cylinders, spheres and walls.
    pub objects: Vec<Object>,
    /// People standing in the world.
    pub people: Vec<Person>,
    /// Models of a Gazebo SDF world (empty for TOML worlds).
    pub models: Vec<crate::sdf::Model>,
}

/// Robot spawn settings (`[robot]`).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotSpawn {
    /// URDF file, resolved against the world file's folder; `None` = the app's default robot.
    pub urdf: Option<PathBuf>,
    /// Spawn position on the ground (x, y in m).
    pub position_m: [f64; 2],
    /// Spawn heading (rad, counter-clockwise from +x).
    pub yaw_rad: f64,
    /// `xacro_args`: `$(arg NAME)` values when the robot is a xacro file.
    pub xacro_args: std::collections::BTreeMap<String, String>,
    /// `[robot.drive]`: how to drive a robot whose URDF names no drive plugin.
    pub drive: Option<DriveSpec>,
}

/// Wheels to drive like gazebo_ros_diff_drive, for a robot whose URDF has no drive plugin
/// (`[robot.drive]`, or `--drive LEFT,RIGHT`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// The left wheel's joint.
    pub left_joint: String,
    /// The right wheel's joint.
    pub right_joint: String,
    /// Distance between the wheels (m); default: between the two joints' origins.
    #[serde(default)]
    pub wheel_separation_m: Option<f64>,
    /// Wheel diameter (m); default: from the left wheel's collision cylinder or sphere.
    #[serde(default)]
    pub wheel_diameter_m: Option<f64>,
    /// Motor torque limit (N m); default gazebo_ros_diff_drive's 5.
    #[serde(default)]
    pub wheel_torque_nm: Option<f64>,
}

/// Physics settings (`[physics]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Physics {
    /// Fixed step rate (Hz).
    pub step_hz: f64,
    /// Gravity (m/s^2, world frame).
    pub gravity_mps2: [f64; 3],
    /// Solver iterations per step.
    pub solver_iterations: usize,
}

/// The ground (`[ground]`): a flat square centred on the origin, top at z = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Ground {
    /// Side lengths along x and y (m).
    pub size_m: [f64; 2],
    /// Friction coefficient.
    pub friction: f32,
    /// Main colour.
    pub color: Rgba,
    /// Second colour of the checker texture.
    pub checker_color: Rgba,
    /// Checker square size (m).
    pub checker_size_m: f64,
}

/// Shape of a world object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObjectShape {
    /// Box with full side lengths (m).
    Box {
        /// Side lengths along the object's x, y, z (m).
        size_m: [f64; 3],
    },
    /// Upright cylinder.
    Cylinder {
        /// Radius (m).
        radius_m: f64,
        /// Height (m).
        length_m: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius (m).
        radius_m: f64,
    },
}

/// A static or dynamic object.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name (unique within the world).
    pub name: String,
    /// Shape.
    pub shape: ObjectShape,
    /// Centre position (m, world frame).
    pub position_m: [f64; 3],
    /// Heading about +z (rad).
    pub yaw_rad: f64,
    /// Colour.
    pub color: Rgba,
    /// Mass (kg); `None` for a static object.
    pub mass_kg: Option<f64>,
    /// Friction coefficient.
    pub friction: f32,
}

/// Physics step rates rover accepts (Hz), from world files and `--physics-hz` alike.
pub const STEP_HZ_RANGE: std::ops::RangeInclusive<f64> = 50.0..=10_000.0;

/// Checks a physics step rate against [`STEP_HZ_RANGE`]; the error says what was expected.
pub fn check_step_hz(step_hz: f64) -> std::result::Result<(), String> {
    if step_hz.is_finite() && STEP_HZ_RANGE.contains(&step_hz) {
        Ok(())
    } else {
        Err(format!(
            "expected a physics step rate of {}..={} Hz (default {DEFAULT_STEP_HZ}), found {step_hz}",
            STEP_HZ_RANGE.start(),
            STEP_HZ_RANGE.end()
        ))
    }
}

/// A person (`[[person]]`): a standing human figure, an obstacle for physics.
#[derive(Debug, Clone, PartialEq)]
pub struct Person {
    /// Name (unique within the world).
    pub name: String,
    /// Position of the feet on the ground (x, y in m).
    pub position_m: [f64; 2],
    /// Facing direction (rad, counter-clockwise from +x).
    pub heading_rad: f64,
    /// Standing height (m).
    pub height_m: f64,
    /// Shirt colour.
    pub shirt_color: Rgba,
    /// Trousers colour.
    pub trousers_color: Rgba,
    /// Skin colour.
    pub skin_color: Rgba,
    /// Hair colour.
    pub hair_color: Rgba,
    /// A walk: `position_m`, then each waypoint, then back to `position_m`, repeated.
    pub walk: Option<Walk>,
}

/// A person's walk: a path at a constant speed, closed and repeated (the default) or walked
/// once.
#[derive(Debug, Clone, PartialEq)]
pub struct Walk {
    /// Waypoints after the start position (m, world frame).
    pub waypoints_m: Vec<[f64; 2]>,
    /// Walking speed (m/s).
    pub speed_mps: f64,
    /// Back to the start and round again (true), or stop at the last waypoint (false).
    pub repeat: bool,
    /// Stand at the start this long before walking (s).
    pub start_after_s: f64,
}

impl Object {
    /// Where the object's centre is, turned by its yaw.
    pub fn world_from_object(&self) -> Pose {
        pose_from_position_yaw(self.position_m, self.yaw_rad)
    }
}

impl Person {
    /// A 1.75 m person in rover's default clothes, standing at `position_m` facing
    /// `heading_rad`.
    pub fn standing(name: impl Into<String>, position_m: [f64; 2], heading_rad: f64) -> Self {
        Self {
            name: name.into(),
            position_m,
            heading_rad,
            height_m: default_person_height(),
            shirt_color: Rgba::rgb(0.75, 0.15, 0.12),
            trousers_color: Rgba::rgb(0.15, 0.2, 0.35),
            skin_color: Rgba::rgb(0.87, 0.67, 0.53),
            hair_color: Rgba::rgb(0.2, 0.13, 0.08),
            walk: None,
        }
    }

    /// The person's pose at sim time `t_s`: feet on the ground, x facing where they look.
    pub fn world_from_person(&self, t_s: f64) -> Pose {
        let (x, y, heading) = self.pose_at(t_s);
        pose_from_position_yaw([x, y, 0.0], heading)
    }

    /// Where the person is at sim time `t_s`: (x m, y m, heading rad). Standing people stay
    /// put; walking people follow their closed path at their speed, facing where they go.
    pub fn pose_at(&self, t_s: f64) -> (f64, f64, f64) {
        let [x0, y0] = self.position_m;
        let Some(walk) = &self.walk else {
            return (x0, y0, self.heading_rad);
        };
        let n = walk.waypoints_m.len() + 1;
        let corner = |i: usize| {
            if i.is_multiple_of(n) {
                self.position_m
            } else {
                walk.waypoints_m[i % n - 1]
            }
        };
        // Legs: corner i to corner i + 1; a repeated walk closes the loop, a single one does not.
        let legs = if walk.repeat { n } else { n - 1 };
        let leg = |i: usize| {
            let (a, b) = (corner(i), corner(i + 1));
            (a, b, (b[0] - a[0]).hypot(b[1] - a[1]))
        };
        let length: f64 = (0..legs).map(|i| leg(i).2).sum();
        if length <= 1e-9 {
            return (x0, y0, self.heading_rad);
        }
        let walked = walk.speed_mps * (t_s - walk.start_after_s).max(0.0);
        if t_s < walk.start_after_s {
            let (a, b, _) = leg(0);
            return (x0, y0, (b[1] - a[1]).atan2(b[0] - a[0]));
        }
        let mut s = if walk.repeat {
            walked.rem_euclid(length)
        } else {
            walked.min(length)
        };
        for i in 0..legs {
            let (a, b, l) = leg(i);
            if s <= l || i + 1 == legs {
                let f = if l > 0.0 { (s / l).min(1.0) } else { 0.0 };
                let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
                return (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, heading);
            }
            s -= l;
        }
        (x0, y0, self.heading_rad)
    }

    /// Radius of the upright capsule that stands in for the person in physics (m).
    pub fn body_radius_m(&self) -> f64 {
        0.13 * self.height_m / 1.75
    }
}

impl World {
    /// Loads a world file: TOML, or a Gazebo SDF world (`.world`, `.sdf`) with `model://`
    /// models found through `GAZEBO_MODEL_PATH`.
    pub fn load(path: &Path) -> Result<Self> {
        Self::load_with(path, &crate::resource::ResourcePaths::from_env())
    }

    /// Loads a world file; `resources` finds an SDF world's `model://` models and meshes.
    pub fn load_with(path: &Path, resources: &crate::resource::ResourcePaths) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("world" | "sdf")) {
            return crate::sdf::load_world(path, resources);
        }
        let raw: RawWorld = tomlfile::load_toml(path)?;
        raw.into_world(path)
    }

    /// Parses world TOML text; `path` is used in messages and to resolve the robot's URDF.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        let raw: RawWorld = tomlfile::parse_toml(text, path)?;
        raw.into_world(path)
    }

    /// An empty flat world (ground only, every setting at its default), for tests and calibration.
    pub fn flat() -> Result<Self> {
        Self::from_str("name = \"flat\"\n", Path::new("<built-in flat world>"))
    }
}

/// A TOML world as written, before validation: for files that embed a world (rover's scenario
/// files hold one under `[world]`). Deserialise it with serde, then [`WorldFile::into_world`].
#[derive(Debug)]
pub struct WorldFile(RawWorld);

impl<'de> Deserialize<'de> for WorldFile {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        RawWorld::deserialize(d).map(WorldFile)
    }
}

impl WorldFile {
    /// Validates it into a [`World`]; `path` is the file it came from (for messages and for
    /// resolving the robot's URDF relative to it).
    pub fn into_world(self, path: &Path) -> Result<World> {
        self.0.into_world(path)
    }
}

// ---- Raw (file) representation -------------------------------------------------------------

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorld {
    name: Option<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    robot: RawRobot,
    #[serde(default)]
    physics: RawPhysics,
    #[serde(default)]
    ground: RawGround,
    #[serde(default, rename = "box")]
    boxes: Vec<RawBox>,
    #[serde(default, rename = "cylinder")]
    cylinders: Vec<RawCylinder>,
    #[serde(default, rename = "sphere")]
    spheres: Vec<RawSphere>,
    #[serde(default, rename = "wall")]
    walls: Vec<RawWall>,
    #[serde(default, rename = "person")]
    people: Vec<RawPerson>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    urdf: Option<PathBuf>,
    #[serde(default)]
    position_m: [f64; 2],
    #[serde(default)]
    yaw_deg: f64,
    #[serde(default)]
    xacro_args: std::collections::BTreeMap<String, String>,
    #[serde(default)]
    drive: Option<DriveSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawPhysics {
    step_hz: f64,
    gravity_mps2: [f64; 3],
    solver_iterations: usize,
}

impl Default for RawPhysics {
    fn default() -> Self {
        Self {
            step_hz: DEFAULT_STEP_HZ,
            gravity_mps2: [0.0, 0.0, -9.81],
            solver_iterations: 4,
        }
    }
}

impl From<RawPhysics> for Physics {
    fn from(p: RawPhysics) -> Self {
        Self {
            step_hz: p.step_hz,
            gravity_mps2: p.gravity_mps2,
            solver_iterations: p.solver_iterations,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawGround {
    size_m: [f64; 2],
    friction: f64,
    color: String,
    checker_color: String,
    checker_size_m: f64,
}

impl Default for RawGround {
    fn default() -> Self {
        Self {
            size_m: [60.0, 60.0],
            friction: 1.0,
            color: "#7d8a6a".to_owned(),
            checker_color: "#6f7c5d".to_owned(),
            checker_size_m: 1.0,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBox {
    name: Option<String>,
    size_m: [f64; 3],
    position_m: Vec<f64>,
    #[serde(default)]
    yaw_deg: f64,
    color: Option<String>,
    mass_kg: Option<f64>,
    friction: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCylinder {
    name: Option<String>,
    radius_m: f64,
    length_m: f64,
    position_m: Vec<f64>,
    color: Option<String>,
    mass_kg: Option<f64>,
    friction: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSphere {
    name: Option<String>,
    radius_m: f64,
    position_m: Vec<f64>,
    color: Option<String>,
    mass_kg: Option<f64>,
    friction: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWall {
    name: Option<String>,
    from_m: [f64; 2],
    to_m: [f64; 2],
    #[serde(default = "default_wall_height")]
    height_m: f64,
    #[serde(default = "default_wall_thickness")]
    thickness_m: f64,
    color: Option<String>,
    friction: Option<f64>,
}

fn default_wall_height() -> f64 {
    1.0
}

fn default_wall_thickness() -> f64 {
    0.1
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPerson {
    name: Option<String>,
    position_m: [f64; 2],
    #[serde(default)]
    heading_deg: f64,
    #[serde(default = "default_person_height")]
    height_m: f64,
    shirt_color: Option<String>,
    trousers_color: Option<String>,
    skin_color: Option<String>,
    hair_color: Option<String>,
    #[serde(default)]
    waypoints_m: Vec<[f64; 2]>,
    speed_mps: Option<f64>,
    #[serde(default = "default_repeat")]
    repeat: bool,
    #[serde(default)]
    start_after_s: f64,
}

fn default_repeat() -> bool {
    true
}

fn default_person_height() -> f64 {
    1.75
}

/// Collects validation problems as `key: message` pairs.
struct Checker<'a> {
    path: &'a Path,
}

impl Checker<'_> {
    fn fail(&self, key: &str, message: impl std::fmt::Display) -> SimError {
        SimError::invalid(self.path, None, format!("at `{key}`: {message}"))
    }

    fn finite(&self, key: &str, values: &[f64]) -> Result<()> {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.fail(key, format!("expected finite numbers, found {values:?}")))
        }
    }

    fn positive(&self, key: &str, values: &[f64], unit: &str) -> Result<()> {
        self.finite(key, values)?;
        if values.iter().all(|v| *v > 0.0) {
            Ok(())
        } else {
            Err(self.fail(
                key,
                format!("expected positive numbers ({unit}), found {values:?}"),
            ))
        }
    }

    fn color(&self, key: &str, text: Option<&str>, default: Rgba) -> Result<Rgba> {
        match text {
            None => Ok(default),
            Some(t) => Rgba::from_hex(t).ok_or_else(|| {
                self.fail(
                    key,
                    format!(
                        "expected a colour like \"#a0522d\" (#rrggbb or #rrggbbaa), found \"{t}\""
                    ),
                )
            }),
        }
    }

    fn friction(&self, key: &str, value: Option<f64>) -> Result<f32> {
        let f = value.unwrap_or(0.8);
        if f.is_finite() && f >= 0.0 {
            Ok(f as f32)
        } else {
            Err(self.fail(
                key,
                format!("expected a friction coefficient >= 0, found {f}"),
            ))
        }
    }

    fn mass(&self, key: &str, value: Option<f64>) -> Result<Option<f64>> {
        match value {
            Some(m) if !(m.is_finite() && m > 0.0) => Err(self.fail(
                key,
                format!("expected a positive mass in kg (omit it for a static object), found {m}"),
            )),
            other => Ok(other),
        }
    }

    /// `[x, y]` (resting on the ground, z = `half_height`) or `[x, y, z]`.
    fn position(&self, key: &str, values: &[f64], half_height: f64) -> Result<[f64; 3]> {
        self.finite(key, values)?;
        match *values {
            [x, y] => Ok([x, y, half_height]),
            [x, y, z] => Ok([x, y, z]),
            _ => Err(self.fail(
                key,
                format!(
                    "expected [x, y] (resting on the ground) or [x, y, z] in metres, found {} values",
                    values.len()
                ),
            )),
        }
    }
}

impl RawGround {
    fn into_ground(self, path: &Path) -> Result<Ground> {
        let c = Checker { path };
        c.positive("ground.size_m", &self.size_m, "m")?;
        c.positive("ground.checker_size_m", &[self.checker_size_m], "m")?;
        let color = c.color("ground.color", Some(&self.color), Rgba::rgb(0.5, 0.5, 0.5))?;
        Ok(Ground {
            size_m: self.size_m,
            friction: c.friction("ground.friction", Some(self.friction))?,
            color,
            checker_color: c.color("ground.checker_color", Some(&self.checker_color), color)?,
            checker_size_m: self.checker_size_m,
        })
    }
}

impl RawWorld {
    fn into_world(self, path: &Path) -> Result<World> {
        let c = Checker { path };
        let base_dir = path.parent().unwrap_or(Path::new("."));

        c.finite("robot.position_m", &self.robot.position_m)?;
        c.finite("robot.yaw_deg", &[self.robot.yaw_deg])?;
        let robot = RobotSpawn {
            urdf: self.robot.urdf.map(|u| base_dir.join(u)),
            position_m: self.robot.position_m,
            yaw_rad: self.robot.yaw_deg.to_radians(),
            xacro_args: self.robot.xacro_args,
            drive: self.robot.drive,
        };

        c.positive("physics.step_hz", &[self.physics.step_hz], "Hz")?;
        if let Err(message) = check_step_hz(self.physics.step_hz) {
            return Err(c.fail("physics.step_hz", message));
        }
        c.finite("physics.gravity_mps2", &self.physics.gravity_mps2)?;
        if !(1..=100).contains(&self.physics.solver_iterations) {
            return Err(c.fail(
                "physics.solver_iterations",
                format!("expected 1..=100, found {}", self.physics.solver_iterations),
            ));
        }

        let ground = self.ground.into_ground(path)?;

        let mut objects = Vec::new();
        for (i, b) in self.boxes.into_iter().enumerate() {
            let key = |field: &str| format!("box[{i}].{field}");
            c.positive(&key("size_m"), &b.size_m, "m")?;
            c.finite(&key("yaw_deg"), &[b.yaw_deg])?;
            objects.push(Object {
                name: b.name.unwrap_or_else(|| format!("box_{i}")),
                position_m: c.position(&key("position_m"), &b.position_m, b.size_m[2] / 2.0)?,
                shape: ObjectShape::Box { size_m: b.size_m },
                yaw_rad: b.yaw_deg.to_radians(),
                color: c.color(
                    &key("color"),
                    b.color.as_deref(),
                    Rgba::rgb(0.63, 0.42, 0.25),
                )?,
                mass_kg: c.mass(&key("mass_kg"), b.mass_kg)?,
                friction: c.friction(&key("friction"), b.friction)?,
            });
        }
        for (i, cy) in self.cylinders.into_iter().enumerate() {
            let key = |field: &str| format!("cylinder[{i}].{field}");
            c.positive(&key("radius_m"), &[cy.radius_m], "m")?;
            c.positive(&key("length_m"), &[cy.length_m], "m")?;
            objects.push(Object {
                name: cy.name.unwrap_or_else(|| format!("cylinder_{i}")),
                position_m: c.position(&key("position_m"), &cy.position_m, cy.length_m / 2.0)?,
                shape: ObjectShape::Cylinder {
                    radius_m: cy.radius_m,
                    length_m: cy.length_m,
                },
                yaw_rad: 0.0,
                color: c.color(
                    &key("color"),
                    cy.color.as_deref(),
                    Rgba::rgb(0.8, 0.45, 0.1),
                )?,
                mass_kg: c.mass(&key("mass_kg"), cy.mass_kg)?,
                friction: c.friction(&key("friction"), cy.friction)?,
            });
        }
        for (i, s) in self.spheres.into_iter().enumerate() {
            let key = |field: &str| format!("sphere[{i}].{field}");
            c.positive(&key("radius_m"), &[s.radius_m], "m")?;
            objects.push(Object {
                name: s.name.unwrap_or_else(|| format!("sphere_{i}")),
                position_m: c.position(&key("position_m"), &s.position_m, s.radius_m)?,
                shape: ObjectShape::Sphere {
                    radius_m: s.radius_m,
                },
                yaw_rad: 0.0,
                color: c.color(&key("color"), s.color.as_deref(), Rgba::rgb(0.85, 0.2, 0.2))?,
                mass_kg: c.mass(&key("mass_kg"), s.mass_kg)?,
                friction: c.friction(&key("friction"), s.friction)?,
            });
        }
        for (i, w) in self.walls.into_iter().enumerate() {
            let key = |field: &str| format!("wall[{i}].{field}");
            c.finite(&key("from_m"), &w.from_m)?;
            c.finite(&key("to_m"), &w.to_m)?;
            c.positive(&key("height_m"), &[w.height_m], "m")?;
            c.positive(&key("thickness_m"), &[w.thickness_m], "m")?;
            let (dx, dy) = (w.to_m[0] - w.from_m[0], w.to_m[1] - w.from_m[1]);
            let length = dx.hypot(dy);
            if length < 1e-3 {
                return Err(c.fail(
                    &key("to_m"),
                    "expected a wall end point different from from_m",
                ));
            }
            objects.push(Object {
                name: w.name.unwrap_or_else(|| format!("wall_{i}")),
                shape: ObjectShape::Box {
                    size_m: [length, w.thickness_m, w.height_m],
                },
                position_m: [
                    (w.from_m[0] + w.to_m[0]) / 2.0,
                    (w.from_m[1] + w.to_m[1]) / 2.0,
                    w.height_m / 2.0,
                ],
                yaw_rad: dy.atan2(dx),
                color: c.color(
                    &key("color"),
                    w.color.as_deref(),
                    Rgba::rgb(0.85, 0.83, 0.78),
                )?,
                mass_kg: None,
                friction: c.friction(&key("friction"), w.friction)?,
            });
        }

        let mut people = Vec::new();
        for (i, p) in self.people.into_iter().enumerate() {
            let key = |field: &str| format!("person[{i}].{field}");
            c.finite(&key("position_m"), &p.position_m)?;
            c.finite(&key("heading_deg"), &[p.heading_deg])?;
            if !(p.height_m.is_finite() && (0.5..=2.5).contains(&p.height_m)) {
                return Err(c.fail(
                    &key("height_m"),
                    format!(
                        "expected a height between 0.5 and 2.5 m, found {}",
                        p.height_m
                    ),
                ));
            }
            for (j, w) in p.waypoints_m.iter().enumerate() {
                c.finite(&format!("person[{i}].waypoints_m[{j}]"), w)?;
            }
            let walk = match (p.waypoints_m.is_empty(), p.speed_mps) {
                (true, None) => None,
                (true, Some(_)) => {
                    return Err(c.fail(
                        &key("speed_mps"),
                        "a walking speed needs `waypoints_m = [[x, y], ...]` to walk through",
                    ));
                }
                (false, speed) => {
                    let speed = speed.unwrap_or(0.8);
                    if !(speed.is_finite() && speed > 0.0 && speed <= 3.0) {
                        return Err(c.fail(
                            &key("speed_mps"),
                            format!("expected a walking speed in (0, 3] m/s, found {speed}"),
                        ));
                    }
                    if !(p.start_after_s.is_finite() && p.start_after_s >= 0.0) {
                        return Err(c.fail(
                            &key("start_after_s"),
                            format!("expected seconds >= 0, found {}", p.start_after_s),
                        ));
                    }
                    Some(Walk {
                        waypoints_m: p.waypoints_m,
                        speed_mps: speed,
                        repeat: p.repeat,
                        start_after_s: p.start_after_s,
                    })
                }
            };
            people.push(Person {
                name: p.name.unwrap_or_else(|| format!("person_{i}")),
                walk,
                position_m: p.position_m,
                heading_rad: p.heading_deg.to_radians(),
                height_m: p.height_m,
                shirt_color: c.color(
                    &key("shirt_color"),
                    p.shirt_color.as_deref(),
                    Rgba::rgb(0.75, 0.15, 0.12),
                )?,
                trousers_color: c.color(
                    &key("trousers_color"),
                    p.trousers_color.as_deref(),
                    Rgba::rgb(0.15, 0.2, 0.35),
                )?,
                skin_color: c.color(
                    &key("skin_color"),
                    p.skin_color.as_deref(),
                    Rgba::rgb(0.87, 0.67, 0.53),
                )?,
                hair_color: c.color(
                    &key("hair_color"),
                    p.hair_color.as_deref(),
                    Rgba::rgb(0.2, 0.13, 0.08),
                )?,
            });
        }

        let mut seen = std::collections::BTreeSet::new();
        for name in objects
            .iter()
            .map(|o| &o.name)
            .chain(people.iter().map(|p| &p.name))
        {
            if !seen.insert(name.clone()) {
                return Err(SimError::invalid(
                    path,
                    None,
                    format!("two entries are named \"{name}\": names must be unique"),
                ));
            }
        }

        Ok(World {
            name: self.name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| "world".to_owned())
            }),
            source: path.to_path_buf(),
            description: self.description,
            robot,
            physics: self.physics.into(),
            ground,
            objects,
            people,
            models: Vec::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world(person: &str) -> Result<World> {
        World::from_str(
            &format!("name = \"t\"\n[[person]]\n{person}\n"),
            Path::new("t.toml"),
        )
    }

    #[test]
    fn a_walking_person_follows_the_closed_path_facing_ahead() -> Result<()> {
        let w = world(
            "position_m = [0.0, 0.0]\nwaypoints_m = [[2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]\nspeed_mps = 0.5",
        )?;
        let p = &w.people[0];
        let close = |a: (f64, f64, f64), b: (f64, f64, f64)| {
            (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9 && (a.2 - b.2).abs() < 1e-9
        };
        let half_pi = std::f64::consts::FRAC_PI_2;
        assert!(close(p.pose_at(0.0), (0.0, 0.0, 0.0)));
        assert!(close(p.pose_at(2.0), (1.0, 0.0, 0.0)));
        assert!(close(p.pose_at(6.0), (2.0, 1.0, half_pi)));
        // Last leg back to the start, then around again (16 s per lap).
        assert!(close(p.pose_at(14.0), (0.0, 1.0, -half_pi)));
        assert!(close(p.pose_at(18.0), (1.0, 0.0, 0.0)));
        Ok(())
    }

    #[test]
    fn a_speed_without_waypoints_or_a_bad_speed_is_an_error() {
        let e = world("position_m = [0.0, 0.0]\nspeed_mps = 0.5").err();
        assert!(
            e.is_some_and(|e| e.to_string().contains("waypoints_m")),
            "speed without a path"
        );
        let e =
            world("position_m = [0.0, 0.0]\nwaypoints_m = [[1.0, 0.0]]\nspeed_mps = -1.0").err();
        assert!(e.is_some_and(|e| e.to_string().contains("person[0].speed_mps")));
    }
}
