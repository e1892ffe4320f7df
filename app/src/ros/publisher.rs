//! The publishing thread: it shows every event to every topic family, in the plan's order, and
//! sends the event's buffers back to the loop thread. It ends when the bridge hangs up, then
//! unregisters the node.

use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_ros1::Node;

use super::events::{BufferReturn, Event, TopicFamily};

/// Starts the thread.
pub(super) fn spawn(
    node: Node,
    families: Vec<Box<dyn TopicFamily>>,
    returns: BufferReturn,
    events: Receiver<Event>,
) -> Result<JoinHandle<()>> {
    std::thread::Builder::new()
        .name("ros-bridge".into())
        .spawn(move || run(node, families, &returns, &events))
        .context("starting the ROS bridge thread")
}

fn run(
    node: Node,
    mut families: Vec<Box<dyn TopicFamily>>,
    returns: &BufferReturn,
    events: &Receiver<Event>,
) {
    for mut event in events {
        for family in &mut families {
            match &mut event {
                Event::Start(start) => family.start(start),
                Event::Control(update) => family.control(update),
                Event::Image(image) => family.image(image),
                Event::Detections(detections) => family.detections(detections),
                Event::Truth(truth) => family.ground_truth(truth),
                Event::Scan(scan) => family.scan(scan),
            }
        }
        returns.give_back(event);
    }
    // Unregisters from the master; the publishers go after.
    drop(node);
    drop(families);
}
