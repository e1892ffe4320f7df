//! Ending a run early on SIGINT/SIGTERM: the flag runs check each step, and the error that
//! makes `rover` exit with code 130.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// A run that ended early on SIGINT/SIGTERM, after finishing its files: exit code 130.
#[derive(Debug)]
pub(crate) struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}

/// SIGINT (Ctrl-C) and SIGTERM set the returned flag: runs check it every step and end as at
/// their last step (trace rows complete, the .rrd finished with its footer). A second signal
/// while that is under way ends the process at once (exit code 130).
pub(crate) fn stop_on_signals() -> anyhow::Result<Arc<AtomicBool>> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&flag))?;
        signal_hook::flag::register(signal, Arc::clone(&flag))?;
    }
    Ok(flag)
}
