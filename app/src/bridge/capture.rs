//! What the loop thread copies out of the session for the publishing thread, into recycled
//! buffers: images, scans, boxes, the moving joints, the arm's task, and the transforms that
//! never change. Quick and allocation-free once warm: the loop never waits for a bridge.

use rover_perception::{BoundingBox, BoundingBoxes};
use rover_sim::{
    geometry::Pose,
    model::{CameraInfo, JointKind, RobotModel, link_from_optical},
    physics::{ControlSample, Simulation},
    sensors::{CameraFrame, GroundTruthBox, LaserScan, PointCloud},
};

use super::events::{
    ArmSample, Detections, GripperSample, ImageFrame, JointSample, RunSample, Transform,
};
use super::plan::{JointSource, MovingJoint};

/// The image to hand over: `frame` copied into the recycled `pixels`, its depth image (if
/// any) into `depth` as 32FC1 bytes.
pub(crate) fn image(
    frame: &CameraFrame<'_>,
    mut pixels: Vec<u8>,
    mut depth: Vec<u8>,
) -> ImageFrame {
    pixels.clear();
    pixels.extend_from_slice(frame.rgb);
    depth.clear();
    if let Some(metres) = frame.depth_m {
        depth.reserve(metres.len() * 4);
        for m in metres {
            depth.extend_from_slice(&m.to_le_bytes());
        }
    }
    ImageFrame {
        stamp_s: frame.sim_time_s,
        seq: frame.seq,
        width: frame.width,
        height: frame.height,
        pixels,
        depth,
    }
}

/// The cloud to hand over: `cloud` copied, its points into the recycled `data`.
pub(crate) fn cloud(cloud: &PointCloud, mut data: Vec<u8>) -> PointCloud {
    data.clone_from(&cloud.data);
    PointCloud {
        frame_id: cloud.frame_id.clone(),
        data,
        ..*cloud
    }
}

/// The scan to hand over: `scan` copied, its ranges into the recycled `ranges_m`.
pub(crate) fn scan(scan: &LaserScan, mut ranges_m: Vec<f32>) -> LaserScan {
    ranges_m.clone_from(&scan.ranges_m);
    LaserScan {
        frame_id: scan.frame_id.clone(),
        ranges_m,
        ..*scan
    }
}

/// The detections to hand over, published at `now_s` (never before their image): `boxes`
/// copied into the recycled `out`, whose class strings keep their capacity.
pub(crate) fn detections(
    boxes: &BoundingBoxes,
    now_s: f64,
    mut out: Vec<BoundingBox>,
) -> Detections {
    out.clone_from(&boxes.bounding_boxes);
    Detections {
        stamp_s: now_s.max(boxes.image_stamp.sim_time_s),
        image_stamp_s: boxes.image_stamp.sim_time_s,
        image_seq: boxes.image_stamp.frame,
        boxes: out,
    }
}

/// The ground truth of the image `boxes` came from, to hand over in the recycled `out`:
/// labelled things in view that are not ignore regions, their visible boxes at pixel edges
/// (as darknet_ros's), `class` the COCO name, `id` its COCO-80 number, probability 1.
pub(crate) fn ground_truth(
    boxes: &BoundingBoxes,
    truth: &[GroundTruthBox],
    now_s: f64,
    mut out: Vec<BoundingBox>,
) -> Detections {
    let shown = truth.iter().filter(|t| !t.ignore).filter_map(|t| {
        let v = t.visible?;
        Some((t, v))
    });
    let count = shown.clone().count();
    out.resize_with(count, || BoundingBox {
        class: String::new(),
        probability: 0.0,
        xmin: 0,
        ymin: 0,
        xmax: 0,
        ymax: 0,
        id: 0,
    });
    for (b, (t, v)) in out.iter_mut().zip(shown) {
        b.class.clone_from(&t.class);
        b.probability = 1.0;
        b.xmin = v.xmin.round() as i64;
        b.ymin = v.ymin.round() as i64;
        b.xmax = v.xmax.round() as i64;
        b.ymax = v.ymax.round() as i64;
        b.id = rover_core::yolo_class(&t.class).map_or(-1, |i| i as i16);
    }
    Detections {
        stamp_s: now_s.max(boxes.image_stamp.sim_time_s),
        image_stamp_s: boxes.image_stamp.sim_time_s,
        image_seq: boxes.image_stamp.frame,
        boxes: out,
    }
}

/// Samples every joint of `joints` at a control update, into `out`.
pub(crate) fn joints(
    sim: &Simulation,
    sample: &ControlSample,
    joints: &[MovingJoint],
    out: &mut Vec<JointSample>,
) {
    out.clear();
    out.extend(joints.iter().map(|j| {
        let state = match j.source {
            JointSource::Joint(id) => sim.joint_state(id).unwrap_or_default(),
            JointSource::Wheel { .. } => rover_sim::physics::JointState {
                velocity: j.source.velocity_radps(sample),
                ..rover_sim::physics::JointState::default()
            },
        };
        let setpoint = match j.source {
            JointSource::Joint(id) => sim.joint_setpoint(id).unwrap_or(state.position),
            JointSource::Wheel { .. } => state.position,
        };
        let parent_from_child =
            sim.world_from_link(j.parent).inverse() * sim.world_from_link(j.child);
        let position = match j.source {
            JointSource::Wheel { .. } => angle_rad(j, parent_from_child),
            JointSource::Joint(_) => state.position,
        };
        JointSample {
            parent_from_child,
            velocity_radps: state.velocity,
            position,
            effort: state.effort,
            setpoint,
        }
    }));
}

/// Samples each of `controllers` (names) at a control update, into `out`: what its
/// trajectory does, or its gripper command.
pub(crate) fn runs(sim: &Simulation, controllers: &[String], out: &mut Vec<RunSample>) {
    out.clear();
    out.extend(controllers.iter().map(|name| {
        if let Some(g) = sim.gripper_state(name) {
            return RunSample {
                active: g.active,
                runs: g.runs,
                outcome: None,
                gripper: GripperSample {
                    position: g.position,
                    effort: g.effort,
                    stalled: g.stalled,
                    reached_goal: g.reached_goal,
                },
            };
        }
        sim.trajectory_state(name)
            .map(|s| RunSample {
                active: s.active,
                runs: s.runs,
                outcome: s.outcome,
                gripper: GripperSample::default(),
            })
            .unwrap_or_default()
    }));
}

/// A joint's angle: its rotation since its rest pose, about its axis (rad).
fn angle_rad(joint: &MovingJoint, parent_from_child: Pose) -> f64 {
    let rel = joint.parent_from_child_at_rest.rotation.inverse() * parent_from_child.rotation;
    let along = glam::Vec3::new(rel.x, rel.y, rel.z).dot(joint.axis);
    2.0 * f64::from(along).atan2(f64::from(rel.w))
}

/// The arm's status with its points moved from the world into the robot's base frame.
pub(crate) fn arm(sim: &Simulation, arm: &rover_core::ArmStatus) -> ArmSample {
    let base_from_world = sim.world_from_base().inverse();
    let to_base = |p: Option<[f64; 3]>| {
        p.map(|[x, y, z]| {
            let b = base_from_world.transform_point(glam::Vec3::new(x as f32, y as f32, z as f32));
            [f64::from(b.x), f64::from(b.y), f64::from(b.z)]
        })
    };
    ArmSample {
        mode: arm.mode,
        reach: arm.reach,
        pick: arm.pick,
        object_base_m: to_base(arm.object_world_m),
        goal_base_m: to_base(arm.goal_world_m),
    }
}

/// What `/tf_static` says for `robot` (once, at the start): every fixed joint, the camera's
/// optical frame under `camera_link` when the URDF has no link of that name, and each laser's
/// frame when it is not its link.
pub(crate) fn static_transforms(
    robot: &RobotModel,
    camera: Option<&CameraInfo>,
    camera_link: Option<&str>,
) -> Vec<Transform> {
    let mut static_tf: Vec<Transform> = robot
        .joints
        .iter()
        .filter(|j| matches!(j.kind, JointKind::Fixed))
        .map(|j| {
            let (parent, child) = (robot.link(j.parent), robot.link(j.child));
            Transform::new(&parent.name, &child.name, j.parent_from_child)
        })
        .collect();
    // The camera's optical frame, unless the URDF has it (TIAGo's xtion_rgb_optical_frame: its
    // own fixed joint is above).
    if let (Some(info), Some(link)) = (camera, camera_link)
        && robot.link_id(&info.frame_id).is_none()
    {
        let optical = Pose::from_parts(glam::Vec3::ZERO, link_from_optical());
        static_tf.push(Transform::new(link, &info.frame_id, optical));
    }
    for laser in &robot.lasers {
        if laser.frame_name != laser.link {
            static_tf.push(Transform::new(
                &laser.link,
                &laser.frame_name,
                laser.link_from_sensor,
            ));
        }
    }
    static_tf
}

#[cfg(test)]
mod tests {
    use super::*;
    use rover_perception::FrameStamp;

    fn person(xmin: i64) -> BoundingBox {
        BoundingBox {
            class: "person".into(),
            probability: 0.5,
            xmin,
            ymin: 1,
            xmax: xmin + 3,
            ymax: 4,
            id: 0,
        }
    }

    #[test]
    fn captured_boxes_reuse_the_recycled_buffer() {
        let boxes = BoundingBoxes {
            image_stamp: FrameStamp {
                sim_time_s: 2.0,
                frame: 7,
            },
            bounding_boxes: vec![person(1), person(5)],
            ..BoundingBoxes::default()
        };
        let recycled = vec![person(0), person(0), person(0)];
        let first_class = recycled[0].class.as_ptr();
        let d = detections(&boxes, 1.5, recycled);
        assert_eq!(d.boxes, boxes.bounding_boxes);
        assert_eq!(
            d.boxes[0].class.as_ptr(),
            first_class,
            "the string was reused"
        );
        assert_eq!((d.stamp_s, d.image_stamp_s, d.image_seq), (2.0, 2.0, 7));
        let d = detections(&boxes, 3.0, Vec::new());
        assert_eq!(d.boxes, boxes.bounding_boxes);
        assert_eq!(d.stamp_s, 3.0);
    }

    #[test]
    fn a_joints_angle_is_its_turn_about_its_axis_since_rest() -> anyhow::Result<()> {
        // The links only name the joint's frames; the angle depends on the poses alone.
        let robot = rover_sim::model::RobotModel::load(&rover_core::default_robot_path())?;
        let at_rest = Pose::from_parts(
            glam::Vec3::new(0.0, 0.2, 0.0),
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        );
        let joint = MovingJoint {
            name: "left_wheel_joint".into(),
            parent: robot.root,
            child: robot.root,
            parent_link: "base_link".into(),
            child_link: "left_wheel".into(),
            parent_from_child_at_rest: at_rest,
            axis: glam::Vec3::Z,
            source: JointSource::Wheel { side: 0 },
        };
        for turn_rad in [0.0f32, 0.3, -1.2, 3.0] {
            let now = Pose::from_parts(
                at_rest.translation,
                at_rest.rotation * glam::Quat::from_rotation_z(turn_rad),
            );
            let angle = angle_rad(&joint, now);
            assert!(
                (angle - f64::from(turn_rad)).abs() < 1e-6,
                "{angle} for {turn_rad}"
            );
        }
        Ok(())
    }
}
