//! Ground truth from the camera's point of view, checked against what the real renderer draws.

use std::path::Path;

use anyhow::Result;
use rover_sim::{CameraSensor, GroundTruth, RobotModel, SimOptions, Simulation, World};

/// The tutorial car at the origin and a pure red 1 m cube labelled `suitcase` 5 m ahead.
const CUBE_WORLD: &str = r##"
name = "cube"
[[box]]
name = "cube"
size_m = [1.0, 1.0, 1.0]
position_m = [5.0, 0.3]
yaw_deg = 25.0
color = "#ff0000"
class = "suitcase"
"##;

/// The bounding box (edges, px) of the pixels where red dominates.
fn red_pixels_box(rgb: &[u8], width: usize) -> Option<[f64; 4]> {
    let mut b = [usize::MAX, usize::MAX, 0, 0];
    let mut any = false;
    for (i, px) in rgb.chunks_exact(3).enumerate() {
        let (r, g, bl) = (f64::from(px[0]), f64::from(px[1]), f64::from(px[2]));
        if r > 60.0 && r > 2.0 * g && r > 2.0 * bl {
            let (x, y) = (i % width, i / width);
            b = [b[0].min(x), b[1].min(y), b[2].max(x + 1), b[3].max(y + 1)];
            any = true;
        }
    }
    any.then(|| b.map(|v| v as f64))
}

/// Projection: the labelled cube's full box is where the renderer draws it, within 1 px on
/// every edge (no distortion, nothing in front; the cube turned so three faces show).
#[test]
fn a_labelled_cubes_full_box_is_where_the_renderer_draws_it() -> Result<()> {
    let world = World::from_str(CUBE_WORLD, Path::new("cube.toml"))?;
    let robot = RobotModel::load(&rover_tests::repo("assets/robots/my_robot.urdf"))?;
    let mut sim = Simulation::new(world, robot, &SimOptions::default())?;
    sim.step();
    let mut camera = CameraSensor::new(&sim)?;
    let info = camera.info().clone();
    let frame = camera.capture(&sim)?;
    let drawn = red_pixels_box(frame.rgb, frame.width as usize)
        .ok_or_else(|| anyhow::anyhow!("no red pixels: the cube is not in view"))?;
    let link = sim
        .robot()
        .link_id(&sim.robot().cameras[0].link)
        .ok_or_else(|| anyhow::anyhow!("no camera link"))?;
    let mut truth = GroundTruth::new(sim.world())?;
    let mut boxes = Vec::new();
    truth.full_boxes(&sim, &info, sim.world_from_link(link), &mut boxes);
    assert_eq!(boxes.len(), 1, "{boxes:?}");
    let b = &boxes[0];
    assert_eq!(
        (b.class.as_str(), b.name.as_str(), b.truncated),
        ("suitcase", "cube", false)
    );
    let truth_box = [b.xmin, b.ymin, b.xmax, b.ymax];
    println!("drawn {drawn:?}, ground truth {truth_box:?}");
    for (d, t) in drawn.iter().zip(truth_box) {
        assert!(
            (d - t).abs() <= 1.0,
            "drawn {drawn:?} vs ground truth {truth_box:?}"
        );
    }
    Ok(())
}
