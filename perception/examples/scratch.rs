//! Scratch timing.
use tract_onnx::prelude::*;
fn main() -> TractResult<()> {
    let path = std::env::args().nth(1).unwrap_or_default();
    let threads: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let t0 = std::time::Instant::now();
    let model = tract_onnx::onnx()
        .model_for_path(&path)?
        .into_optimized()?
        .into_runnable()?;
    println!("load+optimize {:?}", t0.elapsed());
    let input: Tensor = tract_ndarray::Array4::<f32>::from_elem(
        (
            1,
            3,
            std::env::var("H")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(640),
            std::env::var("W")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(640),
        ),
        0.5,
    )
    .into();
    let input = input.into_tvalue();
    if threads > 1 {
        tract_linalg::multithread::set_threading_panel_threshold(
            std::env::args()
                .nth(4)
                .and_then(|s| s.parse().ok())
                .unwrap_or(64),
        );
        tract_linalg::multithread::set_default_executor(
            tract_linalg::multithread::Executor::multithread(threads),
        );
    }
    let mut times = vec![];
    for _ in 0..std::env::args()
        .nth(3)
        .and_then(|s| s.parse().ok())
        .unwrap_or(6)
    {
        let t = std::time::Instant::now();
        let out = model.run(tvec!(input.clone()))?;
        times.push(t.elapsed().as_secs_f64() * 1000.0);
        let _ = out;
    }
    times.sort_by(f64::total_cmp);
    println!(
        "threads {threads}: median {:.0} ms, all {:?}",
        times[times.len() / 2],
        times
    );
    Ok(())
}
