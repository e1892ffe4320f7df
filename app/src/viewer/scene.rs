//! The static scene, logged once when a run starts: world, robot visuals, camera intrinsics,
//! class names, plot series names. Meshes are the same triangles the camera renders.

use rerun::RecordingStream;
use rover_sim::{
    geometry::{Pose, Rgba},
    model::{CameraInfo, MeshData, Visual, link_from_optical},
    physics::Simulation,
    render::{SkinnedBody, Swing, object_mesh, person_parts, shape_mesh},
};

use super::images::{IMAGE_PATH, ImageOptions};

/// Entity paths of the things that move, in the simulation's order.
#[derive(Debug, Default)]
pub(super) struct ScenePaths {
    /// `world/robot/<link>` per robot link.
    pub links: Vec<String>,
    /// `world/people/<name>` per person.
    pub people: Vec<String>,
    /// `world/people/<name>/limb<k>` per limb of a walking person (legs, arms with their
    /// hands, shoes), with the person's index, how the limb swings and where it sits standing
    /// (its mesh is in that frame).
    pub limbs: Limbs,
    /// `world/people/<name>/body` of each moving person drawn with a skinned body (MakeHuman's
    /// or an actor's skin), with the person's index and the body, re-posed as they walk.
    pub bodies: Vec<(usize, String, SkinnedBody)>,
    /// `world/models/<model>/<link>` of SDF model links that move, with their index among all
    /// model links.
    pub moving_model_links: Vec<(usize, String)>,
    /// `plots/joints/<joint>` per actuated joint: its position and its actuator's target.
    pub joints: Vec<(rover_sim::model::JointId, String)>,
}

/// Logs the static scene and returns the paths per-tick logging uses.
pub(super) fn log_scene(
    rec: &RecordingStream,
    sim: &Simulation,
    camera: Option<&CameraInfo>,
    labels: &[String],
    images: &ImageOptions,
) -> ScenePaths {
    log(rec, "world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP());
    // The 3D view's origin is the robot (see blueprint.rs): it needs the up axis too.
    log(
        rec,
        "world/robot",
        &rerun::ViewCoordinates::RIGHT_HAND_Z_UP(),
    );
    let moving_model_links = log_world(rec, sim);
    let (people, limbs, bodies) = log_people(rec, sim);
    let paths = ScenePaths {
        moving_model_links,
        people,
        limbs,
        bodies,
        links: log_robot(rec, sim),
        joints: log_joint_series(rec, sim),
    };
    if let Some(info) = camera {
        log_camera(rec, sim, info, images);
    }
    if !labels.is_empty() {
        log(
            rec,
            IMAGE_PATH,
            &rerun::AnnotationContext::new(labels.iter().enumerate().map(|(i, name)| {
                let image::Rgb([r, g, b]) =
                    crate::palette::class_color(i16::try_from(i).unwrap_or(i16::MAX));
                (i as u16, name.as_str(), rerun::Rgba32::from_rgb(r, g, b))
            })),
        );
    }
    log_plot_series(rec);
    paths
}

/// Logs static data, with a warning when Rerun refuses it.
fn log(rec: &RecordingStream, path: &str, data: &dyn rerun::AsComponents) {
    if let Err(e) = rec.log_static(path, data) {
        tracing::warn!("rerun: {path}: {e}");
    }
}

/// Logs one link's visuals under `path`, as meshes.
fn log_visuals(rec: &RecordingStream, path: &str, visuals: &[Visual]) {
    for (v, visual) in visuals.iter().enumerate() {
        let vpath = format!("{path}/visual_{v}");
        if let Ok(m) = shape_mesh(&visual.shape) {
            log(rec, &vpath, &transform(visual.link_from_shape));
            log(rec, &vpath, &mesh(&m, visual.display_color(&m)));
        }
    }
}

/// The ground, the world's objects and its SDF models; returns the model links that move (with
/// their index among all model links) and their paths.
fn log_world(rec: &RecordingStream, sim: &Simulation) -> Vec<(usize, String)> {
    let world = sim.world();
    let [gx, gy] = world.ground.size_m;
    log(
        rec,
        "world/ground",
        &rerun::Boxes3D::from_centers_and_sizes(
            [[0.0f32, 0.0, -0.01]],
            [[gx as f32, gy as f32, 0.02]],
        )
        .with_colors([color(world.ground.color)])
        .with_fill_mode(rerun::FillMode::Solid),
    );
    for object in &world.objects {
        let path = format!("world/objects/{}", object.name);
        log(rec, &path, &transform(object.world_from_object()));
        match object_mesh(&object.shape) {
            Ok(m) => log(rec, &path, &mesh(&m, object.color)),
            Err(e) => tracing::warn!("viewer: object \"{}\" not drawn: {e}", object.name),
        }
    }
    let mut moving = Vec::new();
    let model_links = world
        .models
        .iter()
        .flat_map(|m| m.links.iter().map(move |l| (m, l)));
    for (i, (model, link)) in model_links.enumerate() {
        let path = format!("world/models/{}/{}", model.name, link.name);
        // Moving links get their transform per tick (static data would shadow it).
        if !link.is_dynamic(model) {
            log(rec, &path, &transform(link.world_from_link));
        }
        log_visuals(rec, &path, &link.visuals);
        if link.is_dynamic(model) {
            moving.push((i, path));
        }
    }
    moving
}

/// One mesh gathered from figure parts that move together (the body, or one limb).
#[derive(Default)]
struct PartsMesh {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    colors: Vec<[u8; 4]>,
    triangles: Vec<[u32; 3]>,
}

impl PartsMesh {
    /// Adds `part`'s mesh, placed at `frame_from_part`.
    fn add(&mut self, part: &rover_sim::render::PersonPart, frame_from_part: Pose) {
        let base = self.positions.len() as u32;
        for v in &part.mesh.vertices {
            self.positions
                .push((frame_from_part * glam::Vec3::from_array(v.position)).to_array());
            self.normals
                .push((frame_from_part.rotation * glam::Vec3::from_array(v.normal)).to_array());
            self.colors.push(color(part.color));
        }
        self.triangles.extend(
            part.mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    fn log(self, rec: &RecordingStream, path: &str) {
        log(
            rec,
            path,
            &rerun::Mesh3D::new(self.positions)
                .with_vertex_normals(self.normals)
                .with_vertex_colors(self.colors)
                .with_triangle_indices(self.triangles),
        );
    }
}

/// A walking person's limbs: the person's index, the limb's path, how it swings, and where it
/// sits standing (its mesh is in that frame).
type Limbs = Vec<(usize, String, Swing, Pose)>;

/// The people: a skinned body as one mesh (`<path>/body`, its vertices re-logged as a moving
/// person walks), or rover's figure as one mesh of its body and, for a walking person, one
/// per limb that swings (`<path>/limb<k>`, moved per tick); returns the people's paths, the
/// limbs' and the moving skinned bodies'.
#[allow(
    clippy::type_complexity,
    reason = "one private function's result: the people's, limbs' and skinned bodies' paths"
)]
fn log_people(
    rec: &RecordingStream,
    sim: &Simulation,
) -> (Vec<String>, Limbs, Vec<(usize, String, SkinnedBody)>) {
    let mut paths = Vec::new();
    let mut limbs = Vec::new();
    let mut bodies = Vec::new();
    for (i, person) in sim.world().people.iter().enumerate() {
        let path = format!("world/people/{}", person.name);
        let walking = person.moves();
        if let Some(skinned) = SkinnedBody::of(person) {
            log(
                rec,
                &format!("{path}/body"),
                &skinned_mesh(&skinned, person),
            );
            if walking {
                bodies.push((i, format!("{path}/body"), skinned));
            } else {
                log(rec, &path, &transform(sim.world_from_person(i)));
            }
            paths.push(path);
            continue;
        }
        let mut body = PartsMesh::default();
        // Parts that turn about one joint share a mesh in the figure's frame; a part kept
        // level (a shoe) has its own, in its own frame.
        let mut swinging: Vec<(Swing, Pose, PartsMesh)> = Vec::new();
        for part in person_parts(person) {
            if !walking || part.swing.gain == 0.0 {
                body.add(&part, part.pose);
            } else if part.swing.level {
                let mut mesh = PartsMesh::default();
                mesh.add(&part, Pose::IDENTITY);
                swinging.push((part.swing, part.pose, mesh));
            } else if let Some((.., mesh)) = swinging.iter_mut().find(|(s, ..)| *s == part.swing) {
                mesh.add(&part, part.pose);
            } else {
                let mut mesh = PartsMesh::default();
                mesh.add(&part, part.pose);
                swinging.push((part.swing, Pose::IDENTITY, mesh));
            }
        }
        body.log(rec, &format!("{path}/body"));
        for (k, (swing, standing, mesh)) in swinging.into_iter().enumerate() {
            let limb = format!("{path}/limb{k}");
            mesh.log(rec, &limb);
            limbs.push((i, limb, swing, standing));
        }
        if !walking {
            log(rec, &path, &transform(sim.world_from_person(i)));
        }
        paths.push(path);
    }
    (paths, limbs, bodies)
}

/// A skinned body as one Rerun mesh: its posed vertices, each coloured by its layer's paint.
fn skinned_mesh(body: &SkinnedBody, person: &rover_sim::model::Person) -> rerun::Mesh3D {
    let mut colors = vec![rerun::Color::from_rgb(128, 128, 128); body.positions().len()];
    let mut triangles = Vec::new();
    for layer in body.layers() {
        let [r, g, b, _] = layer.paint.of(person).0.map(|c| (c * 255.0).round() as u8);
        for t in layer.indices.chunks_exact(3) {
            for &i in t {
                if let Some(c) = colors.get_mut(i as usize) {
                    *c = rerun::Color::from_rgb(r, g, b);
                }
            }
            triangles.push([t[0], t[1], t[2]]);
        }
    }
    rerun::Mesh3D::new(body.positions().iter().map(|p| p.to_array()))
        .with_vertex_normals(body.normals().iter().map(|n| n.to_array()))
        .with_triangle_indices(triangles)
        .with_vertex_colors(colors)
}

/// The robot: one entity per link under world/robot, visuals as meshes; returns their paths.
fn log_robot(rec: &RecordingStream, sim: &Simulation) -> Vec<String> {
    sim.robot()
        .links
        .iter()
        .map(|link| {
            let path = format!("world/robot/{}", link.name);
            log_visuals(rec, &path, &link.visuals);
            path
        })
        .collect()
}

/// The camera's optical frame on the robot and its pinhole, at the logged images' scale.
fn log_camera(rec: &RecordingStream, sim: &Simulation, info: &CameraInfo, images: &ImageOptions) {
    let robot = sim.robot();
    let link = robot
        .cameras
        .first()
        .and_then(|c| robot.link_id(&c.link))
        .unwrap_or(robot.root);
    let base_from_link = sim.world_from_base().inverse() * sim.world_from_link(link);
    let base_from_optical = base_from_link * Pose::from_rotation(link_from_optical());
    log(rec, "world/robot/camera", &transform(base_from_optical));
    let k = images.scale();
    let proj = rerun::components::PinholeProjection::from_focal_length_and_principal_point(
        [info.k[0] as f32 / k, info.k[4] as f32 / k],
        [info.k[2] as f32 / k, info.k[5] as f32 / k],
    );
    let (w, h) = images.scaled_size(info.width, info.height);
    log(
        rec,
        IMAGE_PATH,
        &rerun::Pinhole::new(proj)
            .with_resolution([w as f32, h as f32])
            .with_image_plane_distance(0.5f32),
    );
}

/// The actuated joints' plot paths, with their series named.
fn log_joint_series(
    rec: &RecordingStream,
    sim: &Simulation,
) -> Vec<(rover_sim::model::JointId, String)> {
    let robot = sim.robot();
    robot
        .actuated_joints()
        .into_iter()
        .map(|id| {
            let name = &robot.joint(id).name;
            let path = format!("plots/joints/{name}");
            log(
                rec,
                &path,
                &rerun::SeriesLines::new()
                    .with_names([format!("{name} position"), format!("{name} target")]),
            );
            (id, path)
        })
        .collect()
}

/// The plots' series names.
fn log_plot_series(rec: &RecordingStream) {
    log(
        rec,
        "plots/velocity/linear",
        &rerun::SeriesLines::new().with_names(["cmd linear.x (m/s)", "measured (m/s)"]),
    );
    log(
        rec,
        "plots/velocity/angular",
        &rerun::SeriesLines::new().with_names(["cmd angular.z (rad/s)", "measured (rad/s)"]),
    );
    log(
        rec,
        "plots/wheels",
        &rerun::SeriesLines::new().with_names([
            "left target (rad/s)",
            "right target (rad/s)",
            "left measured (rad/s)",
            "right measured (rad/s)",
        ]),
    );
}

/// A pose as a Rerun transform.
pub(super) fn transform(pose: Pose) -> rerun::Transform3D {
    rerun::Transform3D::from_translation_rotation(
        pose.translation.to_array(),
        rerun::Quaternion::from_xyzw(pose.rotation.to_array()),
    )
}

fn color(c: Rgba) -> [u8; 4] {
    c.0.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

fn mesh(m: &MeshData, c: Rgba) -> rerun::Mesh3D {
    rerun::Mesh3D::new(m.vertices.iter().map(|v| v.position))
        .with_vertex_normals(m.vertices.iter().map(|v| v.normal))
        .with_triangle_indices(m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]))
        .with_albedo_factor(color(c))
}
