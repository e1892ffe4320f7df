//! What the camera sees, on the GPU: every mesh of the world, its people and models and the
//! robot's visuals uploaded once, one instance (transform and colour) per drawn mesh. Per frame
//! only the transforms of things that move change. Passes draw the same scene.

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

use crate::geometry::{Pose, Rgba};
use crate::model::mesh::MeshData;
use crate::model::robot::RobotModel;
use crate::model::world::World;
use crate::render::gpu::RenderError;
use crate::render::mesh::{cuboid, object_mesh, person_parts, shape_mesh};

/// Per-instance vertex data: the model matrix and the colour (alpha < 0 marks the checkered
/// ground).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Instance {
    model: [[f32; 4]; 4],
    color: [f32; 4],
}

impl Instance {
    fn new(pose: Pose, color: Rgba) -> Self {
        Self {
            model: matrix(pose),
            color: color.0,
        }
    }
}

fn matrix(pose: Pose) -> [[f32; 4]; 4] {
    Mat4::from_rotation_translation(pose.rotation, pose.translation).to_cols_array_2d()
}

/// One vertex as the passes read it (location 0: position, 1: normal). The model's
/// [`MeshData`] stays plain data; this layout is the renderer's own.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuVertex {
    position: [f32; 3],
    normal: [f32; 3],
}

/// One uploaded mesh.
pub(crate) struct GpuMesh {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) count: u32,
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
    instances: Vec<Instance>,
    pub(crate) instance_buffer: wgpu::Buffer,
    robot: Vec<Attached>,
    people: Vec<Attached>,
    /// Visuals of moving SDF model links.
    models: Vec<Attached>,
}

/// Collects meshes and instances before the instance buffer exists.
struct Builder<'d> {
    device: &'d wgpu::Device,
    meshes: Vec<GpuMesh>,
    instances: Vec<Instance>,
}

impl Builder<'_> {
    fn add(&mut self, mesh: &MeshData, pose: Pose, color: Rgba) -> usize {
        let device = self.device;
        let vertices: Vec<GpuVertex> = mesh
            .vertices
            .iter()
            .map(|v| GpuVertex {
                position: v.position,
                normal: v.normal,
            })
            .collect();
        self.meshes.push(GpuMesh {
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
            count: mesh.indices.len() as u32,
        });
        self.instances.push(Instance::new(pose, color));
        self.instances.len() - 1
    }
}

impl Scene {
    /// Uploads the ground, objects, SDF models, people and the robot's visuals (at the origin
    /// until the first [`Scene::set_robot_link_poses`]).
    pub(crate) fn new(
        device: &wgpu::Device,
        world: &World,
        robot: &RobotModel,
    ) -> Result<Self, RenderError> {
        let mut b = Builder {
            device,
            meshes: Vec::new(),
            instances: Vec::new(),
        };
        let [gx, gy] = world.ground.size_m;
        let ground = cuboid(Vec3::new(gx as f32, gy as f32, 0.02));
        let mut ground_color = world.ground.color;
        ground_color.0[3] = -1.0;
        b.add(
            &ground,
            Pose::from_translation(Vec3::new(0.0, 0.0, -0.01)),
            ground_color,
        );
        for object in &world.objects {
            let mesh = object_mesh(&object.shape)?;
            b.add(&mesh, object.world_from_object(), object.color);
        }
        let models = add_models(&mut b, world)?;
        let people = add_people(&mut b, world);
        let mut attached = Vec::new();
        for (link_index, link) in robot.links.iter().enumerate() {
            for visual in &link.visuals {
                let mesh = shape_mesh(&visual.shape)?;
                let color = visual.display_color(&mesh);
                attached.push(Attached {
                    instance: b.add(&mesh, visual.link_from_shape, color),
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
            instances: b.instances,
            instance_buffer,
            robot: attached,
            people,
            models,
        })
    }

    /// Whether some SDF model link can move.
    pub(crate) fn has_moving_models(&self) -> bool {
        !self.models.is_empty()
    }

    /// Moves the visuals of moving SDF model links (every model link in world order).
    pub(crate) fn set_model_link_poses(&mut self, world_from_model_links: &[Pose]) {
        move_attached(&mut self.instances, &self.models, world_from_model_links);
    }

    /// Moves person `index` (world order) to `world_from_person`.
    pub(crate) fn set_person_pose(&mut self, index: usize, world_from_person: Pose) {
        for a in self.people.iter().filter(|a| a.frame == index) {
            self.instances[a.instance].model = matrix(world_from_person * a.frame_from_shape);
        }
    }

    /// Moves the robot's visuals to its link poses (URDF order).
    pub(crate) fn set_robot_link_poses(&mut self, world_from_links: &[Pose]) {
        move_attached(&mut self.instances, &self.robot, world_from_links);
    }

    /// Uploads this frame's instance transforms.
    pub(crate) fn upload(&self, queue: &wgpu::Queue) {
        queue.write_buffer(
            &self.instance_buffer,
            0,
            bytemuck::cast_slice(&self.instances),
        );
    }
}

fn move_attached(instances: &mut [Instance], attached: &[Attached], world_from_frames: &[Pose]) {
    for a in attached {
        if let Some(frame) = world_from_frames.get(a.frame) {
            instances[a.instance].model = matrix(*frame * a.frame_from_shape);
        }
    }
}

fn add_models(b: &mut Builder<'_>, world: &World) -> Result<Vec<Attached>, RenderError> {
    let mut moving = Vec::new();
    let model_links = world
        .models
        .iter()
        .flat_map(|m| m.links.iter().map(move |l| (m, l)));
    for (link_index, (model, link)) in model_links.enumerate() {
        for visual in &link.visuals {
            let mesh = shape_mesh(&visual.shape)?;
            let pose = link.world_from_link * visual.link_from_shape;
            let index = b.add(&mesh, pose, visual.display_color(&mesh));
            if link.is_dynamic(model) {
                moving.push(Attached {
                    instance: index,
                    frame: link_index,
                    frame_from_shape: visual.link_from_shape,
                });
            }
        }
    }
    Ok(moving)
}

fn add_people(b: &mut Builder<'_>, world: &World) -> Vec<Attached> {
    let mut parts = Vec::new();
    for (person_index, person) in world.people.iter().enumerate() {
        let world_from_person = person.world_from_person(0.0);
        for part in person_parts(person) {
            parts.push(Attached {
                instance: b.add(&part.mesh, world_from_person * part.pose, part.color),
                frame: person_index,
                frame_from_shape: part.pose,
            });
        }
    }
    parts
}
