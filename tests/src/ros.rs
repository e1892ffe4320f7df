//! Helpers for tests against real ROS 1 programs (Debian's rospy, rosmaster, roslaunch).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Result, ensure};

/// The Python that has rospy (another `python3` may come first on PATH and lack it).
pub const PYTHON: &str = "/usr/bin/python3";

/// Generates darknet_ros_msgs for rospy into `out` with genpy, from the message definitions in
/// `shared_ros/darknet_ros_msgs/msg` (as ../shared/ros/README.md says); returns the folder to
/// put on PYTHONPATH.
pub fn darknet_msgs(shared_ros: &Path, out: &Path) -> Result<PathBuf> {
    generate_msgs(
        "darknet_ros_msgs",
        &shared_ros.join("darknet_ros_msgs/msg"),
        &[("std_msgs", Path::new("/usr/share/std_msgs/msg"))],
        out,
    )
}

/// Generates ROS 1 package `package`'s messages for rospy into `out` with genpy, from the
/// `.msg` files in `msgs`; `deps` are the other packages' `.msg` folders they use. Returns the
/// folder to put on PYTHONPATH.
pub fn generate_msgs(
    package: &str,
    msgs: &Path,
    deps: &[(&str, &Path)],
    out: &Path,
) -> Result<PathBuf> {
    let pkg = out.join(package);
    let gen_args = |c: &mut Command| {
        c.args(["/usr/lib/genpy/genmsg_py.py", "-p", package])
            .arg(format!("-I{package}:{}", msgs.display()));
        for (dep, dir) in deps {
            c.arg(format!("-I{dep}:{}", dir.display()));
        }
        c.arg("-o").arg(pkg.join("msg"));
    };
    let mut files = Command::new(PYTHON);
    gen_args(&mut files);
    for entry in std::fs::read_dir(msgs)? {
        files.arg(entry?.path());
    }
    ensure!(files.status()?.success(), "genmsg_py failed for {package}");
    let mut init = Command::new(PYTHON);
    gen_args(&mut init);
    init.arg("--initpy");
    ensure!(
        init.status()?.success(),
        "genmsg_py --initpy failed for {package}"
    );
    std::fs::write(pkg.join("__init__.py"), "")?;
    Ok(out.to_path_buf())
}

/// A TCP port nothing listens on now (for a ROS master of a test's own).
pub fn free_port() -> Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}

/// A tmux server of a test's own (its socket and an empty config in `dir`) running one
/// session: a terminal for programs that read keys, such as teleop_twist_keyboard. The
/// server is killed when dropped.
pub struct Tmux {
    socket: PathBuf,
    conf: PathBuf,
    session: String,
}

impl Tmux {
    /// Starts `shell` in a 120x40 session.
    pub fn start(dir: &Path, shell: &str) -> Result<Self> {
        let conf = dir.join("tmux.conf");
        std::fs::write(&conf, "")?;
        let tmux = Self {
            socket: dir.join("tmux.sock"),
            conf,
            session: format!("rover-test-{}", std::process::id()),
        };
        let session = tmux.session.clone();
        tmux.run(&[
            "new-session",
            "-d",
            "-s",
            &session,
            "-x",
            "120",
            "-y",
            "40",
            shell,
        ])?;
        Ok(tmux)
    }

    /// Presses `key` in the session `times` (held: 200 ms apart, as a key repeats), each press
    /// a key-repeat gap after the one before, whichever key that was: teleop_twist_keyboard
    /// loses a key that comes while its publish thread is still sending the previous one
    /// (`update` notifies a condition nobody waits on yet), so a `k` typed within a millisecond
    /// of the last `i` could be lost and the car keep going.
    pub fn press(&self, key: &str, times: usize) -> Result<()> {
        for _ in 0..times {
            std::thread::sleep(std::time::Duration::from_millis(200));
            self.run(&["send-keys", "-t", &self.session, key])?;
        }
        Ok(())
    }

    fn run(&self, args: &[&str]) -> Result<()> {
        let status = Command::new("tmux")
            .arg("-S")
            .arg(&self.socket)
            .arg("-f")
            .arg(&self.conf)
            .args(args)
            .stderr(std::process::Stdio::null())
            .status()?;
        ensure!(status.success(), "tmux {args:?} failed");
        Ok(())
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        // The server is gone already when its one session ended.
        let _ = self.run(&["kill-server"]);
    }
}
