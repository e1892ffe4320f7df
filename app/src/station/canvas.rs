//! The station's CPU canvas: 0RGB pixels as softbuffer shows them, with filled rectangles and
//! text (detection boxes' outlines are `rover_perception::box_outline`'s rectangles, the rule
//! every picture of boxes follows).
//! Text comes from embedded-graphics' mono fonts (ASCII with lower case and punctuation, a
//! well-kept crate with no system font lookup), drawn through its `DrawTarget`.

use std::convert::Infallible;

use embedded_graphics::mono_font::{MonoFont, MonoTextStyle, ascii};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};

/// The HUD's font: 10 x 20 px cells, 64 characters across a 640 px image.
pub const FONT: &MonoFont<'static> = &ascii::FONT_10X20;

/// Width of one character cell of [`FONT`] (px).
pub const CHAR_W: i64 = 10;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// A pixel as softbuffer wants it: 0x00RRGGBB.
pub fn pack(rgb: Rgb) -> u32 {
    (u32::from(rgb[0]) << 16) | (u32::from(rgb[1]) << 8) | u32::from(rgb[2])
}

/// The RGB of a packed pixel.
pub fn unpack(px: u32) -> Rgb {
    [(px >> 16) as u8, (px >> 8) as u8, px as u8]
}

/// A borrowed canvas: `width * height` packed pixels, rows top to bottom.
#[derive(Debug)]
pub struct Canvas<'a> {
    /// Pixels, 0x00RRGGBB.
    pub pixels: &'a mut [u32],
    /// Width (px).
    pub width: usize,
    /// Height (px).
    pub height: usize,
}

impl Canvas<'_> {
    /// Sets one pixel (ignored outside the canvas).
    pub fn put(&mut self, x: i64, y: i64, rgb: Rgb) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        if let Some(p) = self.pixels.get_mut(y as usize * self.width + x as usize) {
            *p = pack(rgb);
        }
    }

    /// Fills a rectangle (clipped to the canvas).
    pub fn fill(&mut self, x: i64, y: i64, w: i64, h: i64, rgb: Rgb) {
        let (x0, x1) = (x.max(0), (x + w).min(self.width as i64));
        let (y0, y1) = (y.max(0), (y + h).min(self.height as i64));
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        let px = pack(rgb);
        for row in y0..y1 {
            let start = row as usize * self.width;
            self.pixels[start + x0 as usize..start + x1 as usize].fill(px);
        }
    }

    /// Draws `text` in [`FONT`] with its top-left corner at (x, y). Returns the x after the
    /// last character.
    pub fn text(&mut self, x: i64, y: i64, text: &str, rgb: Rgb) -> i64 {
        let style = MonoTextStyle::new(FONT, Rgb888::new(rgb[0], rgb[1], rgb[2]));
        let origin = Point::new(x as i32, y as i32);
        match Text::with_baseline(text, origin, style, Baseline::Top).draw(self) {
            Ok(next) => i64::from(next.x),
            Err(never) => match never {},
        }
    }
}

impl OriginDimensions for Canvas<'_> {
    fn size(&self) -> Size {
        Size::new(self.width as u32, self.height as u32)
    }
}

impl DrawTarget for Canvas<'_> {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = Pixel<Self::Color>>,
    {
        for Pixel(p, c) in pixels {
            self.put(i64::from(p.x), i64::from(p.y), [c.r(), c.g(), c.b()]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_has_lower_case_and_punctuation_inside_its_cells() {
        let (w, h) = (80, 24);
        let mut pixels = vec![0u32; w * h];
        let mut c = Canvas {
            pixels: &mut pixels,
            width: w,
            height: h,
        };
        let end = c.text(2, 2, "a{'}", [255, 255, 255]);
        assert_eq!(end, 2 + 4 * CHAR_W);
        // Every character of the HUD's warnings has a glyph: each cell has lit pixels.
        for cell in 0..4 {
            let x0 = 2 + cell * CHAR_W as usize;
            let lit = (0..h)
                .flat_map(|y| (x0..x0 + CHAR_W as usize).map(move |x| (x, y)))
                .filter(|&(x, y)| pixels[y * w + x] != 0)
                .count();
            assert!(lit > 0, "cell {cell} is empty");
        }
        // Nothing drawn outside the text's cells.
        assert!((0..h).all(|y| pixels[y * w] == 0 && pixels[y * w + w - 1] == 0));
    }

    #[test]
    fn fill_clips_and_packs() {
        let mut pixels = vec![0u32; 4 * 3];
        let mut c = Canvas {
            pixels: &mut pixels,
            width: 4,
            height: 3,
        };
        c.fill(-2, 1, 4, 5, [1, 2, 3]);
        assert_eq!(unpack(pixels[4]), [1, 2, 3]);
        assert_eq!(pixels.iter().filter(|p| **p != 0).count(), 4);
    }
}
