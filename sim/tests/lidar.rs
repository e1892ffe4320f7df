//! The 3D lidar on real physics: the VLP-16 on the tutorial car (assets/robots/
//! my_robot_vlp16.urdf.xacro) facing a wall 3 m ahead, its rings at their elevations and its
//! points on the wall, the organized form, noise, determinism and located errors.

use std::collections::BTreeMap;
use std::path::Path;

use rover_sim::{
    description::LoadOptions,
    model::{RobotModel, World},
    physics::{SimOptions, Simulation},
    sensors::{CloudLayout, LidarSensor, PointCloud},
};

mod common;

use common::{Result, assert_located_errors, car_with};

/// The VLP-16 car with its xacro args.
fn vlp16(args: &[(&str, &str)]) -> Result<RobotModel> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/robots/my_robot_vlp16.urdf.xacro");
    let mut options = LoadOptions::from_env();
    options.xacro_args = args
        .iter()
        .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
        .collect::<BTreeMap<_, _>>();
    Ok(RobotModel::load_with(&path, &options)?)
}

/// The wall's near face (world x, m): 3 m ahead of the sensor, which sits 6 cm behind the
/// car's origin.
const WALL_X_M: f32 = 2.94;

fn sim(robot: RobotModel, seed: u64) -> Result<Simulation> {
    let world = World::from_str(
        r#"
[[box]]
name = "wall"
size_m = [0.2, 8.0, 2.5]
position_m = [3.04, 0.0]
"#,
        Path::new("lidar-test.toml"),
    )?;
    let mut sim = Simulation::new(
        world,
        robot,
        &SimOptions {
            seed,
            ..SimOptions::default()
        },
    )?;
    // Let the car settle on its wheels.
    for _ in 0..100 {
        sim.step();
    }
    Ok(sim)
}

/// Each point's world position.
fn world_points(cloud: &PointCloud, sensor: &LidarSensor, sim: &Simulation) -> Vec<[f32; 3]> {
    let world_from_sensor = sensor.world_from_sensor(sim);
    cloud
        .points()
        .map(|(_, p)| {
            world_from_sensor
                .transform_point(glam::Vec3::from(p))
                .to_array()
        })
        .collect()
}

#[test]
fn the_vlp16_sees_each_ring_at_its_elevation_and_the_wall_where_it_is() -> Result<()> {
    let robot = vlp16(&[("lidar_noise", "0")])?;
    let c = robot.lidars.first().ok_or("no lidar")?.clone();
    assert!(
        robot.lasers.is_empty(),
        "a 16-beam ray sensor is no 2D laser"
    );
    assert_eq!(
        (c.vertical_samples, c.rays.samples, c.rays.topic.as_str()),
        (16, 1800, "/velodyne_points")
    );
    assert_eq!(c.rays.frame_name, "velodyne");
    assert!((c.rays.angle_increment_rad().to_degrees() - 0.2).abs() < 1e-6);
    let sim = sim(robot, 1)?;
    let mut lidar = LidarSensor::new(&sim, 0)?;
    let cloud = lidar.scan_now(&sim).clone();
    assert_eq!(cloud.layout, CloudLayout::XyzIntensityRing);
    assert_eq!((cloud.height, cloud.width as usize), (1, cloud.len()));
    assert!(cloud.is_dense);
    // Every ring, at its elevation.
    let mut per_ring = [0usize; 16];
    for (i, [x, y, z]) in cloud.points() {
        let ring = cloud.ring(i).ok_or("no ring")?;
        let elevation_deg = f64::from(z)
            .atan2(f64::from(x).hypot(f64::from(y)))
            .to_degrees();
        let expected_deg = -15.0 + 2.0 * f64::from(ring);
        assert!(
            (elevation_deg - expected_deg).abs() < 0.05,
            "point {i} of ring {ring}: elevation {elevation_deg:.3} deg, expected {expected_deg}"
        );
        per_ring[usize::from(ring)] += 1;
    }
    assert!(
        per_ring.iter().all(|&n| n > 100),
        "points per ring: {per_ring:?}"
    );
    // The points on the wall lie in its face; the rest are on the ground.
    let (mut on_wall, mut on_ground) = (0, 0);
    for [x, y, z] in world_points(&cloud, &lidar, &sim) {
        if y.abs() > 3.9 {
            continue; // the wall's ends
        }
        if z.abs() < 0.02 {
            on_ground += 1; // on the ground (or where it meets the wall)
        } else {
            assert!(
                (x - WALL_X_M).abs() < 0.02,
                "a point off the wall and ground: ({x:.4}, {y:.4}, {z:.4})"
            );
            on_wall += 1;
        }
    }
    assert!(
        on_wall > 2000 && on_ground > 2000,
        "{on_wall} on the wall, {on_ground} on the ground"
    );
    Ok(())
}

#[test]
fn the_organized_cloud_has_a_row_per_ring_with_nan_where_no_beam_returns() -> Result<()> {
    let robot = vlp16(&[("lidar_noise", "0"), ("organize_cloud", "true")])?;
    let sim = sim(robot, 1)?;
    let mut lidar = LidarSensor::new(&sim, 0)?;
    let cloud = lidar.scan_now(&sim).clone();
    assert_eq!((cloud.height, cloud.width), (16, 1800));
    assert_eq!(cloud.len(), 16 * 1800);
    assert_eq!(cloud.row_step_bytes(), 1800 * 32);
    // Upward beams facing away from the wall see nothing: NaN, so the cloud is not dense.
    assert!(!cloud.is_dense);
    for i in 0..cloud.len() {
        assert_eq!(usize::from(cloud.ring(i).ok_or("no ring")?), i / 1800);
    }
    // The forward column (yaw 0 is column 900) of ring 8 (+1 deg) hits the wall.
    let [x, _, _] = cloud.xyz(8 * 1800 + 900);
    assert!((x - 3.0).abs() < 0.05, "forward beam of ring 8 at x {x}");
    Ok(())
}

#[test]
fn gaussian_noise_spreads_the_ranges_by_its_stddev_and_repeats_with_the_seed() -> Result<()> {
    let ranges = |seed: u64| -> Result<Vec<f32>> {
        let sim = sim(vlp16(&[("lidar_noise", "0.05")])?, seed)?;
        let mut lidar = LidarSensor::new(&sim, 0)?;
        let cloud = lidar.scan_now(&sim);
        // Ring 8 (+1 deg) within 10 deg of straight ahead: all on the wall.
        Ok(cloud
            .points()
            .filter(|(i, [x, y, _])| cloud.ring(*i) == Some(8) && y.atan2(*x).abs() < 0.17)
            .map(|(_, [x, y, z])| (x * x + y * y + z * z).sqrt())
            .collect())
    };
    let a = ranges(3)?;
    assert_eq!(a, ranges(3)?, "the same seed gives the same cloud");
    assert_ne!(a, ranges(4)?);
    // The ideal range of each beam: the wall 3 m ahead at its yaw and +1 deg elevation.
    let sim = sim(vlp16(&[("lidar_noise", "0")])?, 3)?;
    let mut ideal = LidarSensor::new(&sim, 0)?;
    let exact: Vec<f32> = {
        let cloud = ideal.scan_now(&sim);
        cloud
            .points()
            .filter(|(i, [x, y, _])| cloud.ring(*i) == Some(8) && y.atan2(*x).abs() < 0.17)
            .map(|(_, [x, y, z])| (x * x + y * y + z * z).sqrt())
            .collect()
    };
    assert_eq!(a.len(), exact.len());
    let errors: Vec<f64> = a
        .iter()
        .zip(&exact)
        .map(|(n, e)| f64::from(n - e))
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let sd = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / errors.len() as f64).sqrt();
    assert!(errors.len() > 90, "{} beams", errors.len());
    assert!(
        mean.abs() < 0.01 && (sd - 0.05).abs() < 0.008,
        "mean {mean:.4}, sd {sd:.4}"
    );
    Ok(())
}

#[test]
fn a_ray_sensor_with_several_beams_on_any_ray_plugin_is_a_cloud() -> Result<()> {
    let robot = car_with(
        r#"<gazebo reference="camera_link"><sensor type="gpu_ray" name="tilted">
          <ray><scan>
            <horizontal><samples>90</samples><min_angle>-0.7</min_angle><max_angle>0.7</max_angle></horizontal>
            <vertical><samples>4</samples><min_angle>-0.1</min_angle><max_angle>0.2</max_angle></vertical>
          </scan><range><min>0.2</min><max>20</max></range></ray>
          <plugin name="ray" filename="libgazebo_ros_ray_sensor.so">
            <ros><remapping>~/out:=points3d</remapping></ros>
            <output_type>sensor_msgs/PointCloud2</output_type>
          </plugin></sensor></gazebo>"#,
    )?;
    assert!(robot.lasers.is_empty());
    let c = &robot.lidars[0];
    assert_eq!((c.vertical_samples, c.rays.samples), (4, 90));
    assert_eq!(c.rays.topic, "points3d");
    assert!((c.ring_elevation_rad(3) - 0.2).abs() < 1e-12);
    assert_eq!((c.min_range_m, c.max_range_m), (0.0, f64::INFINITY));
    Ok(())
}

#[test]
fn bad_vertical_scans_and_plugin_ranges_are_located_errors() -> Result<()> {
    let block = |vertical: &str, plugin: &str| {
        format!(
            r#"<gazebo reference="camera_link"><sensor type="ray" name="v">
              <ray><scan><vertical>{vertical}</vertical></scan></ray>
              <plugin name="p" filename="libgazebo_ros_velodyne_laser.so">{plugin}</plugin>
            </sensor></gazebo>"#
        )
    };
    let cases = [
        (
            block("<samples>sixteen</samples>", ""),
            "<samples> in <vertical> of <sensor name=\"v\">",
        ),
        (
            block(
                "<samples>16</samples><min_angle>0.3</min_angle><max_angle>-0.3</max_angle>",
                "",
            ),
            "<vertical> in <sensor name=\"v\">: expected min_angle <= max_angle",
        ),
        (
            block(
                "<samples>16</samples>",
                "<min_range>5</min_range><max_range>2</max_range>",
            ),
            "expected <min_range> below <max_range>",
        ),
        (
            block("<samples>16</samples>", "<gaussianNoise>-1</gaussianNoise>"),
            "<gaussianNoise> in <sensor name=\"v\">",
        ),
        (
            block(
                "<samples>16</samples>",
                "<organize_cloud>maybe</organize_cloud>",
            ),
            "<organize_cloud> in <sensor name=\"v\">: expected true or false",
        ),
    ];
    assert_located_errors(cases.iter().map(|(b, e)| (b.as_str(), *e)))
}

#[test]
fn a_range_finder_is_listed_not_read_as_a_laser_or_a_lidar() -> Result<()> {
    let robot = car_with(
        r#"<gazebo reference="camera_link"><sensor type="ray" name="sonar_front">
          <ray><scan>
            <horizontal><samples>5</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></horizontal>
            <vertical><samples>5</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></vertical>
          </scan><range><min>0.02</min><max>3</max></range></ray>
          <plugin name="sonar" filename="libgazebo_ros_range.so"><topicName>sonar</topicName></plugin>
        </sensor></gazebo>"#,
    )?;
    assert!(robot.lasers.is_empty() && robot.lidars.is_empty());
    assert!(
        robot
            .not_simulated
            .iter()
            .any(|s| s.contains("\"sonar_front\" (a range finder")),
        "{:?}",
        robot.not_simulated
    );
    Ok(())
}
