//! Class colours shared by everything that draws boxes (`rover detect --out`, the Rerun
//! annotation context), so a class looks the same everywhere.

use image::Rgb;

/// A distinct, stable colour per class id.
pub fn class_color(id: i16) -> Rgb<u8> {
    const PALETTE: [[u8; 3]; 8] = [
        [255, 56, 56],
        [255, 157, 151],
        [255, 112, 31],
        [255, 178, 29],
        [207, 210, 49],
        [72, 249, 10],
        [26, 147, 52],
        [0, 212, 187],
    ];
    Rgb(PALETTE[(id.unsigned_abs() as usize) % PALETTE.len()])
}
