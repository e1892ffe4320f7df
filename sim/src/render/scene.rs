//! What the camera sees, on the GPU: every mesh of the world, its people and models and the
//! robot's visuals uploaded once, one instance (transform, colour and labelled-entity id) per
//! drawn mesh. Per frame only the transforms of things that move change. Passes draw the same
//! scene.

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::geometry::{Pose, Rgba};
use crate::model::classes::EntityIds;
use crate::model::human::{BodyShape, Outfit};
use crate::model::mesh::MeshData;
use crate::model::person::Person;
use crate::model::robot::RobotModel;
use crate::model::world::World;
use crate::render::body::{BodyLayer, SkinnedBody};
use crate::render::gpu::RenderError;
use crate::render::material::Materials;
use crate::render::mesh::{Paint, Swing, cuboid, object_mesh, person_parts, visual_mesh};

/// Per-instance vertex data: the model matrix, the colour (alpha < 0 marks the checkered
/// ground) and the labelled entity the mesh belongs to ([`EntityIds`]; 0: none).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Instance {
    model: [[f32; 4]; 4],
    color: [f32; 4],
    entity: u32,
}

impl Instance {
    fn new(pose: Pose, color: Rgba, entity: u32) -> Self {
        Self {
            model: matrix(pose),
            color: color.0,
            entity,
        }
    }
}

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 8 => Float32x2];
const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 6] = wgpu::vertex_attr_array![2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4, 7 => Uint32];

/// The vertex buffers every pass's vertex shader reads: slot 0 the mesh's vertices (location 0:
/// position, 1: normal, 8: texture coordinates), slot 1 the instances (2-5: model matrix columns, 6: colour, 7: entity).
pub(crate) fn vertex_buffer_layouts() -> [Option<wgpu::VertexBufferLayout<'static>>; 2] {
    [
        Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<GpuVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX_ATTRIBUTES,
        }),
        Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Instance>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &INSTANCE_ATTRIBUTES,
        }),
    ]
}

fn matrix(pose: Pose) -> [[f32; 4]; 4] {
    Mat4::from_rotation_translation(pose.rotation, pose.translation).to_cols_array_2d()
}

/// One vertex as the passes read it (location 0: position, 1: normal, 8: texture
/// coordinates). The model's [`MeshData`] stays plain data; this layout is the renderer's own.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuVertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
}

/// One uploaded mesh.
pub(crate) struct GpuMesh {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    /// Runs of indices and the material (bind group in [`Materials`]) each is drawn with.
    pub(crate) draws: Vec<Draw>,
}

/// A run of a mesh's indices drawn with one material.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Draw {
    pub(crate) first_index: u32,
    pub(crate) count: u32,
    pub(crate) material: u32,
}

/// A drawn shape whose instance follows a moving frame (a robot link, a person, a model link).
#[derive(Debug, Clone, Copy)]
struct Attached {
    instance: usize,
    /// Index of the frame it follows (robot link, person or model link, in world order).
    frame: usize,
    frame_from_shape: Pose,
}

/// The uploaded scene: mesh `i` is drawn with instance `i`.
pub(crate) struct Scene {
    pub(crate) meshes: Vec<GpuMesh>,
    /// The textures and flags the meshes' draws bind.
    pub(crate) materials: Materials,
    /// The meshes of labelled things (indices into `meshes`).
    pub(crate) labelled: Vec<u32>,
    instances: Vec<Instance>,
    pub(crate) instance_buffer: wgpu::Buffer,
    robot: Vec<Attached>,
    /// Every figure part, with where its colour comes from.
    people: Vec<(Attached, Paint, Swing)>,
    /// The people drawn with MakeHuman's body.
    bodies: Vec<SkinnedPerson>,
    /// Visuals of every SDF model link.
    models: Vec<Attached>,
    /// Whether some model link can move on its own (physics).
    moving_models: bool,
    /// One instance per world object, in world order.
    objects: Vec<usize>,
}

impl Scene {
    /// The labelled entity mesh `mesh` belongs to (0: none).
    pub(crate) fn entity_of(&self, mesh: u32) -> u32 {
        self.instances.get(mesh as usize).map_or(0, |i| i.entity)
    }
}

/// Collects meshes and instances before the instance buffer exists.
struct Builder<'d> {
    device: &'d wgpu::Device,
    queue: &'d wgpu::Queue,
    materials: Materials,
    meshes: Vec<GpuMesh>,
    instances: Vec<Instance>,
    labelled: Vec<u32>,
}

impl Builder<'_> {
    fn add(&mut self, mesh: &MeshData, pose: Pose, color: Rgba, entity: u32) -> usize {
        let device = self.device;
        let vertices: Vec<GpuVertex> = mesh
            .vertices
            .iter()
            .enumerate()
            .map(|(i, v)| GpuVertex {
                position: v.position,
                normal: v.normal,
                uv: mesh.uvs.get(i).copied().unwrap_or_default(),
            })
            .collect();
        let draws = self.draws(mesh);
        self.meshes.push(GpuMesh {
            draws,
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
        });
        self.instances.push(Instance::new(pose, color, entity));
        if entity != 0 && entity != EntityIds::ROBOT {
            self.labelled.push(self.meshes.len() as u32 - 1);
        }
        self.instances.len() - 1
    }
}

impl Builder<'_> {
    /// The mesh's textured runs with its own colour between them, in index order.
    fn draws(&mut self, mesh: &MeshData) -> Vec<Draw> {
        let mut runs: Vec<_> = mesh.textured.iter().collect();
        runs.sort_by_key(|r| r.first_index);
        let total = mesh.indices.len() as u32;
        let mut draws = Vec::with_capacity(runs.len() * 2 + 1);
        let mut at = 0;
        for run in runs {
            let (start, end) = (
                run.first_index.min(total),
                (run.first_index + run.count).min(total),
            );
            if start < at || start >= end {
                continue;
            }
            if start > at {
                draws.push(Draw {
                    first_index: at,
                    count: start - at,
                    material: 0,
                });
            }
            let material = self
                .materials
                .textured(self.device, self.queue, &run.texture);
            draws.push(Draw {
                first_index: start,
                count: end - start,
                material,
            });
            at = end;
        }
        if at < total {
            draws.push(Draw {
                first_index: at,
                count: total - at,
                material: 0,
            });
        }
        draws
    }
}

impl Scene {
    /// Uploads the ground, objects, SDF models, people and the robot's visuals (at the origin
    /// until the first [`Scene::set_robot_link_poses`]); labelled things carry their `ids`.
    pub(crate) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        world: &World,
        robot: &RobotModel,
        ids: &EntityIds,
    ) -> Result<Self, RenderError> {
        let mut b = Builder {
            device,
            queue,
            materials: Materials::new(device, queue),
            meshes: Vec::new(),
            instances: Vec::new(),
            labelled: Vec::new(),
        };
        let [gx, gy] = world.ground.size_m;
        let ground = cuboid(Vec3::new(gx as f32, gy as f32, 0.02));
        let mut ground_color = world.ground.color;
        ground_color.0[3] = -1.0;
        b.add(
            &ground,
            Pose::from_translation(Vec3::new(0.0, 0.0, -0.01)),
            ground_color,
            0,
        );
        let mut objects = Vec::with_capacity(world.objects.len());
        for (i, object) in world.objects.iter().enumerate() {
            let mesh = object_mesh(&object.shape)?;
            objects.push(b.add(
                &mesh,
                object.world_from_object(),
                object.color,
                ids.object(i),
            ));
        }
        let models = add_models(&mut b, world, ids)?;
        let moving_models = world
            .models
            .iter()
            .any(|m| m.links.iter().any(|l| l.is_dynamic(m)));
        let (people, bodies) = add_people(&mut b, world, ids);
        let mut attached = Vec::new();
        for (link_index, link) in robot.links.iter().enumerate() {
            for visual in &link.visuals {
                let mesh = visual_mesh(visual)?;
                let color = visual.display_color(&mesh);
                attached.push(Attached {
                    instance: b.add(&mesh, visual.link_from_shape, color, EntityIds::ROBOT),
                    frame: link_index,
                    frame_from_shape: visual.link_from_shape,
                });
            }
        }
        let instance_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("instances"),
            contents: bytemuck::cast_slice(&b.instances),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        Ok(Self {
            meshes: b.meshes,
            materials: b.materials,
            labelled: b.labelled,
            instances: b.instances,
            instance_buffer,
            robot: attached,
            people,
            bodies,
            models,
            moving_models,
            objects,
        })
    }

    /// Whether some SDF model link can move.
    pub(crate) fn has_moving_models(&self) -> bool {
        self.moving_models
    }

    /// Moves the visuals of SDF model links (every model link in world order).
    pub(crate) fn set_model_link_poses(&mut self, world_from_model_links: &[Pose]) {
        move_attached(&mut self.instances, &self.models, world_from_model_links);
    }

    /// Moves person `index` (world order) to `world_from_person`, their limbs to gait phase
    /// `gait_phase_rad` (0: standing).
    pub(crate) fn set_person_pose(
        &mut self,
        index: usize,
        world_from_person: Pose,
        gait_phase_rad: f64,
    ) {
        for (a, _, swing) in self.people.iter().filter(|(a, ..)| a.frame == index) {
            let person_from_shape = swing.pose_at(a.frame_from_shape, gait_phase_rad);
            self.instances[a.instance].model = matrix(world_from_person * person_from_shape);
        }
        for body in self.bodies.iter_mut().filter(|b| b.person == index) {
            body.at = world_from_person.translation;
            for &(instance, _) in &body.instances {
                self.instances[instance].model = matrix(world_from_person);
            }
            if gait_phase_rad != body.phase_rad {
                body.phase_rad = gait_phase_rad;
                body.skin.pose(gait_phase_rad, body.stride_m);
                body.dirty = true;
            }
        }
    }

    /// The posed vertices of person `index` (world order) drawn with MakeHuman's body.
    pub(crate) fn posed_person(&self, index: usize) -> Option<&[Vec3]> {
        self.bodies
            .iter()
            .find(|b| b.person == index)
            .map(|b| b.skin.positions())
    }

    /// Paints person `index` (world order) in `person`'s colours, and reshapes or re-dresses
    /// a skinned body whose shape, height or outfit changed.
    pub(crate) fn dress_person(&mut self, device: &wgpu::Device, index: usize, person: &Person) {
        for (a, paint, _) in self.people.iter().filter(|(a, ..)| a.frame == index) {
            self.instances[a.instance].color = paint.of(person).0;
        }
        for body in self.bodies.iter_mut().filter(|b| b.person == index) {
            for &(instance, paint) in &body.instances {
                self.instances[instance].color = paint.of(person).0;
            }
            if body.look == look_of(person) {
                continue;
            }
            // Reshaped or re-dressed (a dataset's next image); the figure is not swapped in
            // or out here.
            let Some(mut skin) = SkinnedBody::of(person) else {
                tracing::warn!("{}: cannot be reshaped", person.name);
                continue;
            };
            skin.pose(body.phase_rad, person.stride_m());
            // New buffers for the same meshes: an outfit has its own triangles, and a shape
            // its own coarser levels (reusing the last body's made an image depend on the
            // one before it). A MakeHuman body has every layer, worn or not, so they line up.
            let (vertices, meshes) = body_meshes(device, &skin);
            if meshes.len() != body.instances.len() {
                tracing::warn!("{}: cannot be re-dressed", person.name);
                continue;
            }
            body.levels.clear();
            for (&(instance, _), (mesh, runs, _)) in body.instances.iter().zip(meshes) {
                if let Some(slot) = self.meshes.get_mut(instance) {
                    *slot = mesh;
                }
                body.levels.push(runs);
            }
            body.vertices = vertices;
            body.skin = skin;
            body.stride_m = person.stride_m();
            body.look = look_of(person);
            body.dirty = true;
        }
    }

    /// Moves the world objects (world order).
    pub(crate) fn set_object_poses(&mut self, world_from_objects: &[Pose]) {
        for (&instance, pose) in self.objects.iter().zip(world_from_objects) {
            self.instances[instance].model = matrix(*pose);
        }
    }

    /// Moves the robot's visuals to its link poses (URDF order).
    pub(crate) fn set_robot_link_poses(&mut self, world_from_links: &[Pose]) {
        move_attached(&mut self.instances, &self.robot, world_from_links);
    }

    /// Draws each MakeHuman body at the level of detail its distance from `camera_m` calls for.
    pub(crate) fn choose_detail(&mut self, camera_m: Vec3) {
        for body in &self.bodies {
            let d = body.at.distance(camera_m);
            let level = DETAIL_FROM_M.iter().filter(|&&from| d >= from).count();
            for (&(mesh, _), runs) in body.instances.iter().zip(&body.levels) {
                if let Some(m) = self.meshes.get_mut(mesh) {
                    m.draws.clear();
                    m.draws.push(runs[level]);
                }
            }
        }
    }

    /// Uploads this frame's instance transforms and the bodies posed since the last upload.
    pub(crate) fn upload(&mut self, queue: &wgpu::Queue) {
        queue.write_buffer(
            &self.instance_buffer,
            0,
            bytemuck::cast_slice(&self.instances),
        );
        for body in self.bodies.iter_mut().filter(|b| b.dirty) {
            body.upload(queue);
        }
    }
}

fn move_attached(instances: &mut [Instance], attached: &[Attached], world_from_frames: &[Pose]) {
    for a in attached {
        if let Some(frame) = world_from_frames.get(a.frame) {
            instances[a.instance].model = matrix(*frame * a.frame_from_shape);
        }
    }
}

fn add_models(
    b: &mut Builder<'_>,
    world: &World,
    ids: &EntityIds,
) -> Result<Vec<Attached>, RenderError> {
    let model_links = world
        .models
        .iter()
        .enumerate()
        .flat_map(|(i, m)| m.links.iter().map(move |l| (i, m, l)));
    let mut moving = Vec::new();
    for (link_index, (model_index, model, link)) in model_links.enumerate() {
        for visual in &link.visuals {
            let mesh = visual_mesh(visual)?;
            let pose = link.world_from_link * visual.link_from_shape;
            let color = visual.display_color(&mesh);
            let id = ids.model(model_index);
            let mut attach = |instance| {
                moving.push(Attached {
                    instance,
                    frame: link_index,
                    frame_from_shape: visual.link_from_shape,
                });
            };
            match model.label_above_m.filter(|_| id != 0) {
                // Only the upper part is labelled (a stop sign's face): drawn as two meshes,
                // the rest unlabelled.
                Some(above_m) => {
                    let model_from_shape = model.world_from_model.inverse() * pose;
                    let (labelled, rest) = mesh.split_at_height(model_from_shape, above_m);
                    for (part, part_id) in [(rest, 0), (labelled, id)] {
                        if !part.indices.is_empty() {
                            attach(b.add(&part, pose, color, part_id));
                        }
                    }
                }
                None => attach(b.add(&mesh, pose, color, id)),
            }
        }
    }
    Ok(moving)
}

/// Distances from the camera (m) from which each coarser level is drawn.
const DETAIL_FROM_M: [f32; 2] = [3.5, 7.0];

/// A person drawn with a skinned body (MakeHuman's, or a Gazebo actor's skin): one vertex
/// buffer posed on the CPU each time the gait or clip moves, drawn as one mesh per layer
/// (skin, shirt, ...) with that layer's paint.
struct SkinnedPerson {
    /// The person's index (world order).
    person: usize,
    skin: SkinnedBody,
    /// Their stride (m per gait cycle), for MakeHuman's walk.
    stride_m: f64,
    /// The gait phase the vertices are posed for.
    phase_rad: f64,
    /// The shape, outfit and height (m) the body was built for.
    look: Look,
    /// Reused: the posed vertices as the GPU reads them.
    staged: Vec<GpuVertex>,
    vertices: wgpu::Buffer,
    /// Instance (= mesh) and paint of each layer's mesh.
    instances: Vec<(usize, Paint)>,
    /// Each layer mesh's runs of indices: full detail, then coarser (`render::body::DETAIL_CELLS_M`).
    levels: Vec<[Draw; 3]>,
    /// Where the person stands (world, m).
    at: Vec3,
    /// Posed since the last upload.
    dirty: bool,
}

impl SkinnedPerson {
    fn upload(&mut self, queue: &wgpu::Queue) {
        self.staged.clear();
        self.staged.extend(
            self.skin
                .positions()
                .iter()
                .zip(self.skin.normals())
                .map(|(p, n)| GpuVertex {
                    position: p.to_array(),
                    normal: n.to_array(),
                    uv: [0.0; 2],
                }),
        );
        queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(&self.staged));
        self.dirty = false;
    }
}

impl Builder<'_> {
    /// A person with a skinned body, at `world_from_person`, posed as at sim time 0.
    fn add_body(
        &mut self,
        index: usize,
        person: &Person,
        skin: SkinnedBody,
        world_from_person: Pose,
        entity: u32,
    ) -> SkinnedPerson {
        let phase_rad = person.gait_phase_rad(0.0);
        let (vertices, meshes) = body_meshes(self.device, &skin);
        let mut instances = Vec::new();
        let mut levels = Vec::new();
        for (mesh, runs, paint) in meshes {
            levels.push(runs);
            self.meshes.push(mesh);
            self.instances
                .push(Instance::new(world_from_person, paint.of(person), entity));
            if entity != 0 {
                self.labelled.push(self.meshes.len() as u32 - 1);
            }
            instances.push((self.instances.len() - 1, paint));
        }
        let mut skinned = SkinnedPerson {
            person: index,
            skin,
            stride_m: person.stride_m(),
            phase_rad,
            look: look_of(person),
            staged: Vec::new(),
            vertices,
            instances,
            levels,
            at: world_from_person.translation,
            dirty: true,
        };
        skinned.upload(self.queue);
        skinned
    }
}

/// What a skinned body is built from: shape, outfit and height (m).
type Look = (Option<BodyShape>, Outfit, f64);

fn look_of(person: &Person) -> Look {
    (person.shape, person.outfit, person.height_m)
}

/// A body mesh with its levels of detail and its paint.
type LayerMesh = (GpuMesh, [Draw; 3], Paint);

/// A skinned body's GPU meshes: one vertex buffer (written by [`SkinnedPerson::upload`])
/// shared by one mesh per layer, each layer's index buffer holding every level of detail one
/// after the other, with the run of each level.
fn body_meshes(device: &wgpu::Device, skin: &SkinnedBody) -> (wgpu::Buffer, Vec<LayerMesh>) {
    let vertices = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("person"),
        size: (skin.positions().len() * std::mem::size_of::<GpuVertex>()) as u64,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let meshes = skin
        .layers()
        .into_iter()
        .map(
            |BodyLayer {
                 paint,
                 indices,
                 coarse,
             }| {
                let mut all = indices;
                let full = Draw {
                    first_index: 0,
                    count: all.len() as u32,
                    material: 0,
                };
                let mut runs = [full; 3];
                for (run, part) in runs.iter_mut().skip(1).zip(&coarse) {
                    *run = Draw {
                        first_index: all.len() as u32,
                        count: part.len() as u32,
                        material: 0,
                    };
                    all.extend_from_slice(part);
                }
                // A layer this outfit does not wear (a bald head's hair) draws nothing, but an
                // index buffer may not be empty.
                if all.is_empty() {
                    all.extend_from_slice(&[0; 3]);
                }
                let mesh = GpuMesh {
                    vertices: vertices.clone(),
                    indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: None,
                        contents: bytemuck::cast_slice(&all),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    draws: vec![full],
                };
                (mesh, runs, paint)
            },
        )
        .collect();
    (vertices, meshes)
}

fn add_people(
    b: &mut Builder<'_>,
    world: &World,
    ids: &EntityIds,
) -> (Vec<(Attached, Paint, Swing)>, Vec<SkinnedPerson>) {
    let mut parts = Vec::new();
    let mut bodies = Vec::new();
    for (person_index, person) in world.people.iter().enumerate() {
        let world_from_person = person.world_from_person(0.0);
        let id = ids.person(person_index);
        if let Some(skin) = SkinnedBody::of(person) {
            bodies.push(b.add_body(person_index, person, skin, world_from_person, id));
            continue;
        }
        for part in person_parts(person) {
            let attached = Attached {
                instance: b.add(&part.mesh, world_from_person * part.pose, part.color, id),
                frame: person_index,
                frame_from_shape: part.pose,
            };
            parts.push((attached, part.paint, part.swing));
        }
    }
    (parts, bodies)
}
