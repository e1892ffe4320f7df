//! Keyboard teleoperation with teleop_twist_keyboard's layout and speed keys.
//!
//! ```text
//!    u    i    o        i/,: forward/back   j/l: turn left/right in place
//!    j    k    l        u/o: forward turning left/right   m/.: back turning
//!    m    ,    .        k, space: stop
//! q/z: all speeds x1.1/x0.9   w/x: linear only   e/c: angular only
//! ```

use rover_sim::physics::Twist;

/// Default linear speed (m/s), as teleop_twist_keyboard's `~speed`.
const DEFAULT_SPEED_MPS: f64 = 0.5;
/// Default turn rate (rad/s), as teleop_twist_keyboard's `~turn`.
const DEFAULT_TURN_RADPS: f64 = 1.0;

/// What a key does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyAction {
    /// Drive in direction (x, th), scaled by the current speed and turn.
    Move {
        /// Linear direction: -1, 0 or 1.
        x: f64,
        /// Angular direction: -1, 0 or 1.
        th: f64,
    },
    /// Multiply the speed and turn limits.
    Scale {
        /// Factor on the linear speed.
        speed: f64,
        /// Factor on the turn rate.
        turn: f64,
    },
    /// Stop (k, space).
    Stop,
}

/// The teleop key for `name` (`"i"`, `","`, `"space"`, ...), or `None` if it is not a teleop key.
pub fn key_action(name: &str) -> Option<KeyAction> {
    let mv = |x, th| Some(KeyAction::Move { x, th });
    let scale = |speed, turn| Some(KeyAction::Scale { speed, turn });
    match name {
        "u" => mv(1.0, 1.0),
        "i" => mv(1.0, 0.0),
        "o" => mv(1.0, -1.0),
        "j" => mv(0.0, 1.0),
        "l" => mv(0.0, -1.0),
        "m" => mv(-1.0, -1.0),
        "," => mv(-1.0, 0.0),
        "." => mv(-1.0, 1.0),
        "q" => scale(1.1, 1.1),
        "z" => scale(0.9, 0.9),
        "w" => scale(1.1, 1.0),
        "x" => scale(0.9, 1.0),
        "e" => scale(1.0, 1.1),
        "c" => scale(1.0, 0.9),
        "k" | " " | "space" => Some(KeyAction::Stop),
        _ => None,
    }
}

/// Every key name [`key_action`] accepts, for help and error messages.
pub const TELEOP_KEYS: &str = "u i o j k l m , . q z w x e c space";

/// teleop_twist_keyboard's state: current direction and speed limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Teleop {
    /// Linear speed limit (m/s).
    pub speed_mps: f64,
    /// Turn rate limit (rad/s).
    pub turn_radps: f64,
    x: f64,
    th: f64,
}

impl Default for Teleop {
    fn default() -> Self {
        Self {
            speed_mps: DEFAULT_SPEED_MPS,
            turn_radps: DEFAULT_TURN_RADPS,
            x: 0.0,
            th: 0.0,
        }
    }
}

impl Teleop {
    /// Applies a key press, teleop_twist_keyboard style (latched: the motion continues until
    /// another key); returns the Twist it publishes.
    pub fn press(&mut self, action: KeyAction) -> Twist {
        match action {
            KeyAction::Move { x, th } => {
                self.x = x;
                self.th = th;
            }
            KeyAction::Scale { speed, turn } => {
                self.speed_mps *= speed;
                self.turn_radps *= turn;
            }
            KeyAction::Stop => {
                self.x = 0.0;
                self.th = 0.0;
            }
        }
        self.twist()
    }

    /// The Twist for the current direction and limits.
    pub fn twist(&self) -> Twist {
        Twist::new(self.x * self.speed_mps, self.th * self.turn_radps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_matches_teleop_twist_keyboard() {
        let table = [
            ("u", (1.0, 1.0)),
            ("i", (1.0, 0.0)),
            ("o", (1.0, -1.0)),
            ("j", (0.0, 1.0)),
            ("l", (0.0, -1.0)),
            ("m", (-1.0, -1.0)),
            (",", (-1.0, 0.0)),
            (".", (-1.0, 1.0)),
        ];
        for (key, (x, th)) in table {
            let mut t = Teleop::default();
            let action = key_action(key);
            assert_eq!(action, Some(KeyAction::Move { x, th }), "{key}");
            if let Some(a) = action {
                assert_eq!(t.press(a), Twist::new(x * 0.5, th * 1.0), "{key}");
            }
        }
    }

    #[test]
    fn speed_keys_scale_and_keep_direction() {
        let mut t = Teleop::default();
        for k in ["i", "q", "w", "c"] {
            if let Some(a) = key_action(k) {
                t.press(a);
            }
        }
        assert!((t.speed_mps - 0.5 * 1.1 * 1.1).abs() < 1e-12);
        assert!((t.turn_radps - 1.1 * 0.9).abs() < 1e-12);
        assert!(
            (t.twist().linear_mps - t.speed_mps).abs() < 1e-12,
            "still driving forward"
        );
        if let Some(a) = key_action("k") {
            assert_eq!(t.press(a), Twist::ZERO);
        }
        assert_eq!(key_action("space"), Some(KeyAction::Stop));
        assert_eq!(key_action("y"), None);
    }
}
