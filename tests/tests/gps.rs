//! hector's GPS (`libhector_gazebo_ros_gps.so`) and Gazebo's GPS sensor
//! (`libgazebo_ros_gps_sensor.so` on the world's spherical coordinates) on real physics: the
//! tutorial car driven 10 m east and 10 m north; every fix checked against WGS-84 geodesics
//! computed independently by geographiclib (PyPI, installed by set-up), to 1 cm; noise and bad
//! blocks.

use std::io::Write;
use std::process::{Command, Stdio};

use anyhow::{Context, Result, ensure};
use rover_sim::{
    geometry::Pose,
    model::{RobotModel, World},
    physics::{SimOptions, Simulation, Twist},
    sensors::GpsSensor,
};
use rover_tests::{repo, skip};

/// The tutorial car with a hector GPS on base_link, `params` added to the plugin.
fn car_with_gps(params: &str) -> Result<RobotModel> {
    let path = repo("assets/robots/my_robot.urdf");
    let text = std::fs::read_to_string(&path)?;
    let plugin = format!(
        r#"<gazebo><plugin name="gps" filename="libhector_gazebo_ros_gps.so">
      <bodyName>base_link</bodyName>{params}
    </plugin></gazebo>
</robot>"#
    );
    Ok(RobotModel::from_str(
        &text.replacen("</robot>", &plugin, 1),
        &path,
    )?)
}

fn sim(robot: RobotModel) -> Result<Simulation> {
    Ok(Simulation::new(
        World::flat()?,
        robot,
        &SimOptions::default(),
    )?)
}

/// Runs `seconds` under `cmd`, keeping each fix with the true position of the receiver (on
/// base_link, at the sensor's pose) then.
fn drive(
    sim: &mut Simulation,
    gps: &mut GpsSensor,
    cmd: Twist,
    seconds: f64,
    rows: &mut Vec<[f64; 6]>,
) -> Result<()> {
    sim.set_cmd_vel(cmd)?;
    let end = sim.sim_time_s() + seconds;
    let base = sim.robot().root;
    let at = gps.config().link_from_sensor;
    while sim.sim_time_s() < end - 1e-9 {
        sim.step();
        if let Some(fix) = gps.update(sim) {
            let p = sim.link_point_state(base, at).pose.translation;
            let (x, y, z) = (f64::from(p.x), f64::from(p.y), f64::from(p.z));
            rows.push([x, y, z, fix.latitude_deg, fix.longitude_deg, fix.altitude_m]);
        }
    }
    Ok(())
}

/// For each row `x y z lat lon alt`: the distance (m) between the fix and the point `x` m east
/// and `y` m north of the reference on WGS-84's ellipsoid (geographiclib's geodesic), and the
/// altitude's error. Prints `worst HORIZONTAL VERTICAL`.
const GEODESICS: &str = r#"
import math, sys
from geographiclib.geodesic import Geodesic
lat0, lon0, alt0 = map(float, sys.argv[1:4])
g = Geodesic.WGS84
worst_h = worst_v = 0.0
for line in sys.stdin:
    x, y, z, lat, lon, alt = map(float, line.split())
    d = math.hypot(x, y)
    if d > 0:
        p = g.Direct(lat0, lon0, math.degrees(math.atan2(x, y)), d)
        lat2, lon2 = p['lat2'], p['lon2']
    else:
        lat2, lon2 = lat0, lon0
    worst_h = max(worst_h, g.Inverse(lat2, lon2, lat, lon)['s12'])
    worst_v = max(worst_v, abs(alt0 + z - alt))
print('worst %.6f %.6f' % (worst_h, worst_v))
"#;

#[test]
fn fixes_driving_10_m_east_and_10_m_north_agree_with_wgs84_geodesics() -> Result<()> {
    if let Some(skipped) = no_geographiclib() {
        return skipped;
    }
    // x east, y north (heading 90), 10 Hz, a reference in Karlsruhe at 115 m.
    let robot = car_with_gps(
        "<updateRate>10</updateRate><referenceLatitude>49.0069</referenceLatitude>\
         <referenceLongitude>8.4037</referenceLongitude><referenceHeading>90</referenceHeading>\
         <referenceAltitude>115</referenceAltitude><frameId>gps_link</frameId>",
    )?;
    let c = &robot.gpss[0];
    assert_eq!(
        (
            c.topic.as_str(),
            c.velocity_topic.as_str(),
            c.frame_id.as_str()
        ),
        ("fix", "fix_velocity", "gps_link")
    );
    let mut sim = sim(robot)?;
    let mut gps = GpsSensor::new(&sim, 0).context("no GPS")?;
    let mut rows = Vec::new();
    // East (the car's x) 10 m, a quarter turn left, north 10 m.
    drive(&mut sim, &mut gps, Twist::new(0.5, 0.0), 22.5, &mut rows)?;
    drive(&mut sim, &mut gps, Twist::new(0.0, 0.5), 3.3, &mut rows)?;
    drive(&mut sim, &mut gps, Twist::new(0.5, 0.0), 20.5, &mut rows)?;
    let last = rows.last().context("no fixes")?;
    ensure!(
        last[0] > 9.0 && last[1] > 9.0,
        "the car should have driven ~10 m east and ~10 m north, it is at {:.2}, {:.2}",
        last[0],
        last[1]
    );
    ensure!(rows.len() > 400, "{} fixes at 10 Hz", rows.len());
    let [horizontal, vertical] = against_geodesics(&rows, [49.0069, 8.4037, 115.0])?;
    ensure!(
        horizontal <= 0.01,
        "a fix {horizontal} m from the geodesic's point"
    );
    ensure!(vertical <= 1e-6, "an altitude off by {vertical} m");
    Ok(())
}

/// The worst horizontal distance and altitude error (m) of `rows` (`east north up lat lon
/// alt`) against geographiclib's WGS-84 geodesics from `origin` (lat, lon, alt).
fn against_geodesics(rows: &[[f64; 6]], origin: [f64; 3]) -> Result<[f64; 2]> {
    let args = origin.map(|v| v.to_string());
    let mut child = Command::new("python3")
        .args(["-c", GEODESICS])
        .args(&args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()?;
    {
        let mut stdin = child.stdin.take().context("no stdin")?;
        for r in rows {
            writeln!(
                stdin,
                "{} {} {} {:.12} {:.12} {}",
                r[0], r[1], r[2], r[3], r[4], r[5]
            )?;
        }
    }
    let out = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{} fixes; geographiclib: {text}", rows.len());
    let worst: Vec<f64> = text
        .split_whitespace()
        .skip(1)
        .map(str::parse)
        .collect::<std::result::Result<_, _>>()?;
    ensure!(
        out.status.success() && worst.len() == 2,
        "geographiclib said {text}"
    );
    Ok([worst[0], worst[1]])
}

/// Whether python3 has geographiclib; `Some(skip)` when it has not.
fn no_geographiclib() -> Option<Result<()>> {
    let check = Command::new("python3")
        .args(["-c", "import geographiclib"])
        .status();
    (!check.is_ok_and(|s| s.success()))
        .then(|| skip("python3 cannot import geographiclib (scripts/setup.sh test installs it)"))
}

/// Gazebo's `<sensor type="gps">` with `libgazebo_ros_gps_sensor.so`, 10 cm ahead of and 5 cm
/// above base_link, on a world whose `[spherical_coordinates]` put it in Karlsruhe at 115 m
/// with its x axis 30 deg north of east: the car driven ~10 m along x and ~10 m along y, each
/// fix within 1 cm of geographiclib's WGS-84 geodesic to the sensor's true east-north offset
/// (the heading turned as Gazebo turns it), altitudes within 0.1 mm (the tangent plane rises
/// d^2 / 2R above the ellipsoid: 16 um at 14 m).
#[test]
fn the_gazebo_gps_sensor_reads_the_worlds_spherical_coordinates_on_wgs84() -> Result<()> {
    if let Some(skipped) = no_geographiclib() {
        return skipped;
    }
    let path = repo("assets/robots/my_robot.urdf");
    let text = std::fs::read_to_string(&path)?;
    let sensor = r#"<gazebo reference="base_link"><sensor type="gps" name="gps">
      <update_rate>10</update_rate><pose>0.1 0 0.05 0 0 0</pose>
      <plugin name="gps_plugin" filename="libgazebo_ros_gps_sensor.so">
        <ros><namespace>/car</namespace><remapping>~/out:=gps/fix</remapping></ros>
        <frame_name>gps_link</frame_name>
      </plugin></sensor></gazebo>
</robot>"#;
    let robot = RobotModel::from_str(&text.replacen("</robot>", sensor, 1), &path)?;
    let c = &robot.gpss[0];
    assert_eq!(
        (
            c.topic.as_str(),
            c.velocity_topic.as_str(),
            c.frame_id.as_str()
        ),
        ("/car/gps/fix", "/car/gps_plugin/vel", "gps_link")
    );
    let world = World::from_str(
        "[spherical_coordinates]\nlatitude_deg = 49.0069\nlongitude_deg = 8.4037\nelevation_m = 115.0\nheading_deg = 30.0\n",
        std::path::Path::new("karlsruhe.toml"),
    )?;
    let mut sim = Simulation::new(world, robot, &SimOptions::default())?;
    let mut gps = GpsSensor::new(&sim, 0).context("no GPS")?;
    let mut rows = Vec::new();
    drive(&mut sim, &mut gps, Twist::new(0.5, 0.0), 22.5, &mut rows)?;
    drive(&mut sim, &mut gps, Twist::new(0.0, 0.5), 3.3, &mut rows)?;
    drive(&mut sim, &mut gps, Twist::new(0.5, 0.0), 20.5, &mut rows)?;
    ensure!(rows.len() > 400, "{} fixes at 10 Hz", rows.len());
    // Gazebo's heading: east = x cos h + y sin h, north = -x sin h + y cos h.
    let (sin, cos) = 30f64.to_radians().sin_cos();
    for r in &mut rows {
        let (x, y) = (r[0], r[1]);
        (r[0], r[1]) = (x * cos + y * sin, -x * sin + y * cos);
    }
    let [horizontal, vertical] = against_geodesics(&rows, [49.0069, 8.4037, 115.0])?;
    ensure!(
        horizontal <= 0.01,
        "a fix {horizontal} m from the geodesic's point"
    );
    ensure!(vertical <= 1e-4, "an altitude off by {vertical} m");
    // The velocity is east, north, up: driving along +y at the end, 30 deg from north.
    let v = gps.last().velocity_mps;
    ensure!(
        (v[0] - 0.5 * sin).abs() < 0.05 && (v[1] - 0.5 * cos).abs() < 0.05,
        "velocity {v:?}"
    );
    Ok(())
}

#[test]
fn hectors_defaults_and_noise() -> Result<()> {
    // Defaults: 4 Hz, heading 0 (x north, y west), reference 49.9 N 8.9 E, frame /world.
    let robot = car_with_gps("<gaussianNoise>0 0.5 0</gaussianNoise>")?;
    let c = robot.gpss[0].clone();
    assert_eq!((c.update_rate_hz, c.reference_heading_deg), (4.0, 0.0));
    assert_eq!(
        (c.reference_latitude_deg, c.reference_longitude_deg),
        (49.9, 8.9)
    );
    assert_eq!(c.frame_id, "/world");
    let mut sim = sim(robot)?;
    let mut gps = GpsSensor::new(&sim, 0).context("no GPS")?;
    // Standing still: x north is exact, y (west) has 0.5 m of noise, read back in metres
    // against the true position (the car creeps by millimetres on its contacts).
    let (radius_north, radius_east) = rover_sim::sensors::wgs84_radii_m(49.9);
    let (mut north, mut west) = (Vec::new(), Vec::new());
    let base = sim.robot().root;
    while north.len() < 1000 {
        sim.step();
        if let Some(fix) = gps.update(&sim) {
            let p = sim.link_point_state(base, Pose::IDENTITY).pose.translation;
            north.push((fix.latitude_deg - 49.9).to_radians() * radius_north - f64::from(p.x));
            west.push(-(fix.longitude_deg - 8.9).to_radians() * radius_east - f64::from(p.y));
            assert_eq!(fix.position_covariance_diagonal, [0.0, 0.25, 0.0]);
        }
    }
    let stats = |v: &[f64]| {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        (mean, sd)
    };
    let (n_mean, n_sd) = stats(&north);
    let (w_mean, w_sd) = stats(&west);
    ensure!(
        n_sd < 1e-6 && n_mean.abs() < 0.01,
        "north {n_mean} +- {n_sd}"
    );
    ensure!(
        (w_sd / 0.5 - 1.0).abs() < 0.1,
        "west noise {w_sd}, asked 0.5"
    );
    ensure!(w_mean.abs() < 0.1, "west mean {w_mean}");
    ensure!(
        (sim.sim_time_s() - 250.0).abs() < 0.3,
        "1000 fixes at 4 Hz take 250 s, took {}",
        sim.sim_time_s()
    );
    Ok(())
}

#[test]
fn bad_gps_blocks_are_located_errors() -> Result<()> {
    for (params, expected) in [
        (
            "<referenceLatitude>95</referenceLatitude>",
            "<referenceLatitude>",
        ),
        ("<status>fixed</status>", "<status>"),
        ("<gaussianNoise>1 2</gaussianNoise>", "<gaussianNoise>"),
        ("<updateRate>-4</updateRate>", "<updateRate>"),
    ] {
        let err = car_with_gps(params)
            .err()
            .context("expected an error")?
            .to_string();
        ensure!(
            err.contains(expected) && err.contains("my_robot.urdf:"),
            "{err}"
        );
    }
    let path = repo("assets/robots/my_robot.urdf");
    let text = std::fs::read_to_string(&path)?.replacen(
        "</robot>",
        r#"<gazebo><plugin name="g" filename="libhector_gazebo_ros_gps.so"><bodyName>nowhere</bodyName></plugin></gazebo></robot>"#,
        1,
    );
    let err = RobotModel::from_str(&text, &path)
        .err()
        .context("expected an error")?
        .to_string();
    ensure!(err.contains("\"nowhere\": no such link"), "{err}");
    // Without <bodyName>: the robot's root link, as hector takes the model's first.
    let text = std::fs::read_to_string(&path)?.replacen(
        "</robot>",
        r#"<gazebo><plugin name="g" filename="libhector_gazebo_ros_gps.so"/></gazebo></robot>"#,
        1,
    );
    ensure!(RobotModel::from_str(&text, &path)?.gpss[0].link == "base_link");
    // Gazebo's sensor: bad noise is a located error; without its plugin it is listed.
    let sensor = |inner: &str| {
        let block = format!(
            r#"<gazebo reference="base_link"><sensor type="gps" name="fixer">{inner}</sensor></gazebo></robot>"#
        );
        std::fs::read_to_string(&path).map(|t| t.replacen("</robot>", &block, 1))
    };
    let text = sensor(
        r#"<gps><position_sensing><horizontal><noise type="gaussian"><stddev>-1</stddev></noise></horizontal></position_sensing></gps>
        <plugin name="g" filename="libgazebo_ros_gps_sensor.so"/>"#,
    )?;
    let err = RobotModel::from_str(&text, &path)
        .err()
        .context("expected an error")?
        .to_string();
    ensure!(
        err.contains("<stddev> in <sensor name=\"fixer\" type=\"gps\">")
            && err.contains("my_robot.urdf:"),
        "{err}"
    );
    let robot = RobotModel::from_str(&sensor("<update_rate>5</update_rate>")?, &path)?;
    ensure!(robot.gpss.is_empty());
    ensure!(
        robot
            .not_simulated
            .iter()
            .any(|s| s.contains("\"fixer\" (type gps")),
        "{:?}",
        robot.not_simulated
    );
    Ok(())
}
