//! Scratch per-op profile.
use std::collections::HashMap;
use tract_onnx::prelude::*;
fn main() -> TractResult<()> {
    let path = std::env::args().nth(1).unwrap_or_default();
    let model = tract_onnx::onnx()
        .model_for_path(&path)?
        .into_optimized()?
        .into_runnable()?;
    let input: Tensor = tract_ndarray::Array4::<f32>::from_elem((1, 3, 640, 640), 0.5).into();
    let mut state = tract_onnx::tract_core::plan::SimpleState::new(&model)?;
    let mut by_op: HashMap<String, (f64, usize)> = HashMap::new();
    for _ in 0..3 {
        state.run_plan_with_eval(
            tvec!(input.clone().into_tvalue()),
            |ctx, st, node, inputs| {
                let t = std::time::Instant::now();
                let r = tract_onnx::tract_core::plan::eval(ctx, st, node, inputs);
                let e = by_op.entry(node.op().name().to_string()).or_default();
                e.0 += t.elapsed().as_secs_f64() * 1000.0 / 3.0;
                e.1 += 1;
                r
            },
        )?;
    }
    let mut v: Vec<_> = by_op.into_iter().collect();
    v.sort_by(|a, b| b.1.0.total_cmp(&a.1.0));
    for (k, (ms, n)) in v.iter().take(25) {
        println!("{k:40} {ms:8.1} ms  x{}", n / 3);
    }
    Ok(())
}
