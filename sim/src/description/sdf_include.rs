//! Bringing in a Gazebo model folder: an SDF `<include>` (`model://NAME`, a Fuel URL or a
//! folder), and a TOML world's `[[model]]` ([`include_model`]), both through one path: the
//! folder, its `model.config`'s newest SDF, that file's `<model>` placed at a pose.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use roxmltree::Node;
use serde::Deserialize;

use crate::description::resource::ResourcePaths;
use crate::description::sdf::{Ctx, Loader, MAX_INCLUDE_DEPTH, Overrides, model_file};
use crate::description::xml::{child, parse_xml};
use crate::error::{Result, SimError};
use crate::geometry::{MAX_COORDINATE_M, Pose, pose_from_xyz_rpy};
use crate::model::world::Model;

impl Loader<'_> {
    /// An SDF `<include>` at `node`, under a model placed at `parent`: its models into `out`.
    pub(crate) fn include(
        &mut self,
        ctx: &Ctx<'_, '_>,
        node: Node<'_, '_>,
        parent: Pose,
        out: &mut Vec<Model>,
        depth: usize,
    ) -> Result<()> {
        if depth > MAX_INCLUDE_DEPTH {
            return Err(ctx.err(
                node,
                format!(
                    "<include> nested deeper than {MAX_INCLUDE_DEPTH}: does a model include itself?"
                ),
            ));
        }
        let uri_node =
            child(node, "uri").ok_or_else(|| ctx.err(node, "<include> needs a <uri>"))?;
        let uri = uri_node.text().unwrap_or("").trim();
        let base = ctx.path.parent().unwrap_or(Path::new("."));
        let file = self
            .model_sdf(uri, base)
            .map_err(|m| ctx.err(uri_node, format!("<include><uri>{uri}</uri>: {m}")))?;
        // The include's <pose> places the model's frame (its own <pose> is relative to it).
        let placed = parent * ctx.local_pose(node)?;
        let overrides = Overrides {
            name: child(node, "name")
                .and_then(|n| n.text())
                .map(|s| s.trim().to_owned()),
            is_static: child(node, "static").map(|s| ctx.flag(s)),
            uri_name: uri_model_name(uri),
        };
        self.model_from_file(&file, placed, overrides, out, depth)
    }

    /// The SDF file of the model folder `uri` names (`model://NAME` through the model paths, a
    /// Fuel URL from its local cache, else a folder, relative to `base`); else why not.
    fn model_sdf(&self, uri: &str, base: &Path) -> std::result::Result<PathBuf, String> {
        let dir = if let Some(name) = uri.strip_prefix("model://") {
            (self.resources.find_model(name.trim_end_matches('/'))).map_err(|e| e.to_string())?
        } else if let Some(fuel) = super::fuel::parse(uri) {
            super::fuel::find_local(&fuel, self.resources).map_err(|e| e.to_string())?
        } else {
            let p = PathBuf::from(uri.strip_prefix("file://").unwrap_or(uri));
            let p = if p.is_absolute() { p } else { base.join(p) };
            if !p.is_dir() {
                return Err(format!("no model folder at {}", p.display()));
            }
            p
        };
        model_file(&dir)
    }

    /// The `<model>` of SDF `file`, its frame at `placed`, with `overrides`.
    fn model_from_file(
        &mut self,
        file: &Path,
        placed: Pose,
        overrides: Overrides,
        out: &mut Vec<Model>,
        depth: usize,
    ) -> Result<()> {
        let text = crate::io::read_text(file)?;
        let doc = parse_xml(&text, file)?;
        let inner = Ctx {
            path: file,
            doc: &doc,
        };
        let root = doc.root_element();
        let model = if root.has_tag_name("model") {
            Some(root)
        } else {
            child(root, "model")
        };
        let model = model.ok_or_else(|| inner.err(root, "expected an <sdf> with a <model>"))?;
        self.model(&inner, model, placed, Some(overrides), out, depth)
    }
}

/// The `NAME` of a `model://NAME` URI.
fn uri_model_name(uri: &str) -> Option<String> {
    uri.strip_prefix("model://")
        .map(|n| n.trim_end_matches('/').to_owned())
}

/// A model folder as a TOML world's `[[model]]` brings it in: `uri` (`model://NAME` through
/// `resources`' model paths, a Fuel URL, or a folder relative to the world file `world_path`),
/// its frame at `world_from_model`, renamed `name` and made static or not when given. Its
/// models (a model with nested models or includes gives several); an error naming the world
/// file's `entry` (`model[2]`) when the folder or its SDF is missing or bad.
pub(crate) fn include_model(
    world_path: &Path,
    entry: &str,
    resources: &ResourcePaths,
    (uri, world_from_model): (&str, Pose),
    (name, is_static): (Option<String>, Option<bool>),
) -> Result<Vec<Model>> {
    let mut loader = Loader {
        resources,
        skipped: BTreeSet::new(),
    };
    let base = world_path.parent().unwrap_or(Path::new("."));
    let file = loader.model_sdf(uri, base).map_err(|m| {
        SimError::invalid(world_path, None, format!("{entry}.uri = \"{uri}\": {m}"))
    })?;
    let overrides = Overrides {
        name,
        is_static,
        uri_name: uri_model_name(uri),
    };
    let mut out = Vec::new();
    loader.model_from_file(&file, world_from_model, overrides, &mut out, 0)?;
    if !loader.skipped.is_empty() {
        let skipped: Vec<String> = loader.skipped.into_iter().collect();
        tracing::info!(
            "{}: {entry} ({uri}): not simulated (rover has no model for them): {}",
            world_path.display(),
            skipped.join(", ")
        );
    }
    Ok(out)
}

/// A TOML world's `[[model]]`: a Gazebo model folder placed in the world (docs/WORLDS.md).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawModel {
    /// `model://NAME`, a Fuel URL, or a folder relative to the world file.
    uri: String,
    /// Its name in the world (default: the model's own).
    name: Option<String>,
    /// Where the model's frame is (x, y, z, m): as an `<include>`'s `<pose>`.
    position_m: [f64; 3],
    /// Its turn about z (deg).
    #[serde(default)]
    yaw_deg: f64,
    /// Static (fixed in the world) or not; default: the model's own `<static>`.
    #[serde(rename = "static")]
    is_static: Option<bool>,
}

impl RawModel {
    /// The models it brings in, entry `index` of the world file `path`, through `resources`.
    pub(crate) fn into_models(
        self,
        index: usize,
        path: &Path,
        resources: &ResourcePaths,
    ) -> Result<Vec<Model>> {
        let entry = format!("model[{index}]");
        let numbers = self.position_m.iter().chain([&self.yaw_deg]);
        if let Some(bad) = numbers
            .copied()
            .find(|v| !v.is_finite() || v.abs() > MAX_COORDINATE_M)
        {
            return Err(SimError::invalid(
                path,
                None,
                format!(
                    "{entry}: {bad} is out of range: expected finite numbers within {MAX_COORDINATE_M:e} of zero"
                ),
            ));
        }
        let [x, y, z] = self.position_m;
        let pose = pose_from_xyz_rpy([x, y, z], [0.0, 0.0, self.yaw_deg.to_radians()]);
        include_model(
            path,
            &entry,
            resources,
            (&self.uri, pose),
            (self.name, self.is_static),
        )
    }
}
