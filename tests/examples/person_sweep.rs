//! Person visibility sweep with a free choice of detector input size, printing the Markdown table
//! for docs/PERCEPTION.md (the same sweep as `tests/tests/person_visibility.rs`).
//!
//! `cargo run -p rover-tests --example person_sweep [WxH] [OUT_DIR]`
use rover_tests::sweep::{PASS_CONFIDENCE, person_sweep};

fn main() -> anyhow::Result<()> {
    let size = match std::env::args().nth(1) {
        Some(s) => {
            let (w, h) = s
                .split_once('x')
                .ok_or_else(|| anyhow::anyhow!("input size must be WxH, e.g. 512x384"))?;
            Some((w.parse()?, h.parse()?))
        }
        None => None,
    };
    let out = std::env::args().nth(2).map(std::path::PathBuf::from);
    if let Some(dir) = &out {
        std::fs::create_dir_all(dir)?;
    }
    let distances: Vec<f64> = (3..=16).map(|i| f64::from(i) * 0.5).collect();
    let sweep = person_sweep(
        &distances,
        &[-25.0, -12.0, 0.0, 12.0, 25.0],
        size,
        out.as_deref(),
    )?;
    print!("{}", sweep.markdown());
    let (ok, counted) = sweep.score();
    println!(
        "camera {:.3} m above the ground; person >= {PASS_CONFIDENCE} in {ok}/{counted} frames fully in view",
        sweep.camera_height_m
    );
    Ok(())
}
