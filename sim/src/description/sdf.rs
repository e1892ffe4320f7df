//! Gazebo SDF worlds (`.world`, `.sdf`; SDF 1.4 to 1.9): models with their links, poses,
//! static flags, primitive and mesh visuals and collisions with colours, `<include>` of
//! `model://` models (model.config -> model.sdf, nested includes), `<state>` poses overriding the
//! models', the physics step and gravity. Anything else is skipped with one summary line.
//!
//! SDF is read with roxmltree (already a dependency); the subset rover simulates is small and no
//! maintained Rust SDF crate builds without libsdformat.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use roxmltree::Node;

use crate::description::collada_skin;
use crate::description::resource::ResourcePaths;
use crate::description::xml::{child, children, line_of, parse_xml};
use crate::error::{Result, SimError};
use crate::geometry::{
    MAX_COORDINATE_M, MAX_MAGNITUDE, Pose, Rgba, Shape, pose_from_xyz_rpy, yaw_of,
};
use crate::model::actor::{Actor, ActorSkin, Script, Trajectory, Waypoint};
use crate::model::classes::{class_of_model, label_part_of_model};
use crate::model::person::Person;
use crate::model::robot::{Collision, Visual};
use crate::model::world::{
    DEFAULT_STEP_HZ, Model, ModelLink, STEP_HZ_RANGE, SphericalCoordinates, World,
};

/// Largest magnitude of any number rover reads from an SDF world (sizes, masses, gravity, step
/// size; positions are held to [`MAX_COORDINATE_M`] besides): values far outside physical sense
/// would reach the physics engine, and parry's contact code can fail on them.
const MAX_SDF_NUMBER: f64 = MAX_MAGNITUDE;

/// Deepest `<include>` nesting followed (models including models).
pub(crate) const MAX_INCLUDE_DEPTH: usize = 16;

/// Loads an SDF world file; `resources` finds `model://` models and meshes.
pub fn load_world(path: &Path, resources: &ResourcePaths) -> Result<World> {
    let text = crate::io::read_text(path)?;
    let doc = parse_xml(&text, path)?;
    let root = doc.root_element();
    let ctx = Ctx { path, doc: &doc };
    if !root.has_tag_name("sdf") {
        return Err(ctx.err(
            root,
            format!(
                "expected an <sdf> root element, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    let world_el = child(root, "world")
        .ok_or_else(|| ctx.err(root, "<sdf> has no <world>: expected a world file"))?;
    let mut loader = Loader {
        resources,
        skipped: BTreeSet::new(),
    };

    let mut world = World::flat()?;
    read_physics(&ctx, world_el, &mut world)?;
    let state_models = state_poses(&ctx, world_el)?;
    let mut models = Vec::new();
    read_world_entities(&ctx, world_el, &mut loader, &mut world, &mut models)?;
    apply_state_poses(path, &mut models, &state_models)?;
    if !loader.skipped.is_empty() {
        tracing::info!(
            "{}: not simulated (rover has no model for them): {}",
            path.display(),
            loader
                .skipped
                .iter()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    world.name = world_el.attribute("name").unwrap_or("default").to_owned();
    world.source = path.to_path_buf();
    world.description = format!("Gazebo SDF world {}", path.display());
    // Gazebo's ground_plane is 100 m x 100 m.
    world.ground.size_m = [100.0, 100.0];
    world.models = models;
    Ok(world)
}

/// Reads the world-level settings of `<world>` into `world`: the physics step
/// (`<physics><max_step_size>`, outside rover's range a warning and the default), gravity
/// (`<physics><gravity>`, overridden by `<world><gravity>`) and `<spherical_coordinates>`.
fn read_physics(ctx: &Ctx<'_, '_>, world_el: Node<'_, '_>, world: &mut World) -> Result<()> {
    let physics = &mut world.physics;
    if let Some(p) = child(world_el, "physics") {
        if let Some(step) = child(p, "max_step_size") {
            let dt = ctx.number(step)?;
            let hz = 1.0 / dt;
            physics.step_hz = if dt > 0.0 && STEP_HZ_RANGE.contains(&hz) {
                hz
            } else {
                tracing::warn!(
                    "{}: <max_step_size>{dt}</max_step_size> is outside rover's {}..={} Hz; using {DEFAULT_STEP_HZ} Hz",
                    ctx.path.display(),
                    STEP_HZ_RANGE.start(),
                    STEP_HZ_RANGE.end()
                );
                DEFAULT_STEP_HZ
            };
        }
        if let Some(g) = child(p, "gravity") {
            physics.gravity_mps2 = ctx.numbers::<3>(g)?;
        }
    }
    if let Some(g) = child(world_el, "gravity") {
        physics.gravity_mps2 = ctx.numbers::<3>(g)?;
    }
    if let Some(sc) = child(world_el, "spherical_coordinates") {
        read_spherical_coordinates(ctx, sc, &mut world.spherical_coordinates)?;
    }
    Ok(())
}

/// `<spherical_coordinates>`: the world's origin on WGS-84 (the only surface model Gazebo has)
/// and its heading, Gazebo's defaults (zero) where absent.
fn read_spherical_coordinates(
    ctx: &Ctx<'_, '_>,
    sc: Node<'_, '_>,
    out: &mut SphericalCoordinates,
) -> Result<()> {
    for e in sc.children().filter(Node::is_element) {
        match e.tag_name().name() {
            "surface_model" => {
                let model = e.text().map(str::trim).unwrap_or_default();
                if model != "EARTH_WGS84" {
                    return Err(ctx.err(
                        e,
                        format!("<surface_model>: expected EARTH_WGS84, found '{model}'"),
                    ));
                }
            }
            "latitude_deg" => {
                out.latitude_deg = ctx.number(e)?;
                if out.latitude_deg.abs() > 90.0 {
                    return Err(ctx.err(
                        e,
                        format!(
                            "<latitude_deg>: expected -90 to 90, found {}",
                            out.latitude_deg
                        ),
                    ));
                }
            }
            "longitude_deg" => out.longitude_deg = ctx.number(e)?,
            "elevation" => out.elevation_m = ctx.number(e)?,
            "heading_deg" => out.heading_deg = ctx.number(e)?,
            _ => {}
        }
    }
    Ok(())
}

/// The `<state>` poses of a world, by model name: the model's pose (world frame) when given,
/// and its links' poses (world frame) by link name.
type StatePoses = BTreeMap<String, (Option<Pose>, BTreeMap<String, Pose>)>;

/// Reads the `<state>` elements of `<world>` (Gazebo saves the world's last state there).
fn state_poses(ctx: &Ctx<'_, '_>, world_el: Node<'_, '_>) -> Result<StatePoses> {
    let mut state_models = StatePoses::new();
    for state in children(world_el, "state") {
        for m in children(state, "model") {
            let name = m.attribute("name").unwrap_or_default().to_owned();
            let pose = child(m, "pose").map(|p| ctx.pose(p)).transpose()?;
            let mut links = BTreeMap::new();
            for l in children(m, "link") {
                if let Some(p) = child(l, "pose") {
                    links.insert(
                        l.attribute("name").unwrap_or_default().to_owned(),
                        ctx.pose(p)?,
                    );
                }
            }
            state_models.insert(name, (pose, links));
        }
    }
    Ok(state_models)
}

/// Reads what `<world>` holds besides its settings, in order: models (`<model>`, `<include>`)
/// into `models`, people (`<include>` of a person model, `<actor>`) into `world`; anything else
/// is noted in `loader.skipped`.
fn read_world_entities(
    ctx: &Ctx<'_, '_>,
    world_el: Node<'_, '_>,
    loader: &mut Loader<'_>,
    world: &mut World,
    models: &mut Vec<Model>,
) -> Result<()> {
    for node in world_el.children().filter(Node::is_element) {
        match node.tag_name().name() {
            "model" => loader.model(ctx, node, Pose::IDENTITY, None, models, 0)?,
            "include" => match (person_model(node), included_name(node)) {
                (Some(model), _) => {
                    let person = included_person(ctx, node, &model, world.people.len())?;
                    world.people.push(person);
                }
                // Gazebo's own sun and ground plane, built in: the sun's light direction, and
                // the 100 m x 100 m grey plane rover's ground already is.
                (None, Some("sun")) => world.sun_direction = GAZEBO_SUN_DIRECTION,
                (None, Some("ground_plane")) => {}
                (None, _) => loader.include(ctx, node, Pose::IDENTITY, models, 0)?,
            },
            "light" => {
                if let Some(direction) = directional_light(ctx, node)? {
                    world.sun_direction = direction;
                }
            }
            "actor" => world.people.push(actor(ctx, loader, node)?),
            "plugin" => world_system(node, loader),
            "physics" | "gravity" | "state" | "spherical_coordinates" => {}
            other => {
                loader.skipped.insert(format!("<{other}>"));
            }
        }
    }
    Ok(())
}

/// A world `<plugin>`: gz-sim's world systems are rover's own work (physics, sensors, IMU,
/// NavSat) or have nothing to do here (scene broadcaster, user commands; the sensors' render
/// engine: rover renders with wgpu); any other plugin is listed as skipped.
fn world_system(node: Node<'_, '_>, loader: &mut Loader<'_>) {
    let file = node.attribute("filename").unwrap_or("");
    let name = node.attribute("name").unwrap_or("");
    if super::gazebo::gz::is_world_system(file) {
        tracing::debug!("world system {file} ({name}): done by rover's own simulation");
    } else {
        loader
            .skipped
            .insert(format!("world plugin {file} ({name})"));
    }
}

/// A person standing where `<include>` of the person model `model` puts it, named by the
/// include's `<name>` or else `model_index` (`index`: how many people came before).
fn included_person(
    ctx: &Ctx<'_, '_>,
    include: Node<'_, '_>,
    model: &str,
    index: usize,
) -> Result<Person> {
    let name = child(include, "name")
        .and_then(|n| n.text())
        .map(|s| s.trim().to_owned())
        .unwrap_or_else(|| format!("{model}_{index}"));
    let pose = ctx.local_pose(include)?;
    let t = pose.translation;
    Ok(Person::standing(
        name,
        [f64::from(t.x), f64::from(t.y)],
        yaw_of(pose.rotation),
    ))
}

/// Checks that model names are unique and moves the models named in `<state>` to their state
/// poses: the model's frame, and each link to its state pose or else along with its model.
fn apply_state_poses(path: &Path, models: &mut [Model], state_models: &StatePoses) -> Result<()> {
    let mut names = BTreeSet::new();
    for model in models {
        if !names.insert(model.name.clone()) {
            return Err(SimError::invalid(
                path,
                None,
                format!(
                    "two models are named \"{}\"; expected unique names",
                    model.name
                ),
            ));
        }
        if let Some((pose, links)) = state_models.get(&model.name) {
            // Links keep their place in the model; a <state> link pose wins over both.
            let old_from_world = model.world_from_model.inverse();
            if let Some(p) = pose {
                model.world_from_model = *p;
            }
            for link in &mut model.links {
                link.world_from_link = match links.get(&link.name) {
                    Some(world_from_link) => *world_from_link,
                    None => model.world_from_model * old_from_world * link.world_from_link,
                };
            }
        }
    }
    Ok(())
}

pub(crate) struct Ctx<'a, 'input> {
    pub(crate) path: &'a Path,
    pub(crate) doc: &'a roxmltree::Document<'input>,
}

impl Ctx<'_, '_> {
    pub(crate) fn err(&self, node: Node<'_, '_>, message: impl Into<String>) -> SimError {
        SimError::invalid(self.path, Some(line_of(self.doc, node)), message)
    }

    pub(crate) fn number(&self, node: Node<'_, '_>) -> Result<f64> {
        let text = node.text().unwrap_or("").trim();
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && v.abs() <= MAX_SDF_NUMBER)
            .ok_or_else(|| {
                self.err(
                    node,
                    format!(
                        "<{}>{text}</{}>: expected a finite number of magnitude up to {MAX_SDF_NUMBER:e}",
                        node.tag_name().name(),
                        node.tag_name().name()
                    ),
                )
            })
    }

    pub(crate) fn numbers<const N: usize>(&self, node: Node<'_, '_>) -> Result<[f64; N]> {
        let text = node.text().unwrap_or("");
        let values: Vec<f64> = text
            .split_whitespace()
            .map(|t| {
                t.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && v.abs() <= MAX_SDF_NUMBER)
            })
            .collect::<Option<Vec<_>>>()
            .unwrap_or_default();
        values.try_into().map_err(|_| {
            self.err(
                node,
                format!(
                    "<{}>{}</{}>: expected {N} finite numbers of magnitude up to {MAX_SDF_NUMBER:e}",
                    node.tag_name().name(),
                    text.trim(),
                    node.tag_name().name()
                ),
            )
        })
    }

    pub(crate) fn pose(&self, node: Node<'_, '_>) -> Result<Pose> {
        let [x, y, z, roll, pitch, yaw] = self.numbers::<6>(node)?;
        if let Some(v) = [x, y, z].into_iter().find(|v| v.abs() > MAX_COORDINATE_M) {
            return Err(self.err(
                node,
                format!(
                    "<pose>: {v} m is out of range: expected positions within {MAX_COORDINATE_M:e} m of the origin"
                ),
            ));
        }
        Ok(pose_from_xyz_rpy([x, y, z], [roll, pitch, yaw]))
    }

    pub(crate) fn local_pose(&self, node: Node<'_, '_>) -> Result<Pose> {
        child(node, "pose").map_or(Ok(Pose::IDENTITY), |p| self.pose(p))
    }

    pub(crate) fn flag(&self, node: Node<'_, '_>) -> bool {
        matches!(node.text().map(str::trim), Some("1" | "true"))
    }
}

pub(crate) struct Loader<'r> {
    pub(crate) resources: &'r ResourcePaths,
    pub(crate) skipped: BTreeSet<String>,
}

/// Overrides an `<include>` applies to the model it brings in.
pub(crate) struct Overrides {
    pub(crate) name: Option<String>,
    pub(crate) is_static: Option<bool>,
    /// The `model://` name the `<include>` used (its class, if it is one).
    pub(crate) uri_name: Option<String>,
}

impl Loader<'_> {
    pub(crate) fn model(
        &mut self,
        ctx: &Ctx<'_, '_>,
        node: Node<'_, '_>,
        parent: Pose,
        overrides: Option<Overrides>,
        out: &mut Vec<Model>,
        depth: usize,
    ) -> Result<()> {
        let own_name = node.attribute("name").unwrap_or("model").to_owned();
        // The name that gives the class: the model:// name, else the model's own.
        let known = overrides
            .as_ref()
            .and_then(|o| o.uri_name.as_deref())
            .filter(|n| class_of_model(n).is_some())
            .or_else(|| Some(own_name.as_str()).filter(|n| class_of_model(n).is_some()));
        let class = known.and_then(class_of_model).map(str::to_owned);
        let label_above_m = known.and_then(label_part_of_model);
        let (name, static_override) = match overrides {
            Some(o) => (o.name.unwrap_or(own_name), o.is_static),
            None => (own_name, None),
        };
        let world_from_model = parent * ctx.local_pose(node)?;
        let is_static =
            static_override.unwrap_or_else(|| child(node, "static").is_some_and(|s| ctx.flag(s)));
        let mut model = Model {
            name: name.clone(),
            is_static,
            world_from_model,
            links: Vec::new(),
            class,
            label_above_m,
        };
        let base = ctx.path.parent().unwrap_or(Path::new("."));
        for item in node.children().filter(Node::is_element) {
            match item.tag_name().name() {
                "link" => {
                    model
                        .links
                        .push(self.link(ctx, item, world_from_model, base)?);
                }
                "model" => {
                    // A nested model: its own entry, named parent::child as Gazebo does.
                    let nested_name =
                        format!("{name}::{}", item.attribute("name").unwrap_or("model"));
                    self.model(
                        ctx,
                        item,
                        world_from_model,
                        Some(Overrides {
                            name: Some(nested_name),
                            is_static: is_static.then_some(true),
                            uri_name: None,
                        }),
                        out,
                        depth + 1,
                    )?;
                }
                "include" => self.include(ctx, item, world_from_model, out, depth + 1)?,
                "pose" | "static" | "self_collide" | "allow_auto_disable" | "enable_wind" => {}
                "joint" | "plugin" => {
                    self.skipped
                        .insert(format!("model <{}>", item.tag_name().name()));
                }
                other => {
                    self.skipped.insert(format!("model <{other}>"));
                }
            }
        }
        out.push(model);
        Ok(())
    }

    fn link(
        &mut self,
        ctx: &Ctx<'_, '_>,
        node: Node<'_, '_>,
        world_from_model: Pose,
        base: &Path,
    ) -> Result<ModelLink> {
        let mut link = ModelLink {
            name: node.attribute("name").unwrap_or("link").to_owned(),
            world_from_link: world_from_model * ctx.local_pose(node)?,
            mass_kg: None,
            visuals: Vec::new(),
            collisions: Vec::new(),
        };
        if let Some(mass) = child(node, "inertial").and_then(|i| child(i, "mass")) {
            let m = ctx.number(mass)?;
            if m < 0.0 {
                return Err(ctx.err(
                    mass,
                    format!("<mass>{m}</mass>: expected a non-negative mass"),
                ));
            }
            link.mass_kg = Some(m);
        }
        for item in node.children().filter(Node::is_element) {
            match item.tag_name().name() {
                "visual" => {
                    let Some(shape) = self.geometry(ctx, item, base)? else {
                        continue;
                    };
                    let color = material_color(ctx, item)?;
                    let texture = self.script_texture(item, base);
                    link.visuals.push(Visual {
                        link_from_shape: ctx.local_pose(item)?,
                        shape,
                        color: color.unwrap_or(Rgba::rgb(0.7, 0.7, 0.7)),
                        color_given: color.is_some(),
                        texture,
                    });
                }
                "collision" => {
                    let Some(shape) = self.geometry(ctx, item, base)? else {
                        continue;
                    };
                    link.collisions.push(Collision {
                        link_from_shape: ctx.local_pose(item)?,
                        shape,
                    });
                }
                "sensor" => {
                    self.skipped.insert(format!(
                        "sensor type {}",
                        item.attribute("type").unwrap_or("?")
                    ));
                }
                _ => {}
            }
        }
        Ok(link)
    }

    /// The shape of a `<visual>` or `<collision>`; `None` for a plane (the ground stands in
    /// for it) and for geometry rover does not simulate.
    fn geometry(
        &mut self,
        ctx: &Ctx<'_, '_>,
        item: Node<'_, '_>,
        base: &Path,
    ) -> Result<Option<Shape>> {
        let Some(g) = child(item, "geometry") else {
            return Err(ctx.err(
                item,
                format!("<{}> has no <geometry>", item.tag_name().name()),
            ));
        };
        let Some(shape) = g.children().find(Node::is_element) else {
            return Ok(None);
        };
        let need = |name: &str| {
            child(shape, name).ok_or_else(|| {
                ctx.err(
                    shape,
                    format!("<{}> needs a <{name}>", shape.tag_name().name()),
                )
            })
        };
        let positive = |node: Node<'_, '_>| -> Result<f32> {
            let v = ctx.number(node)?;
            if v < 0.0 {
                return Err(ctx.err(
                    node,
                    format!(
                        "<{}>{v}: expected a non-negative size",
                        node.tag_name().name()
                    ),
                ));
            }
            Ok(v as f32)
        };
        Ok(Some(match shape.tag_name().name() {
            "box" => {
                let size = ctx.numbers::<3>(need("size")?)?;
                if size.iter().any(|v| *v < 0.0) {
                    return Err(ctx.err(shape, "<box><size>: expected non-negative sizes"));
                }
                Shape::Box {
                    size_m: Vec3::new(size[0] as f32, size[1] as f32, size[2] as f32),
                }
            }
            "cylinder" => Shape::Cylinder {
                radius_m: positive(need("radius")?)?,
                length_m: positive(need("length")?)?,
            },
            "sphere" => Shape::Sphere {
                radius_m: positive(need("radius")?)?,
            },
            "capsule" => Shape::Capsule {
                radius_m: positive(need("radius")?)?,
                length_m: positive(need("length")?)?,
            },
            "mesh" => {
                let uri_node = need("uri")?;
                let uri = uri_node.text().unwrap_or("").trim();
                let path = self
                    .resources
                    .resolve(uri, base)
                    .map_err(|e| ctx.err(uri_node, format!("<mesh>: {e}")))?;
                let scale = match child(shape, "scale") {
                    Some(s) => {
                        let [x, y, z] = ctx.numbers::<3>(s)?;
                        Vec3::new(x as f32, y as f32, z as f32)
                    }
                    None => Vec3::ONE,
                };
                if child(shape, "submesh").is_some() {
                    self.skipped
                        .insert("mesh <submesh> (the whole mesh is used)".into());
                }
                Shape::Mesh { path, scale }
            }
            "plane" | "empty" => return Ok(None),
            other => {
                self.skipped.insert(format!("geometry <{other}>"));
                return Ok(None);
            }
        }))
    }

    /// The texture of a visual's OGRE material script (`<material><script>` with `<uri>`
    /// folders or files and a `<name>`), as Gazebo classic finds it: the first `texture` of
    /// that material in the `.material` files there, the image in one of those folders or in
    /// a `textures` folder beside them. `Gazebo/*` names are colours (gazebo.material has no
    /// textures rover needs); a named material rover cannot find is reported once.
    fn script_texture(&mut self, visual: Node<'_, '_>, base: &Path) -> Option<PathBuf> {
        let script = child(visual, "material").and_then(|m| child(m, "script"))?;
        let name = child(script, "name")?.text()?.trim();
        if name.is_empty() || name.starts_with("Gazebo/") {
            return None;
        }
        let dirs: Vec<PathBuf> = children(script, "uri")
            .filter_map(|u| u.text())
            .filter_map(|u| self.resources.resolve_dir(u.trim(), base))
            .collect();
        let found = super::ogre::find_texture(name, &dirs);
        if found.is_none() {
            self.skipped.insert(format!(
                "material script {name} (no texture found: flat colour)"
            ));
        }
        found
    }
}

/// The direction of the light in Gazebo's `model://sun` (a directional light).
const GAZEBO_SUN_DIRECTION: [f64; 3] = [-0.5, 0.1, -0.9];

/// The `model://NAME` an `<include>` names, if it names one; Fuel's Sun, Ground Plane,
/// Standing person and Walking person as `sun`, `ground_plane`, `person_standing`,
/// `person_walking`.
fn included_name<'a>(include: Node<'a, '_>) -> Option<&'a str> {
    let uri = child(include, "uri")?.text()?.trim();
    match uri.strip_prefix("model://") {
        Some(name) => Some(name.trim_end_matches('/')),
        None => super::fuel::parse(uri)
            .as_ref()
            .and_then(super::fuel::builtin),
    }
}

/// A world's `<light type="directional">`: the `<direction>` its light travels (Gazebo's
/// default (0, 0, -1)); `None` for other lights (rover lights the scene with one sun).
fn directional_light(ctx: &Ctx<'_, '_>, light: Node<'_, '_>) -> Result<Option<[f64; 3]>> {
    if light.attribute("type") != Some("directional") {
        return Ok(None);
    }
    let direction = match child(light, "direction") {
        Some(d) => ctx.numbers::<3>(d)?,
        None => [0.0, 0.0, -1.0],
    };
    if direction.iter().all(|v| *v == 0.0) {
        return Err(ctx.err(
            light,
            "<light type=\"directional\"><direction>0 0 0</direction>: expected a non-zero direction",
        ));
    }
    Ok(Some(direction))
}

/// `person_standing` or `person_walking` when an `<include>` brings in one of Gazebo's people
/// (they become rover people: the figure the detector is tested on, not the mesh).
fn person_model(include: Node<'_, '_>) -> Option<String> {
    let name = included_name(include)?;
    matches!(name, "person_standing" | "person_walking").then(|| name.to_owned())
}

/// An `<actor>` as Gazebo plays it: its `<skin>` (a skinned COLLADA mesh, drawn in place of
/// rover's person) posed by its `<animation>`, moved by its `<script>` (timed waypoints on a
/// spline, `loop`, `delay_start`, `auto_start`), the animation following the distance walked
/// with `<interpolate_x>`. Without a script it stands at its `<pose>`; without a skin it is
/// drawn as a rover person.
fn actor(ctx: &Ctx<'_, '_>, loader: &Loader<'_>, node: Node<'_, '_>) -> Result<Person> {
    let name = node.attribute("name").unwrap_or("actor").to_owned();
    let pose = ctx.local_pose(node)?;
    let mut person = Person::standing(
        name,
        [f64::from(pose.translation.x), f64::from(pose.translation.y)],
        yaw_of(pose.rotation),
    );
    let script = match child(node, "script") {
        Some(s) => actor_script(ctx, s)?,
        None => None,
    };
    if let Some(first) = script
        .as_ref()
        .and_then(|s| s.trajectories().first())
        .and_then(|t| t.waypoints().first())
    {
        person.position_m = first.position_m;
        person.heading_rad = first.yaw_rad;
    }
    let skin = match child(node, "skin") {
        Some(skin) => Some(Arc::new(actor_skin(ctx, loader, node, skin)?)),
        None => None,
    };
    person.actor = Some(Arc::new(Actor { script, skin }));
    Ok(person)
}

/// An `<actor>`'s `<skin>` and its `<animation>`s (the first one is played).
fn actor_skin(
    ctx: &Ctx<'_, '_>,
    loader: &Loader<'_>,
    actor: Node<'_, '_>,
    skin: Node<'_, '_>,
) -> Result<ActorSkin> {
    let base = ctx.path.parent().unwrap_or(Path::new("."));
    let file = |el: Node<'_, '_>| -> Result<(PathBuf, f32)> {
        let name = child(el, "filename")
            .ok_or_else(|| ctx.err(el, format!("<{}> needs a <filename>", el.tag_name().name())))?;
        let uri = name.text().unwrap_or("").trim();
        let path = loader
            .resources
            .resolve(uri, base)
            .map_err(|e| ctx.err(name, format!("<filename>: {e}")))?;
        let scale = match child(el, "scale") {
            Some(s) => {
                let v = ctx.number(s)?;
                if v <= 0.0 {
                    return Err(
                        ctx.err(s, format!("<scale>{v}</scale>: expected a positive factor"))
                    );
                }
                v as f32
            }
            None => 1.0,
        };
        Ok((path, scale))
    };
    let (skin_path, skin_scale) = file(skin)?;
    let mut loaded = collada_skin::load_skin(&skin_path, skin_scale)?;
    if let Some(animation) = child(actor, "animation") {
        let (path, scale) = file(animation)?;
        let interpolate_x = child(animation, "interpolate_x").is_some_and(|n| ctx.flag(n));
        loaded.clip = Some(collada_skin::load_clip(
            &path,
            scale,
            interpolate_x,
            &loaded,
        )?);
    }
    Ok(loaded)
}

/// An `<actor>`'s `<script>`: its trajectories in id order (`None` when it has none).
fn actor_script(ctx: &Ctx<'_, '_>, script: Node<'_, '_>) -> Result<Option<Script>> {
    let flag = |tag: &str, default: bool| child(script, tag).map_or(default, |n| ctx.flag(n));
    let delay_start_s = match child(script, "delay_start") {
        Some(d) => ctx.number(d)?.max(0.0),
        None => 0.0,
    };
    let mut trajectories = Vec::new();
    for t in script.children().filter(|n| n.has_tag_name("trajectory")) {
        let id: i64 = t
            .attribute("id")
            .map(|v| {
                v.trim().parse().map_err(|_| {
                    ctx.err(
                        t,
                        format!("<trajectory id=\"{v}\">: expected an integer id"),
                    )
                })
            })
            .transpose()?
            .unwrap_or(0);
        let tension = t
            .attribute("tension")
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| (0.0..=1.0).contains(v))
                    .ok_or_else(|| {
                        ctx.err(t, format!("<trajectory tension=\"{v}\">: expected 0 to 1"))
                    })
            })
            .transpose()?
            .unwrap_or(0.0);
        let mut points = Vec::new();
        for w in t.children().filter(|n| n.has_tag_name("waypoint")) {
            let time_s = child(w, "time")
                .ok_or_else(|| ctx.err(w, "<waypoint> needs a <time>"))
                .and_then(|n| ctx.number(n))?;
            let pose = child(w, "pose").ok_or_else(|| ctx.err(w, "<waypoint> needs a <pose>"))?;
            // Checked as a pose (positions in range); the yaw read as written, in f64, not
            // taken back out of the pose's f32 quaternion.
            ctx.pose(pose)?;
            let [x, y, _, _, _, yaw_rad] = ctx.numbers::<6>(pose)?;
            points.push(Waypoint {
                time_s,
                position_m: [x, y],
                yaw_rad,
            });
        }
        points.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        if points.len() < 2 {
            return Err(ctx.err(
                t,
                format!(
                    "<trajectory> has {} waypoint(s): expected at least two",
                    points.len()
                ),
            ));
        }
        // Gazebo's first keyframe is at time 0, with the first waypoint's pose.
        if points[0].time_s > 0.0 {
            let first = Waypoint {
                time_s: 0.0,
                ..points[0]
            };
            points.insert(0, first);
        } else if points[0].time_s < 0.0 {
            return Err(ctx.err(t, "<waypoint><time> is negative: expected times from 0"));
        }
        trajectories.push((id, Trajectory::new(points, tension)));
    }
    if trajectories.is_empty() {
        return Ok(None);
    }
    trajectories.sort_by_key(|t| t.0);
    let auto_start = flag("auto_start", true);
    if !auto_start {
        tracing::warn!(
            "{}: <actor> <script><auto_start>false: rover has no way to start it later; it \
             stays at its first waypoint",
            ctx.path.display()
        );
    }
    Ok(Some(Script::new(
        trajectories.into_iter().map(|t| t.1).collect(),
        flag("loop", true),
        delay_start_s,
        auto_start,
    )))
}

/// The SDF file of a model folder: the newest `<sdf>` model.config names, else model.sdf.
pub(crate) fn model_file(dir: &Path) -> std::result::Result<PathBuf, String> {
    let config = dir.join("model.config");
    if let Ok(text) = std::fs::read_to_string(&config)
        && let Ok(doc) = roxmltree::Document::parse(&text)
    {
        let best = doc
            .root_element()
            .children()
            .filter(|n| n.has_tag_name("sdf"))
            .filter_map(|n| {
                let version: f64 = n.attribute("version")?.trim().parse().ok()?;
                Some((version, n.text()?.trim().to_owned()))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, file)) = best {
            let p = dir.join(file);
            if p.is_file() {
                return Ok(p);
            }
        }
    }
    let p = dir.join("model.sdf");
    if p.is_file() {
        Ok(p)
    } else {
        Err(format!(
            "{} has neither a model.config naming an SDF file nor a model.sdf",
            dir.display()
        ))
    }
}

/// A visual's colour: `<material><diffuse>` (else `<ambient>`), else a known Gazebo material
/// script name; `None` when the file says nothing rover can use.
pub(crate) fn material_color(ctx: &Ctx<'_, '_>, visual: Node<'_, '_>) -> Result<Option<Rgba>> {
    let Some(material) = child(visual, "material") else {
        return Ok(None);
    };
    for tag in ["diffuse", "ambient"] {
        if let Some(c) = child(material, tag) {
            let text = c.text().unwrap_or("");
            let values: Vec<f32> = text
                .split_whitespace()
                .filter_map(|t| t.parse::<f32>().ok())
                .collect();
            return match values.as_slice() {
                [r, g, b] => Ok(Some(Rgba::rgb(*r, *g, *b))),
                [r, g, b, a] => Ok(Some(Rgba([*r, *g, *b, *a].map(|v| v.clamp(0.0, 1.0))))),
                _ => Err(ctx.err(
                    c,
                    format!("<{tag}>{}</{tag}>: expected 3 or 4 numbers", text.trim()),
                )),
            };
        }
    }
    let script = child(material, "script")
        .and_then(|s| child(s, "name"))
        .and_then(|n| n.text())
        .unwrap_or("")
        .trim();
    Ok(gazebo_material(script))
}

/// Colours of the common `Gazebo/*` material scripts (gazebo.material).
fn gazebo_material(name: &str) -> Option<Rgba> {
    let rgb = match name.strip_prefix("Gazebo/")? {
        "White" | "WhiteGlow" => [1.0, 1.0, 1.0],
        "Grey" | "Gray" => [0.7, 0.7, 0.7],
        "DarkGrey" | "DarkGray" => [0.35, 0.35, 0.35],
        "Black" | "FlatBlack" => [0.1, 0.1, 0.1],
        "Red" | "RedBright" => [0.8, 0.1, 0.1],
        "Green" => [0.1, 0.8, 0.1],
        "Blue" => [0.1, 0.1, 0.8],
        "Yellow" => [0.9, 0.9, 0.1],
        "Orange" => [1.0, 0.5, 0.05],
        "Purple" => [0.6, 0.1, 0.7],
        "Turquoise" => [0.1, 0.8, 0.8],
        "Wood" => [0.65, 0.45, 0.25],
        "Bricks" => [0.6, 0.3, 0.2],
        "WoodFloor" => [0.7, 0.55, 0.35],
        "Gold" => [0.85, 0.7, 0.2],
        _ => return None,
    };
    Some(Rgba::rgb(rgb[0], rgb[1], rgb[2]))
}
