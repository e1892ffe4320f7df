//! World files: a small, strict TOML format (documented in docs/WORLDS.md), and the one entry
//! that loads any world file (TOML, or Gazebo SDF through `sdf.rs`).

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::description::resource::ResourcePaths;
use crate::description::sdf_include::RawModel;
use crate::description::{sdf, toml as tomlfile};
use crate::error::{Result, SimError};
use crate::geometry::{MAX_COORDINATE_M, MAX_MAGNITUDE, MAX_MASS_KG, MAX_SIZE_M, Rgba, Shape};
use crate::model::classes::is_known_class;
use crate::model::drive::DriveSpec;
use crate::model::human::{BodyShape, HairStyle, Legwear, Outfit};
use crate::model::person::{DEFAULT_PERSON_HEIGHT_M, Person, Walk};
use crate::model::world::{
    DEFAULT_CONTACT_HZ, DEFAULT_STEP_HZ, GraspMode, Ground, JointSolver, Object, Physics, Place,
    RobotSpawn, SphericalCoordinates, World, check_step_hz,
};
use rover_assets::COCO80;

impl World {
    /// Loads a world file: TOML, or a Gazebo SDF world (`.world`, `.sdf`) with `model://`
    /// models found through `GAZEBO_MODEL_PATH`.
    pub fn load(path: &Path) -> Result<Self> {
        Self::load_with(path, &ResourcePaths::from_env())
    }

    /// Loads a world file; `resources` finds an SDF world's `model://` models and meshes.
    pub fn load_with(path: &Path, resources: &ResourcePaths) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("world" | "sdf")) {
            return sdf::load_world(path, resources);
        }
        let raw: RawWorld = tomlfile::load_toml(path)?;
        raw.into_world(path, resources)
    }

    /// Parses world TOML text; `path` is used in messages and to resolve the robot's URDF.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        let raw: RawWorld = tomlfile::parse_toml(text, path)?;
        raw.into_world(path, &ResourcePaths::from_env())
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
    /// resolving the robot's URDF relative to it); `[[model]]`s are found through the
    /// environment's model paths ([`ResourcePaths::from_env`]).
    pub fn into_world(self, path: &Path) -> Result<World> {
        self.0.into_world(path, &ResourcePaths::from_env())
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
    #[serde(default, rename = "model")]
    models: Vec<RawModel>,
    #[serde(default)]
    spherical_coordinates: RawSpherical,
}

/// `[spherical_coordinates]`: SDF's `<spherical_coordinates>` (WGS-84), Gazebo's defaults.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawSpherical {
    latitude_deg: f64,
    longitude_deg: f64,
    elevation_m: f64,
    heading_deg: f64,
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
    controllers: Option<PathBuf>,
    bridge_config: Option<PathBuf>,
    camera: Option<String>,
    srdf: Option<PathBuf>,
    arm_group: Option<String>,
    arm_base: Option<String>,
    ee_link: Option<String>,
    #[serde(default)]
    grasp: GraspMode,
    place: Option<RawPlace>,
    pick: Option<String>,
    fetch: Option<[f64; 2]>,
    pose: Option<String>,
}

/// `place = "NAME"` or `place = [x, y, z]`.
#[derive(Debug, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a world object's name (\"bin\") or a point [x, y, z] in metres"
)]
enum RawPlace {
    Object(String),
    Point([f64; 3]),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawPhysics {
    step_hz: f64,
    gravity_mps2: [f64; 3],
    solver_iterations: usize,
    joints: JointSolver,
    contact_hz: f64,
}

impl Default for RawPhysics {
    fn default() -> Self {
        Self {
            step_hz: DEFAULT_STEP_HZ,
            gravity_mps2: [0.0, 0.0, -9.81],
            solver_iterations: 4,
            joints: JointSolver::default(),
            contact_hz: DEFAULT_CONTACT_HZ,
        }
    }
}

impl From<RawPhysics> for Physics {
    fn from(p: RawPhysics) -> Self {
        Self {
            step_hz: p.step_hz,
            gravity_mps2: p.gravity_mps2,
            solver_iterations: p.solver_iterations,
            joints: p.joints,
            contact_hz: p.contact_hz,
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
    class: Option<String>,
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
    class: Option<String>,
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
    class: Option<String>,
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
    body: Option<String>,
    hair_style: Option<String>,
    legwear: Option<String>,
    gender: Option<f64>,
    age: Option<f64>,
    muscle: Option<f64>,
    weight: Option<f64>,
}

fn default_repeat() -> bool {
    true
}

fn default_person_height() -> f64 {
    DEFAULT_PERSON_HEIGHT_M
}

/// Collects validation problems as `key: message` pairs.
struct Checker<'a> {
    path: &'a Path,
}

impl Checker<'_> {
    fn fail(&self, key: &str, message: impl std::fmt::Display) -> SimError {
        SimError::invalid(self.path, None, format!("at `{key}`: {message}"))
    }

    /// NaN and infinities, refused before any range is checked.
    fn all_finite(&self, key: &str, values: &[f64]) -> Result<()> {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.fail(key, format!("expected finite numbers, found {values:?}")))
        }
    }

    /// Finite numbers of magnitude up to [`MAX_MAGNITUDE`].
    fn finite(&self, key: &str, values: &[f64]) -> Result<()> {
        self.all_finite(key, values)?;
        if let Some(v) = values.iter().find(|v| v.abs() > MAX_MAGNITUDE) {
            return Err(self.fail(
                key,
                format!("{v} is out of range: expected a magnitude up to {MAX_MAGNITUDE:e}"),
            ));
        }
        Ok(())
    }

    /// Finite coordinates within [`MAX_COORDINATE_M`] of the origin.
    fn coordinates(&self, key: &str, values: &[f64]) -> Result<()> {
        self.all_finite(key, values)?;
        match values.iter().find(|v| v.abs() > MAX_COORDINATE_M) {
            Some(v) => Err(self.fail(
                key,
                format!(
                    "{v} m is out of range: expected positions within {MAX_COORDINATE_M:e} m of the origin"
                ),
            )),
            None => Ok(()),
        }
    }

    fn positive(&self, key: &str, values: &[f64], unit: &str) -> Result<()> {
        self.all_finite(key, values)?;
        if !values.iter().all(|v| *v > 0.0) {
            return Err(self.fail(
                key,
                format!("expected positive numbers ({unit}), found {values:?}"),
            ));
        }
        if let Some(v) = values.iter().find(|v| unit == "m" && **v > MAX_SIZE_M) {
            return Err(self.fail(
                key,
                format!("{v} m is out of range: expected sizes up to {MAX_SIZE_M:e} m"),
            ));
        }
        self.finite(key, values)
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
        if (0.0..=MAX_MAGNITUDE).contains(&f) {
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
            Some(m) if m > MAX_MASS_KG => Err(self.fail(
                key,
                format!("{m} kg is out of range: expected a mass up to {MAX_MASS_KG:e} kg"),
            )),
            other => Ok(other),
        }
    }

    /// `[x, y]` (resting on the ground, z = `half_height`) or `[x, y, z]`.
    fn position(&self, key: &str, values: &[f64], half_height: f64) -> Result<[f64; 3]> {
        self.coordinates(key, values)?;
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
    /// Boxes, cylinders, spheres, then walls, each checked in file order.
    fn objects(&mut self, c: &Checker<'_>) -> Result<Vec<Object>> {
        let mut objects = Vec::new();
        for (i, b) in std::mem::take(&mut self.boxes).into_iter().enumerate() {
            objects.push(b.into_object(i, c)?);
        }
        for (i, cy) in std::mem::take(&mut self.cylinders).into_iter().enumerate() {
            objects.push(cy.into_object(i, c)?);
        }
        for (i, s) in std::mem::take(&mut self.spheres).into_iter().enumerate() {
            objects.push(s.into_object(i, c)?);
        }
        for (i, w) in std::mem::take(&mut self.walls).into_iter().enumerate() {
            objects.push(w.into_object(i, c)?);
        }
        Ok(objects)
    }

    fn into_world(mut self, path: &Path, resources: &ResourcePaths) -> Result<World> {
        let c = Checker { path };
        let base_dir = path.parent().unwrap_or(Path::new("."));

        let raw_robot = std::mem::take(&mut self.robot);
        c.coordinates("robot.position_m", &raw_robot.position_m)?;
        c.finite("robot.yaw_deg", &[raw_robot.yaw_deg])?;
        let robot = RobotSpawn {
            urdf: raw_robot.urdf.map(|u| base_dir.join(u)),
            position_m: raw_robot.position_m,
            yaw_rad: raw_robot.yaw_deg.to_radians(),
            xacro_args: raw_robot.xacro_args,
            drive: raw_robot.drive,
            controllers: raw_robot.controllers.map(|c| base_dir.join(c)),
            bridge_config: raw_robot.bridge_config.map(|c| base_dir.join(c)),
            camera: raw_robot.camera,
            srdf: raw_robot.srdf.map(|s| base_dir.join(s)),
            arm_group: raw_robot.arm_group,
            arm_base: raw_robot.arm_base,
            ee_link: raw_robot.ee_link,
            grasp: raw_robot.grasp,
            place: match raw_robot.place {
                None => None,
                Some(RawPlace::Object(name)) => Some(Place::Object(name)),
                Some(RawPlace::Point(p)) => {
                    c.coordinates("robot.place", &p)?;
                    Some(Place::Point(p))
                }
            },
            pick: raw_robot.pick,
            fetch: match raw_robot.fetch {
                Some(at) => {
                    c.coordinates("robot.fetch", &at)?;
                    Some(at)
                }
                None => None,
            },
            pose: raw_robot.pose,
        };

        c.positive("physics.step_hz", &[self.physics.step_hz], "Hz")?;
        if let Err(message) = check_step_hz(self.physics.step_hz) {
            return Err(c.fail("physics.step_hz", message));
        }
        c.finite("physics.gravity_mps2", &self.physics.gravity_mps2)?;
        if !(self.physics.contact_hz.is_finite()
            && (1.0..=1000.0).contains(&self.physics.contact_hz))
        {
            return Err(c.fail(
                "physics.contact_hz",
                format!(
                    "expected a contact stiffness of 1..=1000 Hz (default {DEFAULT_CONTACT_HZ}), found {}",
                    self.physics.contact_hz
                ),
            ));
        }
        if !(1..=100).contains(&self.physics.solver_iterations) {
            return Err(c.fail(
                "physics.solver_iterations",
                format!("expected 1..=100, found {}", self.physics.solver_iterations),
            ));
        }

        let ground = std::mem::take(&mut self.ground).into_ground(path)?;

        let objects = self.objects(&c)?;

        let people = self
            .people
            .into_iter()
            .enumerate()
            .map(|(i, p)| p.into_person(i, &c))
            .collect::<Result<Vec<_>>>()?;

        let mut models = Vec::new();
        for (i, m) in std::mem::take(&mut self.models).into_iter().enumerate() {
            models.extend(m.into_models(i, path, resources)?);
        }

        let mut seen = std::collections::BTreeSet::new();
        for name in (objects.iter().map(|o| &o.name))
            .chain(people.iter().map(|p| &p.name))
            .chain(models.iter().map(|m| &m.name))
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
            models,
            sun_direction: crate::model::world::DEFAULT_SUN_DIRECTION,
            spherical_coordinates: spherical(self.spherical_coordinates, path)?,
        })
    }
}

/// The [`SolidFields`] of a raw box, cylinder or sphere (their shared fields have one name).
macro_rules! solid_fields {
    ($raw:expr, $kind:literal, $index:expr) => {
        SolidFields {
            kind: $kind,
            index: $index,
            name: $raw.name,
            class: $raw.class,
            position_m: &$raw.position_m,
            color: $raw.color.as_deref(),
            mass_kg: $raw.mass_kg,
            friction: $raw.friction,
        }
    };
}

/// What boxes, cylinders and spheres share, checked in one order for all of them.
struct SolidFields<'a> {
    /// `box`, `cylinder` or `sphere`: the TOML table and the default name's prefix.
    kind: &'static str,
    index: usize,
    name: Option<String>,
    class: Option<String>,
    position_m: &'a [f64],
    color: Option<&'a str>,
    mass_kg: Option<f64>,
    friction: Option<f64>,
}

impl Checker<'_> {
    /// An object from its shared fields: position (resting on the ground at `half_height_m`
    /// when only x, y are given), colour, mass, friction.
    fn solid(
        &self,
        f: SolidFields<'_>,
        shape: Shape,
        half_height_m: f64,
        yaw_rad: f64,
        default_color: Rgba,
    ) -> Result<Object> {
        let key = |field: &str| format!("{}[{}].{field}", f.kind, f.index);
        Ok(Object {
            name: f.name.unwrap_or_else(|| format!("{}_{}", f.kind, f.index)),
            position_m: self.position(&key("position_m"), f.position_m, half_height_m)?,
            shape,
            yaw_rad,
            color: self.color(&key("color"), f.color, default_color)?,
            mass_kg: self.mass(&key("mass_kg"), f.mass_kg)?,
            friction: self.friction(&key("friction"), f.friction)?,
            class: self.class(&key("class"), f.class)?,
        })
    }

    /// A COCO class name, checked.
    fn class(&self, key: &str, class: Option<String>) -> Result<Option<String>> {
        match class {
            Some(c) if !is_known_class(&c) => Err(self.fail(
                key,
                format!(
                    "\"{c}\" is not a COCO class; expected one of: {}",
                    COCO80.join(", ")
                ),
            )),
            other => Ok(other),
        }
    }
}

impl RawBox {
    fn into_object(self, i: usize, c: &Checker<'_>) -> Result<Object> {
        c.positive(&format!("box[{i}].size_m"), &self.size_m, "m")?;
        c.finite(&format!("box[{i}].yaw_deg"), &[self.yaw_deg])?;
        let fields = solid_fields!(self, "box", i);
        let shape = Shape::Box {
            size_m: vec3_f32(self.size_m),
        };
        let brown = Rgba::rgb(0.63, 0.42, 0.25);
        c.solid(
            fields,
            shape,
            self.size_m[2] / 2.0,
            self.yaw_deg.to_radians(),
            brown,
        )
    }
}

impl RawCylinder {
    fn into_object(self, i: usize, c: &Checker<'_>) -> Result<Object> {
        c.positive(&format!("cylinder[{i}].radius_m"), &[self.radius_m], "m")?;
        c.positive(&format!("cylinder[{i}].length_m"), &[self.length_m], "m")?;
        let fields = solid_fields!(self, "cylinder", i);
        let shape = Shape::Cylinder {
            radius_m: self.radius_m as f32,
            length_m: self.length_m as f32,
        };
        let orange = Rgba::rgb(0.8, 0.45, 0.1);
        c.solid(fields, shape, self.length_m / 2.0, 0.0, orange)
    }
}

impl RawSphere {
    fn into_object(self, i: usize, c: &Checker<'_>) -> Result<Object> {
        c.positive(&format!("sphere[{i}].radius_m"), &[self.radius_m], "m")?;
        let fields = solid_fields!(self, "sphere", i);
        let shape = Shape::Sphere {
            radius_m: self.radius_m as f32,
        };
        let red = Rgba::rgb(0.85, 0.2, 0.2);
        c.solid(fields, shape, self.radius_m, 0.0, red)
    }
}

impl RawWall {
    fn into_object(self, i: usize, c: &Checker<'_>) -> Result<Object> {
        let key = |field: &str| format!("wall[{i}].{field}");
        c.coordinates(&key("from_m"), &self.from_m)?;
        c.coordinates(&key("to_m"), &self.to_m)?;
        c.positive(&key("height_m"), &[self.height_m], "m")?;
        c.positive(&key("thickness_m"), &[self.thickness_m], "m")?;
        let (dx, dy) = (self.to_m[0] - self.from_m[0], self.to_m[1] - self.from_m[1]);
        let length = dx.hypot(dy);
        if length < 1e-3 {
            return Err(c.fail(
                &key("to_m"),
                "expected a wall end point different from from_m",
            ));
        }
        Ok(Object {
            name: self.name.unwrap_or_else(|| format!("wall_{i}")),
            shape: Shape::Box {
                size_m: vec3_f32([length, self.thickness_m, self.height_m]),
            },
            position_m: [
                (self.from_m[0] + self.to_m[0]) / 2.0,
                (self.from_m[1] + self.to_m[1]) / 2.0,
                self.height_m / 2.0,
            ],
            yaw_rad: dy.atan2(dx),
            color: c.color(
                &key("color"),
                self.color.as_deref(),
                Rgba::rgb(0.85, 0.83, 0.78),
            )?,
            mass_kg: None,
            friction: c.friction(&key("friction"), self.friction)?,
            class: None,
        })
    }
}

impl RawPerson {
    /// `body = "makehuman"` (the default) with its shape sliders, or `body = "figure"`.
    fn shape(&self, i: usize, c: &Checker<'_>) -> Result<Option<BodyShape>> {
        let key = |field: &str| format!("person[{i}].{field}");
        let sliders = [
            ("gender", self.gender),
            ("age", self.age),
            ("muscle", self.muscle),
            ("weight", self.weight),
        ];
        for (name, value) in sliders {
            if let Some(v) = value
                && !(v.is_finite() && (0.0..=1.0).contains(&v))
            {
                return Err(c.fail(
                    &key(name),
                    format!("expected a slider value from 0 to 1 (MakeHuman's), found {v}"),
                ));
            }
        }
        match self.body.as_deref().unwrap_or("makehuman") {
            "makehuman" => {
                let d = BodyShape::default();
                let or = |v: Option<f64>, d: f32| v.map_or(d, |v| v as f32);
                Ok(Some(BodyShape {
                    gender: or(self.gender, d.gender),
                    age: or(self.age, d.age),
                    muscle: or(self.muscle, d.muscle),
                    weight: or(self.weight, d.weight),
                }))
            }
            "figure" => match sliders.iter().find(|s| s.1.is_some()) {
                Some((name, _)) => Err(c.fail(
                    &key(name),
                    "rover's figure has no body shape: drop it, or use body = \"makehuman\"",
                )),
                None => Ok(None),
            },
            other => Err(c.fail(
                &key("body"),
                format!("expected \"makehuman\" (MakeHuman's body, the default) or \"figure\" (rover's own), found \"{other}\""),
            )),
        }
    }

    /// `hair_style` and `legwear`, MakeHuman's body only.
    fn outfit(&self, i: usize, c: &Checker<'_>, figure: bool) -> Result<Outfit> {
        let key = |field: &str| format!("person[{i}].{field}");
        let word = |field: &str, value: Option<&str>| -> Result<()> {
            match value {
                Some(_) if figure => Err(c.fail(
                    &key(field),
                    "rover's figure has one outfit: drop it, or use body = \"makehuman\"",
                )),
                _ => Ok(()),
            }
        };
        word("hair_style", self.hair_style.as_deref())?;
        word("legwear", self.legwear.as_deref())?;
        let hair = match self.hair_style.as_deref() {
            None => HairStyle::default(),
            Some(w) => HairStyle::parse(w).ok_or_else(|| {
                c.fail(
                    &key("hair_style"),
                    format!(
                        "expected \"short\" (the default), \"long\" or \"bald\", found \"{w}\""
                    ),
                )
            })?,
        };
        let legwear = match self.legwear.as_deref() {
            None => Legwear::default(),
            Some(w) => Legwear::parse(w).ok_or_else(|| {
                c.fail(
                    &key("legwear"),
                    format!("expected \"trousers\" (the default), \"skirt\" (to the knees) or \"long_skirt\" (to the ankles), found \"{w}\""),
                )
            })?,
        };
        Ok(Outfit::new(hair, legwear))
    }

    fn into_person(self, i: usize, c: &Checker<'_>) -> Result<Person> {
        let p = self;
        let shape = p.shape(i, c)?;
        let outfit = p.outfit(i, c, shape.is_none())?;
        let key = |field: &str| format!("person[{i}].{field}");
        c.coordinates(&key("position_m"), &p.position_m)?;
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
            c.coordinates(&format!("person[{i}].waypoints_m[{j}]"), w)?;
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
        Ok(Person {
            name: p.name.unwrap_or_else(|| format!("person_{i}")),
            walk,
            shape,
            outfit,
            actor: None,
            still_gait_phase_rad: 0.0,
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
        })
    }
}

/// A size in metres as the model stores it (f32, like URDF shapes).
fn vec3_f32(v: [f64; 3]) -> glam::Vec3 {
    glam::Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// `[spherical_coordinates]` checked: a latitude on the Earth, finite numbers.
fn spherical(raw: RawSpherical, path: &Path) -> Result<SphericalCoordinates> {
    let values = [
        raw.latitude_deg,
        raw.longitude_deg,
        raw.elevation_m,
        raw.heading_deg,
    ];
    if !values.iter().all(|v| v.is_finite()) || raw.latitude_deg.abs() > 90.0 {
        return Err(SimError::invalid(
            path,
            None,
            format!(
                "[spherical_coordinates]: expected latitude_deg within -90..90 and finite numbers, found latitude {} longitude {} elevation {} heading {}",
                raw.latitude_deg, raw.longitude_deg, raw.elevation_m, raw.heading_deg
            ),
        ));
    }
    Ok(SphericalCoordinates {
        latitude_deg: raw.latitude_deg,
        longitude_deg: raw.longitude_deg,
        elevation_m: raw.elevation_m,
        heading_deg: raw.heading_deg,
    })
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

    #[test]
    fn hair_style_and_legwear_dress_makehumans_body_and_bad_words_are_errors() -> Result<()> {
        let w = world("position_m = [0.0, 0.0]\nhair_style = \"long\"\nlegwear = \"skirt\"")?;
        assert_eq!(
            w.people[0].outfit,
            Outfit::new(HairStyle::Long, Legwear::Skirt)
        );
        let w = world("position_m = [0.0, 0.0]")?;
        assert_eq!(w.people[0].outfit, Outfit::default());
        let e = world("position_m = [0.0, 0.0]\nlegwear = \"kilt\"").err();
        assert!(e.is_some_and(|e| {
            let m = e.to_string();
            m.contains("person[0].legwear") && m.contains("\"kilt\"") && m.contains("\"skirt\"")
        }));
        let e = world("position_m = [0.0, 0.0]\nhair_style = \"mohawk\"").err();
        assert!(e.is_some_and(|e| e.to_string().contains("person[0].hair_style")));
        let e = world("position_m = [0.0, 0.0]\nbody = \"figure\"\nhair_style = \"long\"").err();
        assert!(e.is_some_and(|e| e.to_string().contains("figure has one outfit")));
        Ok(())
    }
}
