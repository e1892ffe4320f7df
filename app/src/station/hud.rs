//! The station's picture: the camera image, its boxes and the HUD under it.

use rover_core::{LoopStats, Mode, Session, range_bearing_from};
use rover_perception::box_outline;

use super::canvas::{CHAR_W, Canvas, Rgb};

/// Height of the HUD strip under the camera image (px).
pub(super) const HUD_H: usize = 134;

/// The HUD's background, also the margin colour when the window is scaled.
pub(super) const BACKGROUND: Rgb = [24, 26, 30];

/// Outline width of a detection box (px).
const BOX_THICKNESS_PX: u32 = 2;

/// Characters per HUD line at 640 px.
const LINE_CHARS: usize = 64;

/// The narrowest canvas: the HUD's lines fit (a narrower camera image is centred above it).
pub(super) const MIN_WIDTH: usize = LINE_CHARS * CHAR_W as usize;

/// The canvas for a camera image of `camera` (width, height, px): as wide as the image or the
/// HUD's lines, whichever is wider, and the HUD strip taller.
pub(super) fn canvas_size(camera: (usize, usize)) -> (usize, usize) {
    (camera.0.max(MIN_WIDTH), camera.1 + HUD_H)
}

/// Copies the camera image (`image`, `size` px) into the canvas's top, centred; the margins
/// beside a narrower image get the background. Whether it fitted.
fn draw_image(canvas: &mut Canvas<'_>, image: &[u32], size: (usize, usize)) -> Option<usize> {
    let (w, img_h) = (canvas.width, canvas.height.saturating_sub(HUD_H));
    let (iw, ih) = size;
    if iw > w || ih != img_h || image.len() != iw * ih {
        return None;
    }
    let x0 = (w - iw) / 2;
    if x0 > 0 {
        // The margins beside the image.
        canvas.fill(0, 0, x0 as i64, img_h as i64, BACKGROUND);
        let right = x0 + iw;
        canvas.fill(
            right as i64,
            0,
            (w - right) as i64,
            img_h as i64,
            BACKGROUND,
        );
    }
    for (row, src) in image.chunks_exact(iw).enumerate() {
        let start = row * w + x0;
        canvas.pixels[start..start + iw].copy_from_slice(src);
    }
    Some(x0)
}

/// What the HUD shows.
pub(super) struct HudState<'a> {
    /// The newest camera image, packed.
    pub image: &'a [u32],
    /// Its size (px).
    pub image_size: (usize, usize),
    /// The newest warning.
    pub warning: Option<&'a str>,
    /// The session (mode, commands, detections, follower).
    pub session: &'a Session,
    /// Whether the loop is paused.
    pub paused: bool,
    /// Measured sim seconds per wall second.
    pub real_time_factor: f64,
    /// The arm keys' line (robots with actuated joints).
    pub arm: Option<String>,
    /// With `--ground-truth`: how the newest detection result matched its image's ground
    /// truth ([`truth_text`]).
    pub truth: Option<&'a str>,
}

/// The newest detections' outlines and labels on the camera image, whose left edge is at
/// `x0` on the canvas and whose size is `image` (px).
fn draw_boxes(canvas: &mut Canvas<'_>, session: &Session, x0: i64, image: (usize, usize)) {
    let Some(boxes) = session.last_boxes() else {
        return;
    };
    for b in &boxes.bounding_boxes {
        let color = if b.class == session.follower().config().target_class {
            [255, 70, 70]
        } else {
            [80, 200, 255]
        };
        // The ROS detection image's and `rover detect`'s outline, on the camera image.
        let outline = box_outline(image.0 as u32, image.1 as u32, b, BOX_THICKNESS_PX);
        for r in outline.into_iter().flatten() {
            let (x, y) = (x0 + i64::from(r.x0), i64::from(r.y0));
            let (rw, rh) = (i64::from(r.x1 - r.x0), i64::from(r.y1 - r.y0));
            canvas.fill(x, y, rw, rh, color);
        }
        let label = format!("{} {:.2}", b.class, b.probability);
        let lw = label.len() as i64 * CHAR_W + 4;
        let ly = (b.ymin - 20).max(0);
        canvas.fill(x0 + b.xmin, ly, lw, 20, color);
        canvas.text(x0 + b.xmin + 2, ly, &label, [0, 0, 0]);
    }
}

/// Composes camera image, boxes and HUD into `canvas`.
pub(super) fn compose(canvas: &mut Canvas<'_>, hud: &HudState<'_>) {
    let (w, h) = (canvas.width, canvas.height);
    let img_h = h.saturating_sub(HUD_H);
    let (iw, _) = hud.image_size;
    let image_x = match draw_image(canvas, hud.image, hud.image_size) {
        Some(x0) => {
            canvas.fill(0, img_h as i64, w as i64, HUD_H as i64, BACKGROUND);
            Some(x0 as i64)
        }
        None => {
            canvas.fill(0, 0, w as i64, h as i64, BACKGROUND);
            canvas.text(20, 20, "waiting for the camera...", [200, 200, 200]);
            None
        }
    };
    let session = hud.session;
    if let Some(x0) = image_x {
        draw_boxes(canvas, session, x0, (iw, img_h));
    }
    let stats = session.stats();
    let teleop = session.pilot().teleop();
    let cmd = session.sim().drive().command();
    let y0 = img_h as i64 + 4;
    let (mode_text, mode_color) = match stats.mode {
        Mode::Manual => ("MANUAL".to_owned(), [120, 220, 120]),
        Mode::Follow => (
            format!(
                "FOLLOW ({}{}{})",
                stats.follow_state.as_str().to_uppercase(),
                GoalText::new(&stats, session.sim().odometry()),
                if stats.avoiding { ", avoiding" } else { "" }
            ),
            [255, 170, 60],
        ),
    };
    let x = canvas.text(8, y0, &mode_text, mode_color);
    let right = if hud.paused {
        "PAUSED (p resumes, n steps)".to_owned()
    } else {
        format!("t {:.1} s", session.sim().sim_time_s())
    };
    let rx = w as i64 - 8 - right.len() as i64 * CHAR_W;
    if rx > x + CHAR_W {
        canvas.text(rx, y0, &right, [255, 230, 80]);
    }
    let line2 = format!(
        "cmd {:+.2} m/s {:+.2} rad/s   max {:.2} m/s {:.2} rad/s",
        cmd.linear_mps, cmd.angular_radps, teleop.speed_mps, teleop.turn_radps
    );
    canvas.text(8, y0 + 22, &line2, [230, 230, 230]);
    let line3 = if let (true, Some(truth)) = (stats.detector_ok, hud.truth) {
        format!(
            "yolo {:.1} Hz {:.0} ms  {truth}  {:.2}x",
            stats.detector_hz, stats.detector_latency_ms, hud.real_time_factor
        )
    } else if stats.detector_ok {
        format!(
            "yolo {:.1} Hz {:.0} ms  dropped {}  sim {:.2}x real time",
            stats.detector_hz,
            stats.detector_latency_ms,
            stats.frames_dropped,
            hud.real_time_factor
        )
    } else if stats.detector_failed {
        format!(
            "detector FAILED  sim {:.2}x real time",
            hud.real_time_factor
        )
    } else {
        format!("detector off  sim {:.2}x real time", hud.real_time_factor)
    };
    let detector_color = if stats.detector_failed {
        [255, 120, 90]
    } else {
        [230, 230, 230]
    };
    canvas.text(8, y0 + 44, &line3, detector_color);
    match hud.warning {
        Some(warning) => {
            let (a, b) = split_line(warning, LINE_CHARS - 2);
            canvas.text(8, y0 + 66, &format!("! {a}"), [255, 120, 90]);
            let (b, _) = split_line(b, LINE_CHARS);
            canvas.text(8, y0 + 86, b, [255, 120, 90]);
        }
        None => {
            canvas.text(
                8,
                y0 + 66,
                "i , j l u o m . drive   k stop   q/z speed   f follow",
                [160, 170, 180],
            );
            match &hud.arm {
                Some(arm) => canvas.text(8, y0 + 86, arm, [255, 200, 120]),
                None => canvas.text(
                    8,
                    y0 + 86,
                    "p pause   pad: hold LB + sticks, A follow   Esc quit",
                    [160, 170, 180],
                ),
            };
        }
    }
    if let Some(sensors) = sensor_line(session) {
        let (text, _) = split_line(&sensors, LINE_CHARS);
        canvas.text(8, y0 + 108, text, [150, 200, 230]);
    }
}

/// One line with the newest reading of each kind of sensor the robot carries besides its
/// camera (`None`: none): the laser's nearest return, the first IMU's vertical acceleration
/// (gravity in it), the first GPS fix, what the first bumper touches (the other model's
/// name), the first lidar's points.
fn sensor_line(session: &Session) -> Option<String> {
    use std::fmt::Write as _;
    let mut line = String::new();
    if let Some(laser) = session.laser() {
        let nearest = laser
            .last()
            .ranges_m
            .iter()
            .copied()
            .filter(|r| r.is_finite())
            .fold(f32::INFINITY, f32::min);
        if nearest.is_finite() {
            let _ = write!(line, "scan {nearest:.2} m  ");
        } else {
            line.push_str("scan -  ");
        }
    }
    if let Some(imu) = session.imus().first() {
        let r = imu.last();
        let _ = write!(line, "imu {:.2} m/s2  ", r.linear_acceleration_mps2[2]);
    }
    if let Some(gps) = session.gpss().first() {
        let f = gps.last();
        let _ = write!(line, "gps {:.5},{:.5}  ", f.latitude_deg, f.longitude_deg);
    }
    if let Some(bumper) = session.bumpers().first() {
        let touching = bumper.last().contacts.first().map_or("-", |c| {
            c.other.split("::").next().unwrap_or(c.other.as_str())
        });
        let _ = write!(line, "bump {touching}  ");
    }
    if let Some(lidar) = session.lidars().first() {
        let _ = write!(line, "lidar {} pts", lidar.last().valid_len());
    }
    let line = line.trim_end();
    (!line.is_empty()).then(|| line.to_owned())
}

/// One detection result against its image's ground truth, for the HUD's detector line:
/// "truth 2: found 1 (IoU 0.97) missed 1 false 0" (written into `out`, cleared first).
pub(super) fn truth_text(
    out: &mut String,
    matched: &rover_perception::FrameMatch,
    truth: &[rover_sim::sensors::GroundTruthBox],
) {
    use std::fmt::Write as _;
    out.clear();
    let to_find = truth.iter().filter(|t| !t.ignore).count();
    let _ = write!(out, "truth {to_find}: found {}", matched.matches.len());
    if !matched.matches.is_empty() {
        let iou = matched.matches.iter().map(|m| m.iou).sum::<f64>() / matched.matches.len() as f64;
        let _ = write!(out, " (IoU {iou:.2})");
    }
    let _ = write!(
        out,
        " missed {} false {}",
        matched.misses.len(),
        matched.false_positives.len()
    );
}

/// Splits `text` after at most `chars` characters, at a space when there is one.
fn split_line(text: &str, chars: usize) -> (&str, &str) {
    let Some((cut, _)) = text.char_indices().nth(chars) else {
        return (text, "");
    };
    let at = text[..cut]
        .rfind(' ')
        .filter(|&i| i > cut / 2)
        .unwrap_or(cut);
    (&text[..at], text[at..].trim_start())
}

/// " 2.3 m +12 deg": where the point the follower drives to is from the robot (odometry);
/// nothing without one. Written straight into the HUD's line.
struct GoalText(Option<(f64, f64)>);

impl GoalText {
    fn new(stats: &LoopStats, odom: rover_sim::physics::Odometry) -> Self {
        Self(stats.follow_goal_m.map(|p| range_bearing_from(odom, p)))
    }
}

impl std::fmt::Display for GoalText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some((range_m, bearing_rad)) => {
                write!(f, " {range_m:.1} m {:+.0} deg", bearing_rad.to_degrees())
            }
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera narrower than the HUD (worlds/arm_car_reach.toml renders 320 px) gets a canvas
    /// the HUD's lines fit, the image centred with background beside it.
    #[test]
    fn a_narrow_camera_image_is_centred_above_a_hud_that_fits() {
        assert_eq!(canvas_size((320, 240)), (MIN_WIDTH, 240 + HUD_H));
        assert_eq!(canvas_size((1280, 720)), (1280, 720 + HUD_H));
        // The HUD's longest fixed line.
        let keys = "i , j l u o m . drive   k stop   q/z speed   f follow";
        assert!(keys.len() as i64 * CHAR_W + 8 <= MIN_WIDTH as i64);
        let (w, h) = canvas_size((320, 240));
        let mut pixels = vec![0u32; w * h];
        let mut canvas = Canvas {
            pixels: &mut pixels,
            width: w,
            height: h,
        };
        let image = vec![0x00ff_0000u32; 320 * 240];
        assert_eq!(draw_image(&mut canvas, &image, (320, 240)), Some(160));
        let bg = super::super::canvas::pack(BACKGROUND);
        assert_eq!(pixels[10 * w + 159], bg);
        assert_eq!(pixels[10 * w + 160], 0x00ff_0000);
        assert_eq!(pixels[239 * w + 479], 0x00ff_0000);
        assert_eq!(pixels[239 * w + 480], bg);
        // An image of another size than the canvas expects is not drawn.
        let mut canvas = Canvas {
            pixels: &mut pixels,
            width: w,
            height: h,
        };
        assert_eq!(draw_image(&mut canvas, &image, (320, 200)), None);
    }

    #[test]
    fn the_truth_line_counts_what_was_found_missed_and_false() {
        let thing = |ignore: bool| rover_sim::sensors::GroundTruthBox {
            id: 1,
            entity: rover_sim::model::Labelled::Person(0),
            class: "person".into(),
            name: "alice".into(),
            full: rover_sim::sensors::PixelBox {
                xmin: 0.0,
                ymin: 0.0,
                xmax: 10.0,
                ymax: 10.0,
            },
            visible: None,
            visible_px: 0,
            unoccluded_px: 0,
            visibility: 0.0,
            truncated: false,
            truncation: 0.0,
            ignore,
        };
        let matched = rover_perception::FrameMatch {
            matches: vec![rover_perception::MatchedPair {
                detection: 0,
                ground_truth: 0,
                iou: 0.974,
            }],
            misses: vec![1],
            false_positives: vec![1, 2],
            ignored: vec![],
        };
        let mut line = String::from("stale");
        truth_text(
            &mut line,
            &matched,
            &[thing(false), thing(false), thing(true)],
        );
        assert_eq!(line, "truth 2: found 1 (IoU 0.97) missed 1 false 2");
        let none = rover_perception::FrameMatch::default();
        truth_text(&mut line, &none, &[]);
        assert_eq!(line, "truth 0: found 0 missed 0 false 0");
    }

    #[test]
    fn warnings_wrap_at_a_space() {
        assert_eq!(split_line("short", 10), ("short", ""));
        assert_eq!(
            split_line("no detector (model missing); manual driving works", 20),
            ("no detector (model", "missing); manual driving works")
        );
        assert_eq!(split_line("abcdefghij", 4), ("abcd", "efghij"));
    }

    #[test]
    fn the_pursued_point_is_shown_from_the_robot() {
        let odom = rover_sim::physics::Odometry {
            x_m: 1.0,
            yaw_rad: std::f64::consts::FRAC_PI_2,
            ..rover_sim::physics::Odometry::default()
        };
        let stats = LoopStats {
            follow_goal_m: Some([1.0, 2.0]),
            ..LoopStats::default()
        };
        assert_eq!(GoalText::new(&stats, odom).to_string(), " 2.0 m +0 deg");
        let left = LoopStats {
            follow_goal_m: Some([0.0, 0.0]),
            ..LoopStats::default()
        };
        assert_eq!(GoalText::new(&left, odom).to_string(), " 1.0 m +90 deg");
        assert_eq!(GoalText::new(&LoopStats::default(), odom).to_string(), "");
    }
}
