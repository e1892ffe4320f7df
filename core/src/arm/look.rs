//! Look: turns a camera's chain (a pan-tilt head, or an arm with a wrist camera) so the chosen
//! detection's box centre converges on the image centre. From perception only: the boxes, the
//! camera's intrinsics and the robot's own joint positions; never the object's true pose.
//!
//! Each detector message: pick the box (the configured class, confident enough; the one nearest
//! the box looked at last, within a gate, so a second object does not take over), turn its
//! centre pixel into a ray in the camera link's frame, and move the chain's joints a fraction
//! of the way that turns the optical axis onto the ray ([`KinematicChain::pointing_step`]).
//! Nothing seen: no new targets (the joints hold where they are).

use nalgebra::Vector3;
use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::{
        CameraConfig, CameraInfo, ChainJoint, KinematicChain, KinematicsError, RobotModel,
        isometry_from_pose, link_from_optical,
    },
};

/// Look settings.
#[derive(Debug, Clone, PartialEq)]
pub struct LookConfig {
    /// Class to look at (darknet_ros `Class`).
    pub class: String,
    /// Minimum detection probability.
    pub min_probability: f64,
    /// Fraction of the angle to the box centre turned per detector message (the joints' own
    /// controllers do the motion).
    pub gain: f64,
    /// A box whose centre is further than this (px) from where the last one looked at is
    /// expected after the step is another object, unless nothing was looked at for
    /// `forget_after_s`.
    pub gate_px: f64,
    /// After this long without the object (s of sim time), any box of the class will do.
    pub forget_after_s: f64,
    /// Damping of the pointing step (rad).
    pub damping: f64,
}

impl Default for LookConfig {
    fn default() -> Self {
        Self {
            class: "person".into(),
            min_probability: 0.4,
            gain: 0.7,
            gate_px: 150.0,
            forget_after_s: 3.0,
            damping: 0.05,
        }
    }
}

/// The look controller for one camera on one chain.
#[derive(Debug, Clone)]
pub struct Look {
    config: LookConfig,
    chain: KinematicChain,
    /// fx, fy, cx, cy (px).
    intrinsics: [f64; 4],
    link_from_optical: nalgebra::UnitQuaternion<f64>,
    /// Where the box looked at last is expected after the step (px), and its image's time (s).
    last: Option<([f64; 2], f64)>,
    /// The centre of the box looked at last (px).
    looked_at: Option<[f64; 2]>,
}

impl Look {
    /// A look controller for `camera` of `robot`, moving the joints between `base_link` and
    /// the camera's link (e.g. TIAGo: `torso_lift_link`, its head's two joints).
    pub fn new(
        robot: &RobotModel,
        camera: &CameraConfig,
        base_link: &str,
        config: LookConfig,
    ) -> Result<Self, KinematicsError> {
        let chain = KinematicChain::new(robot, base_link, &camera.link)?;
        let info = CameraInfo::from_config(camera);
        let rotation = isometry_from_pose(&Pose::from_rotation(link_from_optical())).rotation;
        Ok(Self {
            config,
            chain,
            intrinsics: [info.k[0], info.k[4], info.k[2], info.k[5]],
            link_from_optical: rotation,
            last: None,
            looked_at: None,
        })
    }

    /// The settings.
    pub fn config(&self) -> &LookConfig {
        &self.config
    }

    /// The joints it moves, base to camera.
    pub fn joints(&self) -> &[ChainJoint] {
        self.chain.joints()
    }

    /// The centre of the box looked at last (px), if any.
    pub fn looked_at_px(&self) -> Option<[f64; 2]> {
        self.looked_at
    }

    /// Takes one detector message and the chain's joint positions (in [`Look::joints`]
    /// order, as they were at the image's time): the joints' new targets, or `None` when the
    /// object is not in this message (hold).
    pub fn observe(
        &mut self,
        boxes: &BoundingBoxes,
        q: &[f64],
    ) -> Result<Option<Vec<f64>>, KinematicsError> {
        let t = boxes.image_stamp.sim_time_s;
        let keep = self
            .last
            .filter(|(_, seen_s)| t - seen_s <= self.config.forget_after_s);
        let c = &self.config;
        let centre = boxes
            .bounding_boxes
            .iter()
            .filter(|b| b.class == c.class && b.probability >= c.min_probability)
            .map(|b| {
                (
                    [
                        (b.xmin + b.xmax) as f64 / 2.0,
                        (b.ymin + b.ymax) as f64 / 2.0,
                    ],
                    b.probability,
                )
            })
            .filter_map(|(px, p)| match keep {
                Some((last, _)) => {
                    let gap = (px[0] - last[0]).hypot(px[1] - last[1]);
                    (gap <= c.gate_px).then_some((px, -gap))
                }
                None => Some((px, p)),
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(px, _)| px);
        let Some(px) = centre else {
            return Ok(None);
        };
        let [fx, fy, cx, cy] = self.intrinsics;
        // Where the box should be once the joints have made this step: `gain` of the way to
        // the centre. The next box is gated around that.
        self.looked_at = Some(px);
        self.last = Some((
            [
                cx + (1.0 - c.gain) * (px[0] - cx),
                cy + (1.0 - c.gain) * (px[1] - cy),
            ],
            t,
        ));
        let ray_optical = Vector3::new((px[0] - cx) / fx, (px[1] - cy) / fy, 1.0).normalize();
        let ray_link = self.link_from_optical * ray_optical;
        let step = self.chain.pointing_step(
            q,
            self.link_from_optical * Vector3::z(),
            ray_link,
            c.damping,
        )?;
        Ok(Some(
            q.iter()
                .zip(&step)
                .zip(self.chain.joints())
                .map(|((q, s), j)| j.clamp(q + c.gain * s))
                .collect(),
        ))
    }
}
