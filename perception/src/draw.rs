//! Detection boxes drawn into pictures: one routine and one pixel-edge rule for every picture
//! rover draws them on (the ROS detection image, `rover detect --out`, the station's HUD).
//!
//! **The rule.** A [`BoundingBox`]'s bounds are pixel *edges*, half-open: the box covers the
//! columns `xmin..xmax` and the rows `ymin..ymax`, so `xmax` is the first column right of the
//! box and [`BoundingBox::width`] (`xmax - xmin`) counts its pixels, as
//! [`BoundingBox::iou`] reads them too. That is how darknet_ros fills its boxes
//! (`xmax = (x + w / 2) * frameWidth`, which reaches the frame's width at its right border) and
//! how the detector does (the box's edges in source pixels, rounded, clamped to `0..=width`).
//!
//! The outline lies inside the box, `thickness_px` wide: its outermost pixels are the columns
//! `xmin` and `xmax - 1` and the rows `ymin` and `ymax - 1`. The box is clipped to the image
//! first, so an edge beyond a border is drawn along that border; a box with no pixel in the
//! image (empty, inverted or outside it) draws nothing, and an outline thicker than half the
//! box fills it.

use crate::messages::BoundingBox;

/// A rectangle of whole pixels inside an image: columns `x0..x1`, rows `y0..y1` (half-open;
/// empty when `x0 == x1` or `y0 == y1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelRect {
    /// First column (px).
    pub x0: u32,
    /// First row (px).
    pub y0: u32,
    /// The column after the last (px).
    pub x1: u32,
    /// The row after the last (px).
    pub y1: u32,
}

impl PixelRect {
    /// Whether the rectangle has no pixel.
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }
}

/// The outline of `b` in a `width` x `height` image under the module's rule, as four
/// rectangles that never overlap (top, bottom, left, right; some may be empty): what
/// [`draw_box_rgb8`] fills, for pictures in other pixel formats. `None` when nothing is drawn.
pub fn box_outline(
    width: u32,
    height: u32,
    b: &BoundingBox,
    thickness_px: u32,
) -> Option<[PixelRect; 4]> {
    // Clamped into 0..=size, the conversion back to u32 is lossless.
    let clip = |v: i64, size: u32| v.clamp(0, i64::from(size)) as u32;
    let (x0, x1) = (clip(b.xmin, width), clip(b.xmax, width));
    let (y0, y1) = (clip(b.ymin, height), clip(b.ymax, height));
    if x0 >= x1 || y0 >= y1 || thickness_px == 0 {
        return None;
    }
    let top_end = y0 + thickness_px.min(y1 - y0);
    let bottom_start = y1.saturating_sub(thickness_px).max(top_end);
    let left_end = x0 + thickness_px.min(x1 - x0);
    let right_start = x1.saturating_sub(thickness_px).max(left_end);
    Some([
        PixelRect {
            x0,
            y0,
            x1,
            y1: top_end,
        },
        PixelRect {
            x0,
            y0: bottom_start,
            x1,
            y1,
        },
        PixelRect {
            x0,
            y0: top_end,
            x1: left_end,
            y1: bottom_start,
        },
        PixelRect {
            x0: right_start,
            y0: top_end,
            x1,
            y1: bottom_start,
        },
    ])
}

/// Draws `b`'s outline, `thickness_px` wide, in `rgb_colour` into a packed RGB8 image of
/// `width` x `height` pixels (rows top to bottom, 3 bytes a pixel), under the module's rule.
/// Rows that `rgb` is too short to hold are left out.
pub fn draw_box_rgb8(
    rgb: &mut [u8],
    width: u32,
    height: u32,
    b: &BoundingBox,
    thickness_px: u32,
    rgb_colour: [u8; 3],
) {
    let Some(bands) = box_outline(width, height, b, thickness_px) else {
        return;
    };
    let row_bytes = width as usize * 3;
    for band in bands.iter().filter(|r| !r.is_empty()) {
        for row in band.y0..band.y1 {
            let start = row as usize * row_bytes;
            let span = start + band.x0 as usize * 3..start + band.x1 as usize * 3;
            if let Some(pixels) = rgb.get_mut(span) {
                for px in pixels.chunks_exact_mut(3) {
                    px.copy_from_slice(&rgb_colour);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RED: [u8; 3] = [255, 0, 0];

    fn bbox(xmin: i64, ymin: i64, xmax: i64, ymax: i64) -> BoundingBox {
        BoundingBox {
            class: "person".into(),
            probability: 0.9,
            xmin,
            ymin,
            xmax,
            ymax,
            id: 0,
        }
    }

    /// The image drawn as text, one line per row: `#` drawn, `.` untouched.
    fn drawn(w: u32, h: u32, b: &BoundingBox, thickness_px: u32) -> Vec<String> {
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        draw_box_rgb8(&mut rgb, w, h, b, thickness_px, RED);
        rgb.chunks_exact(w as usize * 3)
            .map(|row| {
                row.chunks_exact(3)
                    .map(|px| match px {
                        [255, 0, 0] => '#',
                        [0, 0, 0] => '.',
                        _ => '?',
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn the_outline_covers_xmin_to_xmax_minus_one() {
        // Columns 1..5 and rows 1..4: the last drawn column is 4, the last row 3.
        assert_eq!(
            drawn(7, 5, &bbox(1, 1, 5, 4), 1),
            [".......", ".####..", ".#..#..", ".####..", "......."]
        );
    }

    #[test]
    fn a_thick_outline_grows_inward() {
        assert_eq!(
            drawn(8, 7, &bbox(1, 1, 7, 7), 2),
            [
                "........", ".######.", ".######.", ".##..##.", ".##..##.", ".######.", ".######."
            ]
        );
    }

    #[test]
    fn boxes_are_clipped_to_the_image_and_edges_drawn_along_its_borders() {
        assert_eq!(
            drawn(8, 6, &bbox(-5, 1, 100, 4), 1),
            [
                "........", "########", "#......#", "########", "........", "........"
            ]
        );
        // A box ending exactly at the image's size (as the detector and darknet_ros fill a
        // box at the border) draws its edge in the last column and row.
        assert_eq!(drawn(4, 3, &bbox(1, 0, 4, 3), 1), [".###", ".#.#", ".###"]);
    }

    #[test]
    fn degenerate_boxes_draw_nothing() {
        let nothing = vec!["....".to_owned(); 3];
        for b in [
            bbox(2, 0, 2, 3),   // no width
            bbox(0, 1, 4, 1),   // no height
            bbox(3, 2, 1, 0),   // inverted
            bbox(5, 0, 9, 3),   // right of the image
            bbox(-4, -3, 0, 0), // above and left of it
        ] {
            assert_eq!(drawn(4, 3, &b, 2), nothing, "{b:?}");
        }
        assert_eq!(drawn(4, 3, &bbox(0, 0, 4, 3), 0), nothing, "no thickness");
        assert!(
            box_outline(0, 0, &bbox(0, 0, 4, 3), 2).is_none(),
            "no image"
        );
    }

    #[test]
    fn an_outline_thicker_than_the_box_fills_it_once() {
        assert_eq!(
            drawn(5, 3, &bbox(1, 1, 4, 2), 2),
            [".....", ".###.", "....."]
        );
        let bands = box_outline(5, 3, &bbox(1, 0, 4, 3), 2)
            .into_iter()
            .flatten();
        let area: u32 = bands
            .filter(|r| !r.is_empty())
            .map(|r| (r.x1 - r.x0) * (r.y1 - r.y0))
            .sum();
        assert_eq!(area, 9, "the bands never overlap");
    }

    #[test]
    fn a_short_buffer_is_not_overrun() {
        let mut rgb = vec![0u8; 4 * 3 * 2];
        draw_box_rgb8(&mut rgb, 4, 3, &bbox(0, 0, 4, 3), 1, RED);
        assert_eq!(rgb[..12], [255, 0, 0].repeat(4)[..]);
    }
}
