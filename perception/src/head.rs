//! YOLO output heads: decoding to candidate boxes, and class-wise non-maximum suppression.

use crate::error::{PerceptionError, Result};

/// The layout of a YOLO model's output.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Head {
    /// Ultralytics' raw detect head, cut before its built-in decode: `[1, 4*reg_max + C, N]`
    /// with distribution-focal box distances over anchors of `strides` (row-major grids).
    Dfl {
        /// Bins per box side (16 for Ultralytics models).
        reg_max: usize,
        /// Strides of the feature maps, in anchor order.
        strides: Vec<usize>,
    },
    /// `[1, 4+C, N]`: cx, cy, w, h in input pixels, then C class scores (YOLOv8/11/12 exports).
    AnchorFree,
    /// `[1, N, 5+C]`: cx, cy, w, h, objectness, C class scores (YOLOv5 exports).
    Objectness,
    /// `[1, K, 6]`: x1, y1, x2, y2, score, class (YOLOv10 end-to-end, already NMS-free).
    EndToEnd,
}

impl Head {
    /// Recognises the head from the output shape. Returns the head and its class count
    /// (`None` for [`Head::EndToEnd`], whose class count the labels decide).
    pub fn from_shape(shape: &[usize]) -> Option<(Head, Option<usize>)> {
        match *shape {
            [1, k, 6] if k <= 1000 => Some((Head::EndToEnd, None)),
            [1, a, n] if a > 4 && a < n => Some((Head::AnchorFree, Some(a - 4))),
            [1, n, b] if b > 5 && n > b => Some((Head::Objectness, Some(b - 5))),
            _ => None,
        }
    }

    /// A short name for messages.
    pub fn name(&self) -> &'static str {
        match self {
            Head::Dfl { .. } => "ultralytics raw head (decoded by rover)",
            Head::AnchorFree => "YOLOv8-style [1, 4+C, N]",
            Head::Objectness => "YOLOv5-style [1, N, 5+C]",
            Head::EndToEnd => "YOLOv10-style end-to-end [1, K, 6]",
        }
    }
}

/// A decoded box before NMS, in model-input pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// Class index.
    pub class: usize,
    /// Confidence.
    pub score: f32,
    /// Left (px).
    pub x1: f32,
    /// Top (px).
    pub y1: f32,
    /// Right (px).
    pub x2: f32,
    /// Bottom (px).
    pub y2: f32,
}

impl Candidate {
    fn area(&self) -> f32 {
        (self.x2 - self.x1).max(0.0) * (self.y2 - self.y1).max(0.0)
    }

    /// Intersection over union.
    pub fn iou(&self, o: &Candidate) -> f32 {
        let iw = (self.x2.min(o.x2) - self.x1.max(o.x1)).max(0.0);
        let ih = (self.y2.min(o.y2) - self.y1.max(o.y1)).max(0.0);
        let inter = iw * ih;
        let union = self.area() + o.area() - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
}

/// What decoding needs besides the output itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DecodeSpec {
    /// Model input width (px).
    pub input_w: usize,
    /// Model input height (px).
    pub input_h: usize,
    /// Number of classes the model predicts.
    pub num_classes: usize,
    /// Keep candidates scoring at least this.
    pub threshold: f32,
}

/// Decodes `output` (row-major, `shape`) into `out` (cleared first).
pub(crate) fn decode(
    head: &Head,
    output: &[f32],
    shape: &[usize],
    spec: DecodeSpec,
    out: &mut Vec<Candidate>,
) -> Result<()> {
    out.clear();
    let layout = Layout {
        head,
        output,
        shape,
    };
    if output.len() != shape.iter().product::<usize>() {
        return Err(layout.mismatch("as many values as the shape holds".into()));
    }
    match head {
        Head::Dfl { reg_max, strides } => decode_dfl(layout, *reg_max, strides, spec, out),
        Head::AnchorFree => decode_anchor_free(layout, spec, out),
        Head::Objectness => decode_objectness(layout, spec, out),
        Head::EndToEnd => decode_end_to_end(layout, spec, out),
    }
}

/// A model output with the head it is decoded as.
#[derive(Clone, Copy)]
struct Layout<'a> {
    head: &'a Head,
    output: &'a [f32],
    shape: &'a [usize],
}

impl Layout<'_> {
    /// The error for an output that does not fit its head; `expected` says what would.
    fn mismatch(&self, expected: String) -> PerceptionError {
        PerceptionError::Inference(format!(
            "model output {:?} does not match its head ({}): expected {expected}",
            self.shape,
            self.head.name()
        ))
    }
}

/// [`Head::Dfl`]: class logits per anchor, then distribution-focal distances of the four box
/// sides from the anchor's centre, in strides.
fn decode_dfl(
    layout: Layout<'_>,
    reg_max: usize,
    strides: &[usize],
    spec: DecodeSpec,
    out: &mut Vec<Candidate>,
) -> Result<()> {
    let DecodeSpec {
        input_w,
        input_h,
        num_classes,
        threshold,
    } = spec;
    let n: usize = strides.iter().map(|s| (input_w / s) * (input_h / s)).sum();
    let channels = 4 * reg_max + num_classes;
    if layout.shape != [1, channels, n] {
        return Err(layout.mismatch(format!("[1, {channels}, {n}]")));
    }
    // Class scores are logits here: compare against the threshold's logit so that the box
    // softmax runs only for anchors that can pass.
    let t = threshold.clamp(1e-6, 1.0 - 1e-6);
    let logit_threshold = (t / (1.0 - t)).ln();
    let output = layout.output;
    let at = |c: usize, a: usize| output[c * n + a];
    let mut anchor = 0;
    for &stride in strides {
        let (gw, gh) = (input_w / stride, input_h / stride);
        for gy in 0..gh {
            for gx in 0..gw {
                let a = anchor;
                anchor += 1;
                let (mut best, mut best_logit) = (0, f32::NEG_INFINITY);
                for c in 0..num_classes {
                    let v = at(4 * reg_max + c, a);
                    if v > best_logit {
                        best_logit = v;
                        best = c;
                    }
                }
                if best_logit < logit_threshold {
                    continue;
                }
                let dist = dfl_distances(|c| at(c, a), reg_max);
                let (cx, cy) = (gx as f32 + 0.5, gy as f32 + 0.5);
                let s = stride as f32;
                out.push(Candidate {
                    class: best,
                    score: 1.0 / (1.0 + (-best_logit).exp()),
                    x1: (cx - dist[0]) * s,
                    y1: (cy - dist[1]) * s,
                    x2: (cx + dist[2]) * s,
                    y2: (cy + dist[3]) * s,
                });
            }
        }
    }
    Ok(())
}

/// The expected bin (in strides) of each box side's softmax over `reg_max` bins; `channel`
/// reads one channel of the anchor (side `s`, bin `j` at channel `s * reg_max + j`).
fn dfl_distances(channel: impl Fn(usize) -> f32, reg_max: usize) -> [f32; 4] {
    let mut dist = [0f32; 4];
    for (side, d) in dist.iter_mut().enumerate() {
        let base = side * reg_max;
        let max = (0..reg_max)
            .map(|j| channel(base + j))
            .fold(f32::NEG_INFINITY, f32::max);
        let (mut sum, mut weighted) = (0f32, 0f32);
        for j in 0..reg_max {
            let e = (channel(base + j) - max).exp();
            sum += e;
            weighted += e * j as f32;
        }
        *d = weighted / sum;
    }
    dist
}

/// [`Head::AnchorFree`]: `[1, 4+C, N]`, one column per anchor.
fn decode_anchor_free(
    layout: Layout<'_>,
    spec: DecodeSpec,
    out: &mut Vec<Candidate>,
) -> Result<()> {
    let DecodeSpec {
        num_classes,
        threshold,
        ..
    } = spec;
    let [1, rows, n] = *layout.shape else {
        return Err(layout.mismatch("[1, 4+C, N]".into()));
    };
    if rows != 4 + num_classes {
        return Err(layout.mismatch(format!("[1, {}, N]", 4 + num_classes)));
    }
    let output = layout.output;
    for a in 0..n {
        let (mut best, mut score) = (0, f32::NEG_INFINITY);
        for c in 0..num_classes {
            let v = output[(4 + c) * n + a];
            if v > score {
                score = v;
                best = c;
            }
        }
        if score < threshold {
            continue;
        }
        let [cx, cy, w, h] = [0, 1, 2, 3].map(|r| output[r * n + a]);
        out.push(centre_box(best, score, cx, cy, w, h));
    }
    Ok(())
}

/// [`Head::Objectness`]: `[1, N, 5+C]`, one row per anchor; the score is objectness times the
/// best class score.
fn decode_objectness(layout: Layout<'_>, spec: DecodeSpec, out: &mut Vec<Candidate>) -> Result<()> {
    let DecodeSpec {
        num_classes,
        threshold,
        ..
    } = spec;
    let [1, n, cols] = *layout.shape else {
        return Err(layout.mismatch("[1, N, 5+C]".into()));
    };
    if cols != 5 + num_classes {
        return Err(layout.mismatch(format!("[1, N, {}]", 5 + num_classes)));
    }
    for row in layout.output.chunks_exact(cols).take(n) {
        let objectness = row[4];
        if objectness < threshold {
            continue;
        }
        let (mut best, mut cls) = (0, f32::NEG_INFINITY);
        for (c, v) in row[5..].iter().enumerate() {
            if *v > cls {
                cls = *v;
                best = c;
            }
        }
        let score = objectness * cls;
        if score >= threshold {
            out.push(centre_box(best, score, row[0], row[1], row[2], row[3]));
        }
    }
    Ok(())
}

/// [`Head::EndToEnd`]: `[1, K, 6]`, boxes already decoded and suppressed.
fn decode_end_to_end(layout: Layout<'_>, spec: DecodeSpec, out: &mut Vec<Candidate>) -> Result<()> {
    let DecodeSpec {
        num_classes,
        threshold,
        ..
    } = spec;
    let [1, k, 6] = *layout.shape else {
        return Err(layout.mismatch("[1, K, 6]".into()));
    };
    for row in layout.output.chunks_exact(6).take(k) {
        let class = row[5].round();
        if row[4] >= threshold && class >= 0.0 && (class as usize) < num_classes {
            out.push(Candidate {
                class: class as usize,
                score: row[4],
                x1: row[0],
                y1: row[1],
                x2: row[2],
                y2: row[3],
            });
        }
    }
    Ok(())
}

fn centre_box(class: usize, score: f32, cx: f32, cy: f32, w: f32, h: f32) -> Candidate {
    Candidate {
        class,
        score,
        x1: cx - w / 2.0,
        y1: cy - h / 2.0,
        x2: cx + w / 2.0,
        y2: cy + h / 2.0,
    }
}

/// Class-wise greedy non-maximum suppression: `candidates` is sorted by score (in place) and
/// the survivors, at most `max_boxes`, go to `keep` (cleared first), highest score first.
pub(crate) fn nms(
    candidates: &mut [Candidate],
    iou_threshold: f32,
    max_boxes: usize,
    keep: &mut Vec<Candidate>,
) {
    keep.clear();
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    for c in candidates.iter() {
        if keep.len() >= max_boxes {
            break;
        }
        if keep
            .iter()
            .all(|k| k.class != c.class || k.iou(c) <= iou_threshold)
        {
            keep.push(*c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(class: usize, score: f32, x1: f32) -> Candidate {
        Candidate {
            class,
            score,
            x1,
            y1: 0.0,
            x2: x1 + 10.0,
            y2: 10.0,
        }
    }

    #[test]
    fn heads_from_shapes() {
        assert_eq!(
            Head::from_shape(&[1, 84, 8400]),
            Some((Head::AnchorFree, Some(80)))
        );
        assert_eq!(
            Head::from_shape(&[1, 25200, 85]),
            Some((Head::Objectness, Some(80)))
        );
        assert_eq!(Head::from_shape(&[1, 300, 6]), Some((Head::EndToEnd, None)));
        assert_eq!(Head::from_shape(&[1, 3, 224, 224]), None);
    }

    #[test]
    fn anchor_free_decoding() -> Result<()> {
        // Two anchors, two classes: [1, 6, 2].
        let n = 2;
        let mut out = vec![0f32; 6 * n];
        let set = |o: &mut Vec<f32>, r: usize, a: usize, v: f32| o[r * n + a] = v;
        // Anchor 0: box centred (50, 40), 20x10, class 1 at 0.9.
        for (r, v) in [
            (0, 50.0),
            (1, 40.0),
            (2, 20.0),
            (3, 10.0),
            (4, 0.1),
            (5, 0.9),
        ] {
            set(&mut out, r, 0, v);
        }
        // Anchor 1: below threshold.
        set(&mut out, 4, 1, 0.2);
        let mut c = Vec::new();
        decode(
            &Head::AnchorFree,
            &out,
            &[1, 6, 2],
            DecodeSpec {
                input_w: 640,
                input_h: 640,
                num_classes: 2,
                threshold: 0.3,
            },
            &mut c,
        )?;
        assert_eq!(
            c,
            vec![Candidate {
                class: 1,
                score: 0.9,
                x1: 40.0,
                y1: 35.0,
                x2: 60.0,
                y2: 45.0
            }]
        );
        Ok(())
    }

    #[test]
    fn objectness_decoding_multiplies_scores() -> Result<()> {
        // [1, 2, 7]: two rows, 2 classes.
        let out = vec![
            10.0, 10.0, 4.0, 4.0, 0.8, 0.5, 0.9, // 0.8 * 0.9 = 0.72, class 1
            10.0, 10.0, 4.0, 4.0, 0.9, 0.2, 0.3, // 0.27 < 0.3
        ];
        let mut c = Vec::new();
        decode(
            &Head::Objectness,
            &out,
            &[1, 2, 7],
            DecodeSpec {
                input_w: 640,
                input_h: 640,
                num_classes: 2,
                threshold: 0.3,
            },
            &mut c,
        )?;
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].class, 1);
        assert!((c[0].score - 0.72).abs() < 1e-6);
        assert_eq!((c[0].x1, c[0].y2), (8.0, 12.0));
        Ok(())
    }

    #[test]
    fn end_to_end_decoding() -> Result<()> {
        let out = vec![
            1.0, 2.0, 30.0, 40.0, 0.95, 0.0, 5.0, 5.0, 6.0, 6.0, 0.1, 1.0,
        ];
        let mut c = Vec::new();
        decode(
            &Head::EndToEnd,
            &out,
            &[1, 2, 6],
            DecodeSpec {
                input_w: 640,
                input_h: 640,
                num_classes: 80,
                threshold: 0.3,
            },
            &mut c,
        )?;
        assert_eq!(
            c,
            vec![Candidate {
                class: 0,
                score: 0.95,
                x1: 1.0,
                y1: 2.0,
                x2: 30.0,
                y2: 40.0
            }]
        );
        Ok(())
    }

    #[test]
    fn dfl_decoding_puts_boxes_around_their_anchor() -> Result<()> {
        // A 64x32 input with stride 32 only: 2x1 anchors; reg_max 4, one class.
        let (reg_max, n) = (4, 2);
        let channels = 4 * reg_max + 1;
        let mut out = vec![-20f32; channels * n];
        // Anchor 1 (grid x = 1, centre (48, 16) px): every side's distribution peaks at bin 1,
        // i.e. 1 stride = 32 px, so the box spans 16..80 x -16..48.
        for side in 0..4 {
            out[(side * reg_max + 1) * n + 1] = 20.0;
        }
        out[(4 * reg_max) * n + 1] = 3.0; // logit 3 -> 0.9526
        let mut c = Vec::new();
        let head = Head::Dfl {
            reg_max,
            strides: vec![32],
        };
        decode(
            &head,
            &out,
            &[1, channels, n],
            DecodeSpec {
                input_w: 64,
                input_h: 32,
                num_classes: 1,
                threshold: 0.3,
            },
            &mut c,
        )?;
        assert_eq!(c.len(), 1, "anchor 0's score is far below threshold");
        let b = c[0];
        assert!((b.score - 0.952_574).abs() < 1e-4);
        for (got, want) in [(b.x1, 16.0), (b.y1, -16.0), (b.x2, 80.0), (b.y2, 48.0)] {
            assert!((got - want).abs() < 1e-3, "{b:?}");
        }
        // Wrong shapes are errors, not garbage.
        assert!(
            decode(
                &head,
                &out,
                &[1, channels, 3],
                DecodeSpec {
                    input_w: 64,
                    input_h: 32,
                    num_classes: 1,
                    threshold: 0.3
                },
                &mut c
            )
            .is_err()
        );
        Ok(())
    }

    #[test]
    fn nms_is_class_wise() {
        let mut c = vec![
            cand(0, 0.8, 0.0),
            cand(0, 0.9, 1.0),
            cand(1, 0.7, 1.0),
            cand(0, 0.6, 50.0),
        ];
        let mut keep = Vec::new();
        nms(&mut c, 0.4, 100, &mut keep);
        let got: Vec<(usize, f32)> = keep.iter().map(|k| (k.class, k.score)).collect();
        assert_eq!(got, vec![(0, 0.9), (1, 0.7), (0, 0.6)]);
        nms(&mut c, 0.4, 1, &mut keep);
        assert_eq!(keep.len(), 1);
    }
}
