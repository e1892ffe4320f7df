//! Tests that cannot run here say so in a way that counts.
//!
//! A test whose dependency is missing (a ROS package, `../shared`, a PyPI wheel that set-up did
//! not fetch, a service that will not start) calls [`skip`] (or a helper of this crate that
//! does) instead of passing quietly:
//!
//! * **Strict mode** — `CI` set to anything but `false`/`0` (CI runs with `CI=true`), or
//!   `ROVER_TEST_STRICT=1` (`./test --strict`): the skip is a failure, its message saying what
//!   was missing.
//! * Otherwise the test passes, the reason goes to stderr prefixed `SKIP:`, and a line goes to
//!   the file named by `ROVER_SKIP_LOG` (`./test` sets it), so `./test` counts the skips and
//!   lists them with their reasons instead of counting them as passed.
//!
//! Each line of the log is `STATUS<TAB>BINARY::TEST<TAB>REASON`, STATUS being `skipped` or
//! `failed` (strict mode). The test's name is its libtest thread's name; the binary's is the
//! test executable's without cargo's hash.

use std::fmt::Display;
use std::io::Write;

/// Whether a skip is a failure here: `CI` is set (and not `false` or `0`) or
/// `ROVER_TEST_STRICT=1`.
pub fn strict() -> bool {
    let truthy = |name: &str| {
        std::env::var(name)
            .is_ok_and(|v| !v.is_empty() && !v.eq_ignore_ascii_case("false") && v != "0")
    };
    truthy("ROVER_TEST_STRICT") || truthy("CI")
}

/// The running test, as `binary::module::test`.
pub fn current_test() -> String {
    let binary = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .map(|stem| match stem.rsplit_once('-') {
            // cargo names test executables NAME-HASH (16 hex digits).
            Some((name, hash))
                if hash.len() == 16 && hash.bytes().all(|b| b.is_ascii_hexdigit()) =>
            {
                name.to_owned()
            }
            _ => stem,
        })
        .unwrap_or_else(|| "?".to_owned());
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("main");
    format!("{binary}::{test}")
}

/// Records that the running test could not run (all of it, or the part `reason` names).
/// Outside strict mode: `Ok(())`, to be returned by the test (`return skip(...)`), after
/// saying why on stderr and in the skip log. In strict mode: an error naming what was
/// missing, so the test fails.
pub fn skip(reason: impl Display) -> anyhow::Result<()> {
    let reason = reason.to_string();
    if record(&reason) {
        anyhow::bail!("{}", strict_message(&reason));
    }
    Ok(())
}

/// Like [`skip`] for helpers that hand a test an `Option` (`None`: cannot run here): records
/// the skip and, in strict mode, panics with the reason, failing the test.
pub fn skip_or_panic(reason: impl Display) {
    let reason = reason.to_string();
    if record(&reason) {
        panic!("{}", strict_message(&reason));
    }
}

fn strict_message(reason: &str) -> String {
    format!(
        "could not run ({reason}); a skip is a failure in strict mode (CI set, or ./test --strict)"
    )
}

/// Says why on stderr and appends the skip to `ROVER_SKIP_LOG`; returns whether strict mode
/// makes it a failure.
fn record(reason: &str) -> bool {
    let strict = strict();
    let log = std::env::var_os("ROVER_SKIP_LOG").map(std::path::PathBuf::from);
    record_to(reason, &current_test(), strict, log.as_deref());
    strict
}

/// Writes the skip of `test` to stderr and to `log`, as [`skip`] does.
fn record_to(reason: &str, test: &str, strict: bool, log: Option<&std::path::Path>) {
    let status = if strict { "failed" } else { "skipped" };
    // One line, whatever the reason holds.
    let one_line = reason.replace(['\n', '\t'], " ");
    eprintln!("SKIP: {test}: {one_line}");
    if let Some(log) = log {
        let line = format!("{status}\t{test}\t{one_line}\n");
        // Appended with one write: tests running at once each add whole lines.
        let written = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(log)
            .and_then(|mut f| f.write_all(line.as_bytes()));
        if let Err(e) = written {
            eprintln!("cannot append to ROVER_SKIP_LOG {}: {e}", log.display());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_test_is_named_by_its_thread() {
        let name = current_test();
        assert!(
            name.ends_with("::skip::tests::the_test_is_named_by_its_thread"),
            "{name}"
        );
    }

    #[test]
    fn a_skip_is_one_line_of_the_log_saying_whether_it_failed() -> anyhow::Result<()> {
        let dir = tempfile::tempdir()?;
        let log = dir.path().join("skips.tsv");
        record_to("no ../shared\nhere", "bin::a", false, Some(&log));
        record_to("no rosmaster", "bin::b", true, Some(&log));
        assert_eq!(
            std::fs::read_to_string(&log)?,
            "skipped\tbin::a\tno ../shared here\nfailed\tbin::b\tno rosmaster\n"
        );
        Ok(())
    }

    #[test]
    fn the_strict_message_says_what_was_missing() {
        let m = strict_message("PyPI xacro==2.1.1 is not in the cache");
        assert!(
            m.contains("PyPI xacro==2.1.1") && m.contains("strict mode"),
            "{m}"
        );
    }
}
