//! A person's skinned body as every view draws it: MakeHuman's body posed by rover's gait, or
//! a Gazebo actor's own skin posed by its animation. The camera's renderer, the ground truth
//! (through the renderer's posed vertices) and the Rerun viewer all pose it the same way.

use std::sync::Arc;

use glam::Vec3;

use crate::geometry::Rgba;
use crate::model::actor::{Actor, BoneCapsule, PosedSkin};
use crate::model::human::{Body, Layer, PosedBody, Posture};
use crate::model::person::Person;
use crate::render::mesh::Paint;

/// Grid cells (m) of the coarser levels of detail of MakeHuman's bodies
/// ([`Body::coarse_layers`]), drawn by the camera from a distance on.
pub(crate) const DETAIL_CELLS_M: [f32; 2] = [0.03, 0.06];

/// One layer of a body: its paint, its triangles and its coarser levels of detail
/// ([`DETAIL_CELLS_M`]; empty for an actor's skin, drawn in full at every distance).
#[derive(Debug, Clone)]
pub struct BodyLayer {
    /// Where its colour comes from.
    pub paint: Paint,
    /// Triangles, as indices into the posed vertices.
    pub indices: Vec<u32>,
    /// The same at coarser levels of detail.
    pub coarse: Vec<Vec<u32>>,
}

/// What a skinned person's vertices are posed from, with the posed result.
enum Skin {
    /// MakeHuman's body, posed by rover's gait.
    Human(Box<Body>, PosedBody),
    /// A Gazebo actor's skin, posed by its animation.
    Actor(Arc<Actor>, PosedSkin),
}

impl Skin {
    /// Poses the vertices for gait phase `phase_rad` (an actor: the clip's time as a
    /// fraction of a turn) and stride `stride_m` (MakeHuman's walk).
    fn pose(&mut self, phase_rad: f64, stride_m: f64) {
        match self {
            Self::Human(body, posed) => body.pose(Posture::from_gait(phase_rad, stride_m), posed),
            Self::Actor(actor, posed) => {
                if let Some(skin) = &actor.skin {
                    let duration_s = skin.clip.as_ref().map_or(0.0, |c| c.duration_s);
                    let time_s = phase_rad / std::f64::consts::TAU * duration_s;
                    skin.pose(time_s, actor.carried(), posed);
                }
            }
        }
    }

    fn positions(&self) -> &[Vec3] {
        match self {
            Self::Human(_, posed) => &posed.positions,
            Self::Actor(_, posed) => &posed.positions,
        }
    }

    fn normals(&self) -> &[Vec3] {
        match self {
            Self::Human(_, posed) => &posed.normals,
            Self::Actor(_, posed) => &posed.normals,
        }
    }

    /// Each layer's paint, its triangles, and its coarser levels of detail.
    fn layers(&self) -> Vec<BodyLayer> {
        match self {
            Self::Human(body, _) => {
                let coarse: Vec<Vec<Vec<u32>>> = DETAIL_CELLS_M
                    .iter()
                    .map(|&cell| body.coarse_layers(cell))
                    .collect();
                body.layers()
                    .iter()
                    .enumerate()
                    .map(|(k, (layer, indices))| {
                        let levels = coarse
                            .iter()
                            .map(|level| level.get(k).cloned().unwrap_or_default())
                            .collect();
                        BodyLayer {
                            paint: layer_paint(*layer),
                            indices: indices.clone(),
                            coarse: levels,
                        }
                    })
                    .collect()
            }
            Self::Actor(actor, _) => actor
                .skin
                .iter()
                .flat_map(|skin| skin.layers())
                .map(|(color, indices)| BodyLayer {
                    paint: Paint::Fixed(*color),
                    indices: indices.clone(),
                    coarse: Vec::new(),
                })
                .collect(),
        }
    }
}

/// A person's skinned body and its posed vertices.
pub struct SkinnedBody(Skin);

impl std::fmt::Debug for SkinnedBody {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match &self.0 {
            Skin::Human(..) => "MakeHuman",
            Skin::Actor(..) => "actor",
        };
        write!(
            f,
            "SkinnedBody({kind}, {} vertices)",
            self.positions().len()
        )
    }
}

impl SkinnedBody {
    /// The skinned body `person` is drawn with: an actor's own skin, else MakeHuman's body;
    /// `None` when they are drawn as rover's figure (asked for, or MakeHuman's body could not
    /// be had). Posed as at sim time 0.
    pub fn of(person: &Person) -> Option<Self> {
        let skin = if let Some(actor) = person.actor.as_ref().filter(|a| a.skin.is_some()) {
            Skin::Actor(actor.clone(), PosedSkin::default())
        } else {
            let shape = person.shape?;
            let human = crate::model::human::shared()?;
            match human.body(shape, person.height_m, person.outfit) {
                Ok(body) => Skin::Human(Box::new(body), PosedBody::default()),
                Err(e) => {
                    tracing::warn!("{}: drawn as rover's figure: {e}", person.name);
                    return None;
                }
            }
        };
        let mut body = Self(skin);
        body.pose(person.gait_phase_rad(0.0), person.stride_m());
        Some(body)
    }

    /// Poses the vertices for gait phase `phase_rad` ([`Person::gait_phase_rad`]; an actor:
    /// its clip's time as a fraction of a turn) and stride `stride_m` (MakeHuman's walk).
    pub fn pose(&mut self, phase_rad: f64, stride_m: f64) {
        self.0.pose(phase_rad, stride_m);
    }

    /// The posed vertex positions (m, the person's frame).
    pub fn positions(&self) -> &[Vec3] {
        self.0.positions()
    }

    /// The posed vertex normals.
    pub fn normals(&self) -> &[Vec3] {
        self.0.normals()
    }

    /// The layers, each with its paint and triangles.
    pub fn layers(&self) -> Vec<BodyLayer> {
        self.0.layers()
    }

    /// The body's bones as capsules for range sensors (indices into the joints
    /// [`SkinnedBody::pose_joints`] gives), each as thick as the skin it moves.
    pub fn bone_capsules(&self) -> Vec<BoneCapsule> {
        match &self.0 {
            Skin::Human(body, _) => body.bone_capsules(),
            Skin::Actor(actor, _) => actor
                .skin
                .as_ref()
                .map(|s| s.bone_capsules())
                .unwrap_or_default(),
        }
    }

    /// The skeleton's joints (m, the person's frame) at gait phase `phase_rad` and stride
    /// `stride_m` (as [`SkinnedBody::pose`]), into `joints`; the vertices are left as they were.
    pub fn pose_joints(&mut self, phase_rad: f64, stride_m: f64, joints: &mut Vec<Vec3>) {
        match &mut self.0 {
            Skin::Human(body, posed) => {
                body.pose_joints(Posture::from_gait(phase_rad, stride_m), posed, joints);
            }
            Skin::Actor(actor, posed) => {
                if let Some(skin) = &actor.skin {
                    let duration_s = skin.clip.as_ref().map_or(0.0, |c| c.duration_s);
                    let time_s = phase_rad / std::f64::consts::TAU * duration_s;
                    skin.pose_joints(time_s, actor.carried(), posed);
                }
                joints.clear();
                joints.extend(posed.joints.iter().map(|m| Vec3::from(m.translation)));
            }
        }
    }
}

/// The paint a body layer wears.
fn layer_paint(layer: Layer) -> Paint {
    match layer {
        Layer::Skin => Paint::Skin,
        Layer::Shirt => Paint::Shirt,
        Layer::Trousers => Paint::Trousers,
        Layer::Hair => Paint::Hair,
        Layer::Shoes => Paint::Fixed(Rgba::rgb(0.08, 0.08, 0.09)),
        Layer::Eyes => Paint::Fixed(Rgba::rgb(0.12, 0.09, 0.07)),
    }
}
