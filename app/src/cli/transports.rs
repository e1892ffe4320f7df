//! The ROS transports a run speaks, as one list: ROS 1 (`--ros`) and ROS 2 (`--ros2`,
//! `--record-mcap`), each a bridge that watches the run (an observer) and, where it listens,
//! an input that drives it; started from the flags, finished when the run ends. The headless
//! run and the window run hold the same list.

use std::path::PathBuf;

use anyhow::Result;
use rover_core::{Action, Fanout, InputSource, Observer};
use rover_sim::model::RobotModel;

use super::args::RosArgs;
use crate::ros::{RosBridge, RosInput};
use crate::ros2::{Ros2Bridge, Ros2Input};

/// One running transport.
trait Running {
    /// Its bridge, to watch the run, and its input, if it listens.
    fn parts(&mut self) -> (&mut dyn Observer, Option<&mut dyn InputSource>);
    /// Stops it, saying what it did; an error when it lost what it was to keep.
    fn finish(&mut self) -> Result<()>;
}

/// ROS 1: the bridge and its subscriptions.
struct Ros1 {
    bridge: RosBridge,
    input: RosInput,
}

impl Running for Ros1 {
    fn parts(&mut self) -> (&mut dyn Observer, Option<&mut dyn InputSource>) {
        (&mut self.bridge, Some(&mut self.input))
    }

    fn finish(&mut self) -> Result<()> {
        self.bridge.finish();
        if self.bridge.dropped() > 0 {
            tracing::info!(
                "ROS bridge: {} events dropped while it was behind",
                self.bridge.dropped()
            );
        }
        Ok(())
    }
}

/// ROS 2: the bridge (DDS and/or the MCAP file) and, with DDS, its subscriptions.
struct Ros2 {
    bridge: Ros2Bridge,
    input: Option<Ros2Input>,
    mcap: Option<PathBuf>,
}

impl Running for Ros2 {
    fn parts(&mut self) -> (&mut dyn Observer, Option<&mut dyn InputSource>) {
        let input = self.input.as_mut().map(|i| i as &mut dyn InputSource);
        (&mut self.bridge, input)
    }

    /// Also says what the MCAP file holds (an error when it could not be written in full).
    fn finish(&mut self) -> Result<()> {
        let recorded = self.bridge.finish().flatten();
        if self.bridge.dropped() > 0 {
            tracing::info!(
                "ROS 2 bridge: {} events dropped while it was behind",
                self.bridge.dropped()
            );
        }
        if let (Some(recorded), Some(path)) = (recorded, &self.mcap) {
            let summary = recorded?;
            say!(
                "MCAP: {} ({} messages on {} topics)",
                path.display(),
                summary.messages,
                summary.channels
            );
        }
        Ok(())
    }
}

/// The transports the flags ask for, in order: ROS 1, then ROS 2.
pub(super) struct Transports(Vec<Box<dyn Running>>);

impl Transports {
    /// Starts each transport `ros` asks for (none: an empty list) for `robot`;
    /// `ground_truth`: the run measures it (`--ground-truth`), and the bridges publish it.
    pub fn start(ros: &RosArgs, robot: &RobotModel, ground_truth: bool) -> Result<Self> {
        let mut list: Vec<Box<dyn Running>> = Vec::new();
        if let Some(options) = ros.options(ground_truth) {
            let (bridge, input) = RosBridge::start(&options, robot)?;
            list.push(Box::new(Ros1 { bridge, input }));
        }
        if let Some(options) = ros.ros2_options()? {
            let (bridge, input) = Ros2Bridge::start(&options, robot, ground_truth)?;
            list.push(Box::new(Ros2 {
                bridge,
                input,
                mcap: ros.record_mcap.clone(),
            }));
        }
        Ok(Self(list))
    }

    /// Puts each bridge on `fan`; the inputs, polled in turn.
    pub fn attach<'a>(&'a mut self, fan: &mut Fanout<'a>) -> Inputs<'a> {
        let mut inputs = Vec::new();
        for running in &mut self.0 {
            let (bridge, input) = running.parts();
            fan.push(bridge);
            inputs.extend(input);
        }
        Inputs(inputs)
    }

    /// Finishes every transport (each, even when one before it failed); the first error.
    pub fn finish(&mut self) -> Result<()> {
        let mut first = Ok(());
        for running in &mut self.0 {
            let finished = running.finish();
            if first.is_ok() {
                first = finished;
            }
        }
        first
    }
}

/// The transports' inputs, polled in turn: the first with an action gives it.
pub(super) struct Inputs<'a>(Vec<&'a mut dyn InputSource>);

impl InputSource for Inputs<'_> {
    fn poll(&mut self) -> Option<Action> {
        self.0.iter_mut().find_map(|input| input.poll())
    }
}
