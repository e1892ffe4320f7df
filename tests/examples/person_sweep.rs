//! Person visibility sweep: renders the default world's person from the robot camera's height
//! at several distances and bearings (real renderer) and runs the real default detector,
//! printing the best `person` confidence per frame. Work in progress towards issue 4's
//! ">= 0.5 in 90% of frames" goal; the table is in docs/PERCEPTION.md.
//!
//! `cargo run --release -p rover-tests --example person_sweep [WxH] [OUT_DIR]`
use glam::{Quat, Vec3};
use rover_perception::{Detector, DetectorConfig, FrameStamp, RgbView};
use rover_sim::{CameraRenderer, Pose, RobotModel, World};
fn main() -> anyhow::Result<()> {
    let world = World::load(&rover_tests::repo("worlds/playground.toml"))?;
    let robot = RobotModel::load(&rover_tests::repo("assets/robots/my_robot.urdf"))?;
    let cam = robot.cameras[0].clone();
    let mut r = CameraRenderer::new(&world, &robot, &cam, 0)?;
    let size = std::env::args().nth(1).map(|s| {
        let (w, h) = s.split_once('x').unwrap_or(("512", "384"));
        (w.parse().unwrap_or(512), h.parse().unwrap_or(384))
    });
    let mut det = Detector::load(DetectorConfig {
        input_size: size,
        ..DetectorConfig::default()
    })?;
    let parked = vec![Pose::from_translation(Vec3::new(0.0, 0.0, -100.0)); robot.links.len()];
    let person = world.people[0].position_m;
    let (mut ok, mut total) = (0, 0);
    for d in [2.5f32, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0] {
        let mut line = format!("{d:4.1} m:");
        for bearing_deg in [-25.0f32, -12.0, 0.0, 12.0, 25.0] {
            // Camera d metres in front of the person (person faces -x), the person at `bearing`.
            let cam_pos = Vec3::new(person[0] as f32 - d, person[1] as f32, 0.179);
            let yaw = -bearing_deg.to_radians();
            let pose = Pose::from_parts(cam_pos, Quat::from_rotation_z(yaw));
            let rgb = r.render(&parked, pose)?.to_vec();
            let res = det.detect(RgbView::new(640, 480, &rgb)?, FrameStamp::default())?;
            let p = res
                .bounding_boxes
                .iter()
                .filter(|b| b.class == "person")
                .map(|b| b.probability)
                .fold(0.0, f64::max);
            total += 1;
            if p >= 0.5 {
                ok += 1;
            }
            line += &format!(" {p:.2}");
            if let Some(dir) = std::env::args().nth(2) {
                let path = std::path::Path::new(&dir)
                    .join(format!("person_{d:.1}m_{bearing_deg:+.0}deg.png"));
                image::save_buffer(path, &rgb, 640, 480, image::ExtendedColorType::Rgb8)?;
            }
        }
        println!("{line}");
    }
    println!("person >= 0.5 in {ok}/{total} frames");
    Ok(())
}
