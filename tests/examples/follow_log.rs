//! A scenario's run as the follower saw it, one line per detector message: the ground truth
//! (robot pose, true range and bearing to the scenario's target), the follower's state, its
//! target estimate and pursued point, and every box of the target class. For tuning the
//! follower on a new robot; `rover eval` judges, this shows why.
//!
//! `cargo run -p rover-tests --example follow_log SCENARIO.toml [ROBOT.urdf[.xacro]]`
use std::path::PathBuf;

use rover_core::{
    LoopStats, Observer, Scenario, ScenarioOptions, range_bearing_from, run_scenario,
};
use rover_perception::BoundingBoxes;
use rover_sim::physics::{ControlSample, Odometry, Simulation};

#[derive(Default)]
struct Log {
    target: Option<usize>,
    class: String,
    /// (sim time, ground truth x, y, yaw, true range and bearing to the target).
    truth: Option<(f64, f64, f64, f64, f64, f64)>,
    stats: LoopStats,
    odom: Odometry,
}

impl Observer for Log {
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        let g = sample.ground_truth;
        let (range, bearing) = match self.target {
            Some(i) => {
                let (px, py, _) = sim.world().people[i].pose_at(sample.sim_time_s);
                range_bearing_from(g, [px, py])
            }
            None => (f64::NAN, f64::NAN),
        };
        self.truth = Some((sample.sim_time_s, g.x_m, g.y_m, g.yaw_rad, range, bearing));
        self.stats = *stats;
        self.odom = sample.odometry;
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let Some((t, x, y, yaw, range, bearing)) = self.truth else {
            return;
        };
        let rel = |p: Option<[f64; 2]>| {
            p.map_or("-".to_owned(), |p| {
                let (range_m, bearing_rad) = range_bearing_from(self.odom, p);
                format!("{range_m:.2}m {:+.0}deg", bearing_rad.to_degrees())
            })
        };
        let people: Vec<String> = boxes
            .bounding_boxes
            .iter()
            .filter(|b| b.class == self.class)
            .map(|b| {
                format!(
                    "{:.2}[x{}-{} y{}-{}]",
                    b.probability, b.xmin, b.xmax, b.ymin, b.ymax
                )
            })
            .collect();
        println!(
            "{t:6.2} img {:6.2}  robot ({x:+.2},{y:+.2},{:+.0}deg)  true {range:.2}m {:+.0}deg  {:<10} est {:<14} goal {:<14} {}",
            boxes.image_stamp.sim_time_s,
            yaw.to_degrees(),
            bearing.to_degrees(),
            self.stats.follow_state.as_str(),
            rel(self.stats.follow_target_m),
            rel(self.stats.follow_goal_m),
            people.join(" ")
        );
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let file = PathBuf::from(
        args.next()
            .ok_or_else(|| anyhow::anyhow!("usage: follow_log SCENARIO.toml [ROBOT]"))?,
    );
    let robot = args.next().map(PathBuf::from);
    let scenario = Scenario::load_with_robot(&file, robot.as_deref())?;
    let mut log = Log {
        target: scenario.target,
        class: rover_core::FollowerConfig::default().target_class,
        ..Log::default()
    };
    let result = run_scenario(&scenario, &ScenarioOptions::default(), &mut log)?;
    for c in &result.checks {
        println!(
            "{} {} (want {}) {}",
            c.name,
            c.value,
            c.limit,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
    Ok(())
}
