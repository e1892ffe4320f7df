//! Ground truth for the camera: where every labelled thing of the world (people, objects with a
//! `class`, Gazebo models of a known class) is in the image. This file gives the full
//! ("amodal") box: the projection of the thing's whole mesh through the camera's K, occluders
//! ignored, clipped to the image, `truncated` when the clip cut it or part of it is behind the
//! camera. The meshes are the ones the camera renders, built once.

use glam::Vec3;

use crate::geometry::Pose;
use crate::model::camera_info::{CameraInfo, link_from_optical};
use crate::model::world::World;
use crate::physics::Simulation;
use crate::render::{RenderError, object_mesh, person_parts, shape_mesh};

/// Points closer to the camera than this along its axis (m) count as behind it.
const NEAR_M: f32 = 1e-3;

/// What a ground-truth box is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Labelled {
    /// A person (index in the world's people).
    Person(usize),
    /// A TOML world object with a `class` (index in the world's objects).
    Object(usize),
    /// A Gazebo model of a known class (index in the world's models).
    Model(usize),
}

/// One labelled thing's box in the image (pixels, edges: `xmin..xmax` covers the columns the
/// thing spans, like darknet_ros's boxes).
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruthBox {
    /// What it is of.
    pub entity: Labelled,
    /// Its COCO class.
    pub class: String,
    /// Its name in the world.
    pub name: String,
    /// Left edge (px, 0 at the image's left).
    pub xmin: f64,
    /// Top edge (px).
    pub ymin: f64,
    /// Right edge (px).
    pub xmax: f64,
    /// Bottom edge (px).
    pub ymax: f64,
    /// The full box was cut by the image border or by the camera's plane.
    pub truncated: bool,
}

/// Where a part of a labelled thing is each frame.
#[derive(Debug, Clone, Copy)]
enum Frame {
    /// Fixed in the world.
    World(Pose),
    /// On a person (index), at this pose in the person's frame.
    Person(usize, Pose),
    /// On a model link (index among all model links), at this pose in the link's frame.
    ModelLink(usize, Pose),
}

#[derive(Debug, Clone)]
struct Part {
    frame: Frame,
    vertices: Vec<Vec3>,
}

#[derive(Debug, Clone)]
struct Entity {
    label: Labelled,
    class: String,
    name: String,
    parts: Vec<Part>,
}

/// The labelled things of a world with their meshes' vertices, ready to project.
#[derive(Debug, Clone, Default)]
pub struct GroundTruth {
    entities: Vec<Entity>,
    /// Reused for the model links' poses.
    model_poses: Vec<Pose>,
}

fn vertices(mesh: &crate::model::MeshData) -> Vec<Vec3> {
    mesh.vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .collect()
}

impl GroundTruth {
    /// Collects the world's labelled things (their meshes as the camera renders them).
    pub fn new(world: &World) -> Result<Self, RenderError> {
        let mut entities = Vec::new();
        for (i, person) in world.people.iter().enumerate() {
            entities.push(Entity {
                label: Labelled::Person(i),
                class: "person".to_owned(),
                name: person.name.clone(),
                parts: person_parts(person)
                    .into_iter()
                    .map(|p| Part {
                        frame: Frame::Person(i, p.pose),
                        vertices: vertices(&p.mesh),
                    })
                    .collect(),
            });
        }
        for (i, object) in world.objects.iter().enumerate() {
            let Some(class) = &object.class else {
                continue;
            };
            entities.push(Entity {
                label: Labelled::Object(i),
                class: class.clone(),
                name: object.name.clone(),
                parts: vec![Part {
                    frame: Frame::World(object.world_from_object()),
                    vertices: vertices(&object_mesh(&object.shape)?),
                }],
            });
        }
        let mut link_index = 0;
        for (i, model) in world.models.iter().enumerate() {
            let first_link = link_index;
            link_index += model.links.len();
            let Some(class) = &model.class else {
                continue;
            };
            let mut parts = Vec::new();
            for (k, link) in model.links.iter().enumerate() {
                for visual in &link.visuals {
                    parts.push(Part {
                        frame: Frame::ModelLink(first_link + k, visual.link_from_shape),
                        vertices: vertices(&shape_mesh(&visual.shape)?),
                    });
                }
            }
            entities.push(Entity {
                label: Labelled::Model(i),
                class: class.clone(),
                name: model.name.clone(),
                parts,
            });
        }
        Ok(Self {
            entities,
            model_poses: Vec::new(),
        })
    }

    /// The full box of every labelled thing the camera at `world_from_camera` (its link's
    /// pose) sees at least a corner of, into `out` (cleared first).
    pub fn full_boxes(
        &mut self,
        sim: &Simulation,
        info: &CameraInfo,
        world_from_camera: Pose,
        out: &mut Vec<GroundTruthBox>,
    ) {
        out.clear();
        sim.model_link_poses_into(&mut self.model_poses);
        let optical_from_world =
            (world_from_camera * Pose::from_rotation(link_from_optical())).inverse();
        let (fx, cx, fy, cy) = (info.k[0], info.k[2], info.k[4], info.k[5]);
        let (w, h) = (f64::from(info.width), f64::from(info.height));
        for e in &self.entities {
            let mut bounds = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            let mut behind = false;
            for part in &e.parts {
                let world_from_part = match part.frame {
                    Frame::World(pose) => pose,
                    Frame::Person(i, pose) => sim.world_from_person(i) * pose,
                    Frame::ModelLink(i, pose) => {
                        self.model_poses.get(i).copied().unwrap_or_default() * pose
                    }
                };
                let optical_from_part = optical_from_world * world_from_part;
                for v in &part.vertices {
                    let p = optical_from_part * *v;
                    if p.z <= NEAR_M {
                        behind = true;
                        continue;
                    }
                    let u = fx * f64::from(p.x / p.z) + cx;
                    let v = fy * f64::from(p.y / p.z) + cy;
                    bounds = [
                        bounds[0].min(u),
                        bounds[1].min(v),
                        bounds[2].max(u),
                        bounds[3].max(v),
                    ];
                }
            }
            let [x0, y0, x1, y1] = bounds;
            let clipped = [x0.max(0.0), y0.max(0.0), x1.min(w), y1.min(h)];
            if !(clipped[0] < clipped[2] && clipped[1] < clipped[3]) {
                continue;
            }
            out.push(GroundTruthBox {
                entity: e.label,
                class: e.class.clone(),
                name: e.name.clone(),
                xmin: clipped[0],
                ymin: clipped[1],
                xmax: clipped[2],
                ymax: clipped[3],
                truncated: behind || clipped != bounds,
            });
        }
    }
}
