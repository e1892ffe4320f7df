//! When a sensor reads: its update rate on sim time, accumulated as Gazebo's sensors accumulate
//! it (the next time is the last one plus the period, so a rate that does not divide the step
//! keeps its average), and every physics step at a rate of 0.

/// A sensor's (or a topic's) schedule on sim time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    period_s: f64,
    next_s: f64,
}

impl Schedule {
    /// Readings at `rate_hz` on sim time; 0 (or less): every step. The first is due at once.
    pub fn new(rate_hz: f64) -> Self {
        Self {
            period_s: if rate_hz > 0.0 { 1.0 / rate_hz } else { 0.0 },
            next_s: 0.0,
        }
    }

    /// Seconds between readings (0: every step).
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// True when a reading is due at `now_s`.
    pub fn due(&self, now_s: f64) -> bool {
        now_s + 1e-9 >= self.next_s
    }

    /// When due at `now_s`: takes this reading's slot and returns true. A schedule that fell
    /// more than a period behind (a paused sensor) starts again from `now_s`.
    pub fn take(&mut self, now_s: f64) -> bool {
        if !self.due(now_s) {
            return false;
        }
        self.next_s += self.period_s;
        if self.next_s + 1e-9 < now_s {
            self.next_s = now_s + self.period_s;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_follow_the_rate_and_rate_zero_is_every_step() {
        let step = 0.005;
        let count = |rate_hz: f64| {
            let mut s = Schedule::new(rate_hz);
            (1..=200).filter(|k| s.take(f64::from(*k) * step)).count()
        };
        // One second of 200 Hz steps: the first at the first step, then one per period up to
        // and including 1 s.
        assert_eq!(count(10.0), 11);
        assert_eq!(count(30.0), 31);
        assert_eq!(count(0.0), 200);
        assert_eq!(count(1000.0), 200, "no faster than the steps");
        let mut s = Schedule::new(10.0);
        assert!(s.take(0.005));
        assert!(!s.due(0.05) && s.due(0.1));
        // Fallen behind: restarts from now rather than firing every step to catch up.
        assert!(s.take(5.0));
        assert!(!s.take(5.005));
        assert!(s.take(5.1));
    }
}
