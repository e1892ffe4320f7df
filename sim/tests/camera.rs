//! The camera renderer on real wgpu (a GPU or Mesa's software Vulkan): geometry against the
//! pinhole model, clipping, determinism and noise statistics.

use std::path::Path;

use glam::Vec3;
use rover_sim::model::GaussianNoise;
use rover_sim::{
    geometry::Pose,
    model::{CameraInfo, RobotModel, World},
    render::CameraRenderer,
};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn robot() -> Result<RobotModel> {
    Ok(RobotModel::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/robots/my_robot.urdf"),
    )?)
}

/// A world with one small bright cube (plus the ground) at `position`.
fn cube_world(position: [f64; 3], size: f64) -> Result<World> {
    let text = format!(
        "[ground]\ncolor = \"#202020\"\nchecker_color = \"#202020\"\n[[box]]\nsize_m = [{size}, {size}, {size}]\nposition_m = [{}, {}, {}]\ncolor = \"#ff0000\"\n",
        position[0], position[1], position[2]
    );
    Ok(World::from_str(&text, Path::new("cube.toml"))?)
}

/// Robot links parked far below the ground, so only the world is in view.
fn parked(robot: &RobotModel) -> Vec<Pose> {
    vec![Pose::from_translation(Vec3::new(0.0, 0.0, -100.0)); robot.links.len()]
}

fn red_centroid(rgb: &[u8], width: usize) -> Option<(f64, f64, usize)> {
    let (mut n, mut sx, mut sy) = (0usize, 0.0, 0.0);
    for (i, p) in rgb.chunks_exact(3).enumerate() {
        if p[0] > 60 && p[1] < 40 && p[2] < 40 {
            n += 1;
            sx += (i % width) as f64;
            sy += (i / width) as f64;
        }
    }
    (n > 0).then(|| (sx / n as f64, sy / n as f64, n))
}

#[test]
fn a_cube_lands_where_the_pinhole_model_says() -> Result<()> {
    let robot = robot()?;
    let config = robot.cameras[0].clone();
    let info = CameraInfo::from_config(&config);
    // Camera 0.5 m above the ground at the origin, looking along +x.
    let camera = Pose::from_translation(Vec3::new(0.0, 0.0, 0.5));
    for (x, y, z) in [
        (1.0, 0.0, 0.5),
        (3.0, 0.0, 0.5),
        (6.0, 0.0, 0.5),
        (2.0, 0.6, 0.8),
        (4.0, -1.2, 0.2),
    ] {
        let size = 0.04 * x;
        let mut renderer = CameraRenderer::new(&cube_world([x, y, z], size)?, &robot, &config, 0)?;
        let rgb = renderer.render(&parked(&robot), camera)?;
        let (u, v, n) = red_centroid(rgb, 640).ok_or("cube not visible")?;
        // The cube's centre in the optical frame: x right = -y, y down = -(z - 0.5), z = x.
        let (pu, pv) = info.project(-y, -(z - 0.5), x).ok_or("behind the camera")?;
        // The visible faces' centroid sits slightly off the centre for off-axis cubes; the
        // cubes are small (4 cm per metre of distance) so it stays within the tolerance.
        assert!(
            (u - pu).abs() <= 1.5 && (v - pv).abs() <= 1.5,
            "cube at ({x}, {y}, {z}): centroid ({u:.2}, {v:.2}) from {n} px, pinhole ({pu:.2}, {pv:.2})"
        );
    }
    Ok(())
}

#[test]
fn objects_outside_the_clip_range_are_not_drawn() -> Result<()> {
    let robot = robot()?;
    let mut config = robot.cameras[0].clone();
    config.clip_near_m = 0.5;
    config.clip_far_m = 10.0;
    let camera = Pose::from_translation(Vec3::new(0.0, 0.0, 0.5));
    for (x, visible) in [(0.3, false), (2.0, true), (12.0, false)] {
        let size = if x < 1.0 { 0.05 } else { 0.3 };
        let mut renderer =
            CameraRenderer::new(&cube_world([x, 0.0, 0.5], size)?, &robot, &config, 0)?;
        let rgb = renderer.render(&parked(&robot), camera)?;
        assert_eq!(
            red_centroid(rgb, 640).is_some(),
            visible,
            "cube at {x} m with clip 0.5..10 m"
        );
    }
    Ok(())
}

#[test]
fn same_seed_same_bytes_and_noise_has_the_configured_stddev() -> Result<()> {
    let robot = robot()?;
    let mut config = robot.cameras[0].clone();
    let stddev = 0.03;
    config.noise = Some(GaussianNoise { mean: 0.0, stddev });
    // A flat mid-grey scene: the ground seen from above.
    let world = World::from_str(
        "[ground]\ncolor = \"#808080\"\nchecker_color = \"#808080\"\n",
        Path::new("grey.toml"),
    )?;
    let camera = Pose::from_parts(
        Vec3::new(0.0, 0.0, 2.0),
        glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
    );
    let render = |seed: u64| -> Result<Vec<u8>> {
        let mut r = CameraRenderer::new(&world, &robot, &config, seed)?;
        Ok(r.render(&parked(&robot), camera)?.to_vec())
    };
    let (a, b, c) = (render(7)?, render(7)?, render(8)?);
    assert!(a == b, "same seed, same bytes");
    assert!(a != c, "another seed, other noise");

    let mut clean_config = config.clone();
    clean_config.noise = None;
    let mut clean = CameraRenderer::new(&world, &robot, &clean_config, 7)?;
    let clean = clean.render(&parked(&robot), camera)?.to_vec();
    let diffs: Vec<f64> = a
        .iter()
        .zip(&clean)
        .map(|(n, c)| (f64::from(*n) - f64::from(*c)) / 255.0)
        .collect();
    let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
    let var = diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / diffs.len() as f64;
    let measured = var.sqrt();
    assert!(
        (measured - stddev).abs() <= 0.1 * stddev,
        "noise stddev {measured:.4}, configured {stddev}"
    );
    Ok(())
}

/// A depth image from the depth buffer: a 1 m cube whose near face is 2.5 m (then 4.5 m) in
/// front of the camera, square to the optical axis, reads that distance at every pixel of the
/// face within 1% (the optical frame's z, constant across the face); the sky beyond the clip
/// range is NaN; the ground's depth grows toward the horizon.
#[test]
fn the_depth_image_holds_each_pixels_distance_along_the_optical_axis() -> Result<()> {
    let robot = robot()?;
    let config = robot.cameras[0].clone();
    let info = CameraInfo::from_config(&config);
    let camera = Pose::from_translation(Vec3::new(0.0, 0.0, 0.5));
    for face_m in [2.5f64, 4.5] {
        let world = cube_world([face_m + 0.5, 0.0, 0.5], 1.0)?;
        let mut renderer = CameraRenderer::new(&world, &robot, &config, 0)?;
        renderer.enable_depth();
        let rgb = renderer.render(&parked(&robot), camera)?.to_vec();
        let depth = renderer.depth_m().ok_or("no depth image")?;
        let w = info.width as usize;
        assert_eq!(depth.len(), w * info.height as usize);
        // Every red pixel is the cube's near face.
        let mut face = 0;
        for (i, p) in rgb.chunks_exact(3).enumerate() {
            if p[0] > 60 && p[1] < 40 && p[2] < 40 {
                let d = f64::from(depth[i]);
                assert!(
                    (d - face_m).abs() <= 0.01 * face_m,
                    "pixel ({}, {}) of the face {face_m} m away reads {d} m",
                    i % w,
                    i / w
                );
                face += 1;
            }
        }
        assert!(face > 1000, "{face} face pixels");
        // The top row looks at the sky: nothing within the clip range.
        assert!(depth[..w].iter().all(|d| d.is_nan()));
        // The bottom row sees the ground: z = height / tan(dip), nearer toward the bottom.
        let bottom = f64::from(depth[(info.height as usize - 1) * w + w / 2]);
        let dip = ((f64::from(info.height) - 1.0 - info.k[5]) / info.k[4]).atan();
        let expected = 0.5 / dip.tan();
        assert!(
            (bottom - expected).abs() <= 0.01 * expected,
            "ground at the bottom row: {bottom} m, expected {expected} m"
        );
    }
    Ok(())
}

/// A depth camera's `<noise>` on its depth image, in metres (as gz-sim's depth camera applies
/// it): over a cube's face 2.5 m away the depth's mean stays within 2 mm of the distance and
/// its spread is the configured 2 cm within 10%; the same seed gives the same noisy image.
#[test]
fn a_depth_cameras_noise_is_gaussian_in_metres_and_seeded() -> Result<()> {
    let robot = robot()?;
    let mut config = robot.cameras[0].clone();
    let stddev = 0.02;
    config.noise = Some(GaussianNoise { mean: 0.0, stddev });
    let info = CameraInfo::from_config(&config);
    let camera = Pose::from_translation(Vec3::new(0.0, 0.0, 0.5));
    let world = cube_world([3.0, 0.0, 0.5], 1.0)?;
    let mut images = Vec::new();
    for _ in 0..2 {
        let mut renderer = CameraRenderer::new(&world, &robot, &config, 7)?;
        renderer.enable_depth();
        renderer.render(&parked(&robot), camera)?;
        images.push(renderer.depth_m().ok_or("no depth image")?.to_vec());
    }
    let w = info.width as usize;
    // The face's pixels: the middle third of the image, well inside the cube's outline.
    let (cx, cy) = (info.k[2] as usize, info.k[5] as usize);
    let face: Vec<f64> = (cy - 20..cy + 20)
        .flat_map(|y| (cx - 20..cx + 20).map(move |x| y * w + x))
        .map(|i| f64::from(images[0][i]))
        .collect();
    let mean = face.iter().sum::<f64>() / face.len() as f64;
    let spread = (face.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / face.len() as f64).sqrt();
    println!(
        "face: mean {mean:.4} m, stddev {spread:.4} m over {} pixels",
        face.len()
    );
    assert!((mean - 2.5).abs() < 0.002, "mean {mean}");
    assert!((spread - stddev).abs() <= 0.1 * stddev, "stddev {spread}");
    assert!(
        images[0][..w].iter().all(|d| d.is_nan()),
        "the sky stays NaN"
    );
    let same = images[0]
        .iter()
        .zip(&images[1])
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same, "two renders with the same seed differ");
    Ok(())
}

/// A depth camera's point cloud (gazebo_ros_openni_kinect's organized x y z rgb in the optical
/// frame): a wall 3 m ahead, square to the camera and then turned 30 deg; every point that is
/// not the ground lies within 1 cm of the wall's face once put back in the world, and carries
/// its pixel's colour; beyond the cutoffs the points are NaN.
#[test]
fn a_depth_clouds_points_lie_on_the_wall_they_see() -> Result<()> {
    use rover_sim::model::link_from_optical;
    use rover_sim::sensors::{CloudLayout, CloudSource, DepthCloudBuilder, PointCloud};
    let robot = robot()?;
    let config = robot.cameras[0].clone();
    let info = CameraInfo::from_config(&config);
    let builder = DepthCloudBuilder::new(&info);
    let camera = Pose::from_translation(Vec3::new(0.0, 0.0, 0.5));
    let world_from_optical = camera * Pose::from_rotation(link_from_optical());
    for yaw_deg in [0.0f32, 30.0] {
        // The wall's face passes through (3, 0) with its normal turned by yaw.
        let normal = Vec3::new(yaw_deg.to_radians().cos(), yaw_deg.to_radians().sin(), 0.0);
        let centre = Vec3::new(3.0, 0.0, 1.5) + normal * 0.1;
        let text = format!(
            "[ground]\ncolor = \"#202020\"\nchecker_color = \"#202020\"\n[[box]]\nsize_m = [0.2, 8.0, 3.0]\nposition_m = [{}, {}, 0.0]\nyaw_deg = {yaw_deg}\ncolor = \"#ff0000\"\n",
            centre.x, centre.y
        );
        let world = World::from_str(&text, Path::new("wall.toml"))?;
        let mut renderer = CameraRenderer::new(&world, &robot, &config, 0)?;
        renderer.enable_depth();
        let rgb = renderer.render(&parked(&robot), camera)?.to_vec();
        let depth = renderer.depth_m().ok_or("no depth image")?;
        let mut cloud = PointCloud::new(
            CloudSource::DepthCamera,
            &info.frame_id,
            CloudLayout::XyzRgb,
        );
        builder.fill(depth, &rgb, (0.4, 5.0), &mut cloud);
        assert_eq!((cloud.width, cloud.height), (info.width, info.height));
        assert_eq!(cloud.len(), (info.width * info.height) as usize);
        assert!(!cloud.is_dense, "the sky is NaN");
        let (mut on_wall, mut worst_m) = (0, 0.0f32);
        for (i, p) in cloud.points() {
            assert!(p[2] > 0.4 && p[2] < 5.0, "point {i} at depth {}", p[2]);
            let w = world_from_optical.transform_point(Vec3::from(p));
            if w.z < 0.05 {
                continue; // the ground
            }
            let off_m = (w - Vec3::new(3.0, 0.0, 0.0)).dot(normal).abs();
            worst_m = worst_m.max(off_m);
            let [r, g, b] = cloud.rgb(i).ok_or("no colour")?;
            assert!(
                r > 60 && g < 40 && b < 40,
                "point {i} of the red wall is {r} {g} {b}"
            );
            on_wall += 1;
        }
        assert!(on_wall > 10_000, "{on_wall} points on the wall");
        assert!(
            worst_m < 0.01,
            "yaw {yaw_deg}: a wall point {worst_m:.4} m off its face"
        );
        println!(
            "yaw {yaw_deg} deg: {on_wall} points, worst {:.2} mm off the wall",
            worst_m * 1000.0
        );
    }
    Ok(())
}
