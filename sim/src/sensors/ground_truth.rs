//! Ground truth for the camera: where every labelled thing of the world (people, objects with a
//! `class`, Gazebo models of a known class) is in the image, from the renderer itself.
//!
//! * The **full box** (amodal): the projection of the thing's whole mesh through the camera's
//!   K (and its lens distortion), occluders ignored, clipped to the image; `truncated` when the
//!   clip cut it or part of it is behind the camera, `truncation` the fraction of the box's area
//!   the clip cut off (as KITTI's labels). The meshes are the ones the camera renders,
//!   built once.
//! * The **visible box** (tight) and visible pixel count: from the instance-id image the colour
//!   pass writes in the same draw, distorted like the colour image with nearest sampling.
//! * The **visibility fraction**: the thing's pixels in the ideal id image over the pixels it
//!   covers with nothing in front of it (the silhouette pass), both inside the image.
//! * **Ignore** regions: too small ([`MIN_VISIBLE_PX`]) or too occluded ([`MIN_VISIBILITY`]) to
//!   ask a detector for; an evaluation counts a detection there neither as right nor wrong, as
//!   COCO's `iscrowd`.

use glam::Vec3;

use crate::geometry::Pose;
use crate::model::camera_info::link_from_optical;
use crate::model::classes::EntityIds;
use crate::model::classes::Labelled;
use crate::model::sensors::Distortion;
use crate::model::world::World;
use crate::physics::Simulation;
use crate::render::{
    CameraRenderer, EntityImage, RenderError, Swing, object_mesh, person_parts, shape_mesh,
};

/// Pixels checked at once for "nothing labelled here" when counting the id image.
const ZERO_RUN_PX: usize = 32;

/// Points closer to the camera than this along its axis (m) count as behind it.
const NEAR_M: f32 = 1e-3;

/// A thing with fewer visible pixels than this (a 10 x 10 patch) is an ignore region.
pub const MIN_VISIBLE_PX: u32 = 100;

/// A thing with less than this fraction of itself visible (the rest hidden behind other
/// things) is an ignore region.
pub const MIN_VISIBILITY: f64 = 0.2;

/// A box in the image, by its edges (px): `xmin..xmax` covers the columns the thing spans
/// (pixel `i` covers `i..i + 1`), like darknet_ros's boxes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelBox {
    /// Left edge (px, 0 at the image's left).
    pub xmin: f64,
    /// Top edge (px, 0 at the top).
    pub ymin: f64,
    /// Right edge (px).
    pub xmax: f64,
    /// Bottom edge (px).
    pub ymax: f64,
}

impl PixelBox {
    /// Width (px).
    pub fn width(&self) -> f64 {
        (self.xmax - self.xmin).max(0.0)
    }

    /// Height (px).
    pub fn height(&self) -> f64 {
        (self.ymax - self.ymin).max(0.0)
    }

    /// Area (px^2).
    pub fn area(&self) -> f64 {
        self.width() * self.height()
    }

    /// Intersection over union with `other` (0 when either is empty).
    pub fn iou(&self, other: &PixelBox) -> f64 {
        let inter = PixelBox {
            xmin: self.xmin.max(other.xmin),
            ymin: self.ymin.max(other.ymin),
            xmax: self.xmax.min(other.xmax),
            ymax: self.ymax.min(other.ymax),
        }
        .area();
        let union = self.area() + other.area() - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
}

/// One labelled thing in one image. Cloning into an existing box reuses its strings
/// (`clone_from`), so per-frame copies ([`copy_boxes`]) do not allocate.
#[derive(Debug, PartialEq)]
pub struct GroundTruthBox {
    /// Its number in the id image ([`EntityIds`], from 1).
    pub id: u32,
    /// What it is of.
    pub entity: Labelled,
    /// Its COCO class.
    pub class: String,
    /// Its name in the world.
    pub name: String,
    /// The full (amodal) box, clipped to the image.
    pub full: PixelBox,
    /// The tight box around its visible pixels (`None`: nothing of it is visible).
    pub visible: Option<PixelBox>,
    /// How many pixels of the output image show it.
    pub visible_px: u32,
    /// How many pixels of the ideal image it would cover with nothing in front of it.
    pub unoccluded_px: u32,
    /// Visible fraction of what would be seen with nothing in front (0..1).
    pub visibility: f64,
    /// The image border or the camera's plane cut its full box.
    pub truncated: bool,
    /// The fraction of its full box's area outside the image (0..1, as KITTI's `truncated`);
    /// 1 when part of it is behind the camera (its projection is then unbounded).
    pub truncation: f64,
    /// Too small or too occluded to ask a detector for (see [`MIN_VISIBLE_PX`],
    /// [`MIN_VISIBILITY`]): neither a miss nor a false positive. A truncated thing is asked
    /// for: its visible box is what a detector should draw.
    pub ignore: bool,
}

impl Clone for GroundTruthBox {
    fn clone(&self) -> Self {
        Self {
            class: self.class.clone(),
            name: self.name.clone(),
            ..*self
        }
    }

    fn clone_from(&mut self, source: &Self) {
        let (mut class, mut name) = (
            std::mem::take(&mut self.class),
            std::mem::take(&mut self.name),
        );
        class.clone_from(&source.class);
        name.clone_from(&source.name);
        *self = Self {
            class,
            name,
            ..*source
        };
    }
}

/// Copies `from` into `out`, reusing the boxes (and their strings) already there.
pub fn copy_boxes(out: &mut Vec<GroundTruthBox>, from: &[GroundTruthBox]) {
    copy_boxes_from(out, from.iter());
}

fn copy_boxes_from<'a>(
    out: &mut Vec<GroundTruthBox>,
    from: impl Iterator<Item = &'a GroundTruthBox>,
) {
    let mut n = 0;
    for b in from {
        match out.get_mut(n) {
            Some(slot) => slot.clone_from(b),
            None => out.push(b.clone()),
        }
        n += 1;
    }
    out.truncate(n);
}

/// Where a part of a labelled thing is each frame.
#[derive(Debug, Clone, Copy)]
enum Frame {
    /// On a world object (index), at this pose in the object's frame.
    Object(usize, Pose),
    /// On a person (index), at this pose in the person's frame standing, moving so as they
    /// walk.
    Person(usize, Pose, Swing),
    /// On a model link (index among all model links), at this pose in the link's frame.
    ModelLink(usize, Pose),
    /// MakeHuman's body of a person (index), as the renderer posed it this frame (the part's
    /// own `vertices` stay empty).
    Body(usize),
}

#[derive(Debug, Clone)]
struct Part {
    frame: Frame,
    vertices: Vec<Vec3>,
}

#[derive(Debug, Clone)]
struct Entity {
    id: u32,
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
    /// Reused for the world objects' poses.
    object_poses: Vec<Pose>,
    /// Reused per frame: per entity (index `id - 1`), visible pixels of the output image and
    /// of the ideal image, and the visible box's pixel bounds.
    visible: Vec<Visible>,
    /// Every entity's box this frame, in id order (strings made once).
    all: Vec<GroundTruthBox>,
}

#[derive(Debug, Clone, Copy)]
struct Visible {
    px: u32,
    ideal_px: u32,
    bounds: [u32; 4],
}

impl Default for Visible {
    fn default() -> Self {
        Self {
            px: 0,
            ideal_px: 0,
            bounds: [u32::MAX, u32::MAX, 0, 0],
        }
    }
}

fn vertices(mesh: &crate::model::MeshData) -> Vec<Vec3> {
    mesh.vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .collect()
}

impl GroundTruth {
    /// Collects the world's labelled things (their meshes as `renderer` draws them: people
    /// with MakeHuman's body are read from its posed vertices each frame).
    pub fn new(world: &World, renderer: &CameraRenderer) -> Result<Self, RenderError> {
        let ids = EntityIds::new(world);
        let mut entities = Vec::new();
        for (i, person) in world.people.iter().enumerate() {
            let parts = if renderer.posed_person(i).is_some() {
                vec![Part {
                    frame: Frame::Body(i),
                    vertices: Vec::new(),
                }]
            } else {
                person_parts(person)
                    .into_iter()
                    .map(|p| Part {
                        frame: Frame::Person(i, p.pose, p.swing),
                        vertices: vertices(&p.mesh),
                    })
                    .collect()
            };
            entities.push(Entity {
                id: ids.person(i),
                label: Labelled::Person(i),
                class: "person".to_owned(),
                name: person.name.clone(),
                parts,
            });
        }
        for (i, object) in world.objects.iter().enumerate() {
            let Some(class) = &object.class else {
                continue;
            };
            entities.push(Entity {
                id: ids.object(i),
                label: Labelled::Object(i),
                class: class.clone(),
                name: object.name.clone(),
                parts: vec![Part {
                    frame: Frame::Object(i, Pose::IDENTITY),
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
                    let mut mesh = shape_mesh(&visual.shape)?;
                    if let Some(above_m) = model.label_above_m {
                        // Only the labelled part, as the renderer labels it.
                        let model_from_shape = model.world_from_model.inverse()
                            * link.world_from_link
                            * visual.link_from_shape;
                        mesh = mesh.split_at_height(model_from_shape, above_m).0;
                    }
                    parts.push(Part {
                        frame: Frame::ModelLink(first_link + k, visual.link_from_shape),
                        vertices: vertices(&mesh),
                    });
                }
            }
            entities.push(Entity {
                id: ids.model(i),
                label: Labelled::Model(i),
                class: class.clone(),
                name: model.name.clone(),
                parts,
            });
        }
        let empty = PixelBox {
            xmin: 0.0,
            ymin: 0.0,
            xmax: 0.0,
            ymax: 0.0,
        };
        let all = entities
            .iter()
            .map(|e| GroundTruthBox {
                id: e.id,
                entity: e.label,
                class: e.class.clone(),
                name: e.name.clone(),
                full: empty,
                visible: None,
                visible_px: 0,
                unoccluded_px: 0,
                visibility: 0.0,
                truncated: false,
                truncation: 0.0,
                ignore: true,
            })
            .collect();
        Ok(Self {
            visible: vec![Visible::default(); entities.len()],
            entities,
            model_poses: Vec::new(),
            object_poses: Vec::new(),
            all,
        })
    }

    /// Every labelled thing the camera at `world_from_camera` (its link's pose) sees at least
    /// a corner of, or a pixel of, in `image` (the renderer's entity image of the same frame),
    /// into `out` (cleared first), in id order.
    pub fn measure(
        &mut self,
        sim: &Simulation,
        renderer: &CameraRenderer,
        world_from_camera: Pose,
        image: &EntityImage,
        out: &mut Vec<GroundTruthBox>,
    ) {
        self.count_visible(image);
        self.full_boxes(sim, renderer, world_from_camera);
        for (b, seen) in self.all.iter_mut().zip(&self.visible) {
            let i = (b.id - 1) as usize;
            b.visible_px = seen.px;
            b.unoccluded_px = image.silhouette_px.get(i).copied().unwrap_or(0);
            b.visibility = if b.unoccluded_px > 0 {
                (f64::from(seen.ideal_px) / f64::from(b.unoccluded_px)).min(1.0)
            } else {
                0.0
            };
            b.visible = (seen.px > 0).then(|| {
                let [x0, y0, x1, y1] = seen.bounds;
                PixelBox {
                    xmin: f64::from(x0),
                    ymin: f64::from(y0),
                    xmax: f64::from(x1) + 1.0,
                    ymax: f64::from(y1) + 1.0,
                }
            });
            b.ignore = b.visible_px < MIN_VISIBLE_PX || b.visibility < MIN_VISIBILITY;
        }
        copy_boxes_from(
            out,
            self.all
                .iter()
                .filter(|b| b.full.xmax > b.full.xmin || b.visible_px > 0),
        );
    }

    /// Per entity: visible pixels (output and ideal image) and the visible pixels' bounds.
    fn count_visible(&mut self, image: &EntityImage) {
        self.visible.fill(Visible::default());
        let w = image.width as usize;
        for (y, row) in image.ids.chunks_exact(w).enumerate() {
            // Most of an image shows nothing labelled: skip it a run of pixels at a time.
            for (c, run) in row.chunks(ZERO_RUN_PX).enumerate() {
                if run.iter().fold(0, |any, &id| any | id) == 0 {
                    continue;
                }
                for (k, &id) in run.iter().enumerate() {
                    if id == 0 {
                        continue;
                    }
                    if let Some(v) = self.visible.get_mut(id as usize - 1) {
                        let (x, y) = ((c * ZERO_RUN_PX + k) as u32, y as u32);
                        v.px += 1;
                        v.bounds = [
                            v.bounds[0].min(x),
                            v.bounds[1].min(y),
                            v.bounds[2].max(x),
                            v.bounds[3].max(y),
                        ];
                    }
                }
            }
        }
        if !image.distorted {
            for v in &mut self.visible {
                v.ideal_px = v.px;
            }
            return;
        }
        for &id in &image.ideal_ids {
            if id != 0
                && let Some(v) = self.visible.get_mut(id as usize - 1)
            {
                v.ideal_px += 1;
            }
        }
    }

    /// The full box and truncation of every labelled thing (`self.all`); an entity wholly
    /// outside the image gets an empty box.
    fn full_boxes(&mut self, sim: &Simulation, renderer: &CameraRenderer, world_from_camera: Pose) {
        let info = renderer.info();
        sim.model_link_poses_into(&mut self.model_poses);
        sim.object_poses_into(&mut self.object_poses);
        let optical_from_world =
            (world_from_camera * Pose::from_rotation(link_from_optical())).inverse();
        let (fx, cx, fy, cy) = (info.k[0], info.k[2], info.k[4], info.k[5]);
        let [k1, k2, p1, p2, k3] = info.d;
        let lens = Distortion { k1, k2, k3, p1, p2 };
        let distorted = !lens.is_zero();
        let (w, h) = (f64::from(info.width), f64::from(info.height));
        for (e, out) in self.entities.iter().zip(self.all.iter_mut()) {
            let mut bounds = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            let mut behind = false;
            for part in &e.parts {
                let world_from_part = match part.frame {
                    Frame::Object(i, pose) => {
                        self.object_poses.get(i).copied().unwrap_or_default() * pose
                    }
                    Frame::Person(i, pose, swing) => {
                        sim.world_from_person(i) * swing.pose_at(pose, sim.person_gait_phase_rad(i))
                    }
                    Frame::ModelLink(i, pose) => {
                        self.model_poses.get(i).copied().unwrap_or_default() * pose
                    }
                    Frame::Body(i) => sim.world_from_person(i),
                };
                let part_vertices = match part.frame {
                    Frame::Body(i) => renderer.posed_person(i).unwrap_or(&part.vertices),
                    _ => &part.vertices,
                };
                let optical_from_part = optical_from_world * world_from_part;
                for v in part_vertices {
                    let p = optical_from_part * *v;
                    if p.z <= NEAR_M {
                        behind = true;
                        continue;
                    }
                    let (mut x, mut y) = (f64::from(p.x / p.z), f64::from(p.y / p.z));
                    if distorted {
                        (x, y) = lens.distort(x, y);
                    }
                    // K puts pixel centres at integer coordinates: pixel i spans i-0.5..i+0.5,
                    // so its edges are 0.5 further on.
                    let u = fx * x + cx + 0.5;
                    let v = fy * y + cy + 0.5;
                    bounds = [
                        bounds[0].min(u),
                        bounds[1].min(v),
                        bounds[2].max(u),
                        bounds[3].max(v),
                    ];
                }
            }
            let clipped = [
                bounds[0].clamp(0.0, w),
                bounds[1].clamp(0.0, h),
                bounds[2].clamp(0.0, w),
                bounds[3].clamp(0.0, h),
            ];
            let full = if clipped[0] < clipped[2] && clipped[1] < clipped[3] {
                PixelBox {
                    xmin: clipped[0],
                    ymin: clipped[1],
                    xmax: clipped[2],
                    ymax: clipped[3],
                }
            } else {
                PixelBox {
                    xmin: 0.0,
                    ymin: 0.0,
                    xmax: 0.0,
                    ymax: 0.0,
                }
            };
            let whole_area = (bounds[2] - bounds[0]) * (bounds[3] - bounds[1]);
            out.truncation = if behind {
                1.0
            } else if whole_area > 0.0 {
                (1.0 - full.area() / whole_area).clamp(0.0, 1.0)
            } else {
                0.0
            };
            out.full = full;
            out.truncated = behind || clipped != bounds;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thing(class: &str, px: u32) -> GroundTruthBox {
        let b = PixelBox {
            xmin: 1.0,
            ymin: 2.0,
            xmax: 3.0,
            ymax: 4.0,
        };
        GroundTruthBox {
            id: 1,
            entity: Labelled::Person(0),
            class: class.into(),
            name: "alice".into(),
            full: b,
            visible: Some(b),
            visible_px: px,
            unoccluded_px: px,
            visibility: 1.0,
            truncated: false,
            truncation: 0.0,
            ignore: false,
        }
    }

    #[test]
    fn copying_boxes_reuses_the_boxes_and_strings_already_there() {
        let mut out = Vec::new();
        copy_boxes(&mut out, &[thing("person", 10), thing("dog", 20)]);
        let person_text = out[0].class.as_ptr();
        copy_boxes(&mut out, &[thing("person", 30)]);
        assert_eq!(out, vec![thing("person", 30)]);
        assert_eq!(
            out[0].class.as_ptr(),
            person_text,
            "the string was reallocated"
        );
    }
}
