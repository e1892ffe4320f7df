//! The layout the viewer opens with.

use rerun::blueprint::{
    Blueprint, Horizontal, Spatial2DView, Spatial3DView, TextLogView, TimePanel, TimeSeriesView,
    Vertical,
};

/// 3D view, camera view with boxes, plots, log. The 3D view's origin is the robot, so it opens
/// framed on the car and follows it (the world moves around it); the 40 x 40 m ground box is
/// left out of it (the view's grid stands in for the floor), since it would set the initial
/// framing and leave the car a few pixels wide.
pub fn blueprint() -> Blueprint {
    Blueprint::new(Horizontal::new([
        Vertical::new([
            Spatial3DView::new("World")
                .with_origin("world/robot")
                .with_contents(["/world/**", "- /world/ground"])
                .into(),
            TextLogView::new("Log").with_origin("log").into(),
        ])
        .with_row_shares([4.0f32, 1.0])
        .into(),
        Vertical::new([
            Spatial2DView::new("Camera")
                .with_origin(super::images::IMAGE_PATH)
                .into(),
            TimeSeriesView::new("Linear velocity")
                .with_origin("plots/velocity/linear")
                .into(),
            TimeSeriesView::new("Angular velocity")
                .with_origin("plots/velocity/angular")
                .into(),
            TimeSeriesView::new("Detector")
                .with_origin("plots/detector")
                .into(),
            TimeSeriesView::new("Joints (position, target)")
                .with_origin("plots/joints")
                .into(),
        ])
        .with_row_shares([3.0f32, 1.0, 1.0, 1.0, 1.0])
        .into(),
    ]))
    .with_time_panel(TimePanel::new().with_timeline("sim_time"))
}
