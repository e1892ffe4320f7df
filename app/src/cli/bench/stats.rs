//! Statistics the benchmarks share for their reports.

/// The median of `values` (sorted in place; NaN when there are none).
pub(crate) fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}
