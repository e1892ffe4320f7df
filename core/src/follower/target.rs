//! What the follower tracks: its states, the target, and the people a detector message shows.

use super::filter::TargetFilter;
use super::tuning::{MOVING_MPS, PREDICTION_HORIZON_S, WALKER_HOLD_S};

/// What the follower is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FollowState {
    /// No detector message yet: holding still.
    #[default]
    Waiting,
    /// No detector (missing model, failure): holding still.
    NoDetector,
    /// Following a target seen lately.
    Tracking,
    /// Target lost: driving to the standoff from where it was last going, looking there.
    Pursuing,
    /// Target lost: turning toward where it is expected, then sweeping on the spot.
    Searching,
    /// Detections are stale: stopped.
    Stale,
}

impl FollowState {
    /// Lower-case name for logs, traces and the HUD.
    pub fn as_str(self) -> &'static str {
        match self {
            FollowState::Waiting => "waiting",
            FollowState::NoDetector => "no_detector",
            FollowState::Tracking => "tracking",
            FollowState::Pursuing => "pursuing",
            FollowState::Searching => "searching",
            FollowState::Stale => "stale",
        }
    }

    /// Every state, in a stable order (for plots: the index is the state's number).
    pub const ALL: [FollowState; 6] = [
        FollowState::Waiting,
        FollowState::NoDetector,
        FollowState::Tracking,
        FollowState::Pursuing,
        FollowState::Searching,
        FollowState::Stale,
    ];

    /// The state's number in [`FollowState::ALL`].
    pub fn index(self) -> usize {
        FollowState::ALL
            .iter()
            .position(|s| *s == self)
            .unwrap_or(0)
    }
}

/// The followed target, in the odometry frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowTarget {
    /// Track id (increments each time a new target is picked).
    pub id: u32,
    /// Position/velocity estimate.
    pub filter: TargetFilter,
    /// Sim time of the image it was last detected in (s).
    pub camera_s: f64,
    /// Sim time it was last seen by the camera or the laser (s).
    pub seen_s: f64,
    /// Range from the camera at the last detection (m).
    pub range_m: f64,
    /// Bearing at the last detection (rad, positive left).
    pub bearing_rad: f64,
    /// Detection probability.
    pub probability: f64,
    /// Whether it was last seen near, centred and too close for the camera to see whole (at the
    /// standoff a low camera sees legs only and detections flicker).
    pub close_and_centred: bool,
    /// The width of its box in the world (m), learned from its whole boxes: the range of a box
    /// cut off at the top or bottom comes from its width.
    pub width_m: f64,
    /// Sim time of the last update after which its estimate walked (faster than
    /// `MOVING_MPS`); None while it has not, or since it was halted.
    pub walked_s: Option<f64>,
}

impl FollowTarget {
    /// Whether the track was walking when last seen (its estimate's own velocity, not the
    /// prediction's, which runs out when the target is lost: that a prediction stopped does
    /// not mean the person did). A track halted because the person was not where the
    /// prediction walked them (see `Follower::note_missed`) stands.
    ///
    /// A walker's estimate dips below walking speed for a moment now and then (each box's range
    /// wanders with the gait: up to 0.6 s at a time with MakeHuman's walking body): it stays a
    /// walker until it has not walked for [`WALKER_HOLD_S`] of the time it was seen.
    pub fn last_seen_walking(&self) -> bool {
        self.walked_s
            .is_some_and(|walked| self.seen_s - walked <= WALKER_HOLD_S)
    }

    /// Notes, after an update at sim time `t_s`, whether the estimate walks.
    pub(super) fn note_speed(&mut self, t_s: f64) {
        let [vx, vy] = self.filter.velocity_mps();
        if vx.hypot(vy) > MOVING_MPS {
            self.walked_s = Some(self.walked_s.map_or(t_s, |w| w.max(t_s)));
        }
    }

    /// Estimated position now-ish (m, odometry frame): the filter's prediction at `time_s`.
    pub fn position_at(&self, time_s: f64) -> [f64; 2] {
        self.filter
            .predicted_position_m(time_s, PREDICTION_HORIZON_S)
    }
}

/// A person in a detector message, placed in the odometry frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Candidate {
    pub(super) position: [f64; 2],
    /// Bearing from the base's heading (rad, positive left).
    pub(super) bearing_rad: f64,
    pub(super) probability: f64,
    pub(super) seen: Measured,
}

/// What one box says about where a person is.
#[derive(Debug, Clone, Copy)]
pub(super) struct Measured {
    /// Horizontal range from the camera (m).
    pub(super) range_m: f64,
    /// Its 1-sigma uncertainty (m): the way it was measured and how far.
    pub(super) range_sigma_m: f64,
    /// Bearing from the optical axis (rad, positive left).
    pub(super) bearing_rad: f64,
    /// The box's width in the world (m), when the box is whole.
    pub(super) width_m: Option<f64>,
}
