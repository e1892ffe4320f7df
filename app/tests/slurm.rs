//! rover's shards on a real Slurm: Debian's slurm-wlm (slurmctld, slurmd) and munge, started
//! by the test on localhost in a folder of its own (no cgroups, no systemd), and the sbatch
//! files of scripts/slurm/ submitted unchanged. Skipped (counted and listed; a failure in strict mode) where Slurm is not
//! installed (`./test` installs it) or will not start.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail, ensure};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A one-node Slurm cluster (and its munge) running in `dir`; stopped when dropped.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
}

/// Why Slurm cannot run here, if it cannot.
fn missing_slurm() -> Option<String> {
    for tool in [
        "/usr/sbin/slurmctld",
        "/usr/sbin/slurmd",
        "/usr/sbin/munged",
        "/usr/bin/sbatch",
        "/usr/bin/squeue",
        "/usr/bin/scancel",
    ] {
        if !Path::new(tool).exists() {
            return Some(format!(
                "{tool} not found (apt-get install slurmctld slurmd slurm-client munge; ./test does)"
            ));
        }
    }
    None
}

/// A free TCP port on localhost.
fn free_port() -> Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}

impl Cluster {
    fn start() -> Result<Self> {
        let dir = tempfile::tempdir()?;
        let d = dir.path();
        for sub in ["state", "spool"] {
            std::fs::create_dir_all(d.join(sub))?;
        }
        // munge: its own key and socket.
        let key = d.join("munge.key");
        let mut bytes = vec![0u8; 128];
        use std::io::Read;
        std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
        std::fs::write(&key, &bytes)?;
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o600))?;
        let socket = d.join("munge.sock");
        let status = Command::new("/usr/sbin/munged")
            .arg("--force")
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--log-file={}", d.join("munged.log").display()))
            .arg(format!("--pid-file={}", d.join("munged.pid").display()))
            .arg(format!("--seed-file={}", d.join("munged.seed").display()))
            .status()?;
        ensure!(status.success(), "munged did not start");
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let conf = d.join("slurm.conf");
        let p = |name: &str| d.join(name).display().to_string();
        std::fs::write(
            &conf,
            format!(
                "ClusterName=rover\nSlurmctldHost=localhost\nSlurmUser=root\nSlurmdUser=root\n\
                 AuthType=auth/munge\nAuthInfo=socket={sock}\nCredType=cred/munge\n\
                 StateSaveLocation={state}\nSlurmdSpoolDir={spool}\n\
                 SlurmctldPidFile={ctld_pid}\nSlurmdPidFile={d_pid}\n\
                 SlurmctldPort={ctld_port}\nSlurmdPort={d_port}\n\
                 ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
                 SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nReturnToService=2\n\
                 SchedulerType=sched/backfill\nMpiDefault=none\nJobAcctGatherType=jobacct_gather/none\n\
                 AccountingStorageType=accounting_storage/none\n\
                 SlurmctldLogFile={ctld_log}\nSlurmdLogFile={d_log}\n\
                 NodeName=localhost NodeHostname=localhost NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=1 State=UNKNOWN\n\
                 PartitionName=rover Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n",
                sock = socket.display(),
                state = p("state"),
                spool = p("spool"),
                ctld_pid = p("slurmctld.pid"),
                d_pid = p("slurmd.pid"),
                ctld_port = free_port()?,
                d_port = free_port()?,
                ctld_log = p("slurmctld.log"),
                d_log = p("slurmd.log"),
            ),
        )?;
        let cluster = Self { dir, conf };
        let status = cluster.command("/usr/sbin/slurmctld").arg("-c").status()?;
        ensure!(status.success(), "slurmctld did not start");
        let status = cluster
            .command("/usr/sbin/slurmd")
            .args(["-N", "localhost"])
            .status()?;
        ensure!(status.success(), "slurmd did not start");
        let start = Instant::now();
        loop {
            let out = cluster
                .command("/usr/bin/sinfo")
                .args(["-h", "-o", "%T"])
                .output()?;
            let state = String::from_utf8_lossy(&out.stdout).trim().to_owned();
            if state == "idle" {
                return Ok(cluster);
            }
            if start.elapsed() > Duration::from_secs(60) {
                bail!(
                    "the node never came up (state \"{state}\"); slurmctld.log:\n{}",
                    cluster.log("slurmctld.log")
                );
            }
            std::thread::sleep(Duration::from_millis(300));
        }
    }

    fn log(&self, name: &str) -> String {
        std::fs::read_to_string(self.dir.path().join(name)).unwrap_or_default()
    }

    /// A Slurm command against this cluster.
    fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf)
            .current_dir(self.dir.path())
            .stdin(Stdio::null());
        c
    }

    /// `sbatch --parsable ARGS` with `env`: the job id.
    fn sbatch(&self, args: &[&str], env: &[(&str, &Path)]) -> Result<String> {
        let mut c = self.command("/usr/bin/sbatch");
        c.arg("--parsable").args(args);
        for (k, v) in env {
            c.env(k, v);
        }
        let out = c.output()?;
        ensure!(
            out.status.success(),
            "sbatch {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let id = String::from_utf8_lossy(&out.stdout).trim().to_owned();
        Ok(id.split(';').next().unwrap_or_default().to_owned())
    }

    /// squeue's lines for `job` (task id and state), empty once it is done.
    fn queue(&self, job: &str) -> Result<Vec<String>> {
        let out = self
            .command("/usr/bin/squeue")
            .args(["-h", "-j", job, "-o", "%i %T"])
            .output()?;
        Ok(String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(str::to_owned)
            .collect())
    }

    /// Waits for every task of `job` to leave the queue.
    fn wait(&self, job: &str, timeout: Duration) -> Result<()> {
        let start = Instant::now();
        while !self.queue(job)?.is_empty() {
            if start.elapsed() > timeout {
                bail!(
                    "job {job} still queued after {timeout:?}: {:?}",
                    self.queue(job)?
                );
            }
            std::thread::sleep(Duration::from_millis(500));
        }
        Ok(())
    }
}

impl Cluster {
    /// A started cluster, or `None` after recording why this test skips. Where Slurm is
    /// installed but will not start, that is a failure in strict mode like any skip (CI
    /// installs it and must be able to start it).
    fn start_or_skip() -> Option<Self> {
        if let Some(why) = missing_slurm() {
            rover_tests::skip::skip_or_panic(why);
            return None;
        }
        match Self::start() {
            Ok(c) => Some(c),
            Err(e) => {
                rover_tests::skip::skip_or_panic(format!("Slurm will not start here: {e:#}"));
                None
            }
        }
    }

    /// Submits `scripts`' array (with `extra` sbatch options, e.g. `--array=1`) and its merge,
    /// which runs once the array is over (`after`: `afterany`, or `afterok`): their job ids.
    fn submit(
        &self,
        scripts: &Scripts,
        extra: &[&str],
        after: &str,
        env: &[(&str, &Path)],
    ) -> Result<(String, String)> {
        let mut args = extra.to_vec();
        args.push(&scripts.array);
        let array = self.sbatch(&args, env)?;
        let dependency = format!("--dependency={after}:{array}");
        let merge = self.sbatch(&[dependency.as_str(), &scripts.merge], env)?;
        Ok((array, merge))
    }

    /// Cancels array task `task` (`ARRAY_1`) of `array` with scancel once `started` holds
    /// (polled every 50 ms; an error after `limit`), then waits for the merge `merge` and
    /// returns its log, `{log_prefix}-{merge}.log`.
    fn cancel_then_merge(
        &self,
        array: &str,
        task: &str,
        limit: Duration,
        mut started: impl FnMut(&[String]) -> bool,
        merge: &str,
        log_prefix: &str,
    ) -> Result<String> {
        let start = Instant::now();
        loop {
            let queue = self.queue(array)?;
            if started(&queue) {
                break;
            }
            ensure!(
                start.elapsed() < limit,
                "task {task} did not start: {queue:?}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        let status = self.command("/usr/bin/scancel").arg(task).status()?;
        ensure!(status.success(), "scancel {task} failed");
        self.wait(merge, Duration::from_secs(600))?;
        let log = self.log(&format!("{log_prefix}-{merge}.log"));
        println!("merge after scancel of {task}:\n{log}");
        Ok(log)
    }

    /// Shard 1 of 4 alone (`ROVER_SHARDS=4 sbatch --array=1`, as docs/SCALE.md says), then the
    /// merge once it succeeded: their job ids.
    fn rerun_shard_1(&self, scripts: &Scripts, env: &[(&str, &Path)]) -> Result<(String, String)> {
        let mut env = env.to_vec();
        env.push(("ROVER_SHARDS", Path::new("4")));
        self.submit(scripts, &["--array=1"], "afterok", &env)
    }
}

/// A sharded job's two sbatch files in scripts/slurm/, submitted unchanged.
struct Scripts {
    array: String,
    merge: String,
}

impl Scripts {
    /// scripts/slurm/NAME.sbatch and NAME-merge.sbatch.
    fn new(name: &str) -> Self {
        let path = |file: String| {
            repo()
                .join("scripts/slurm")
                .join(file)
                .display()
                .to_string()
        };
        Self {
            array: path(format!("{name}.sbatch")),
            merge: path(format!("{name}-merge.sbatch")),
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for pid_file in ["slurmd.pid", "slurmctld.pid", "munged.pid"] {
            if let Ok(pid) = std::fs::read_to_string(self.dir.path().join(pid_file)) {
                let _ = Command::new("kill").arg(pid.trim()).status();
            }
        }
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// Four short scenarios (bundled ones, 8 s each) in `dir`.
fn scenarios(dir: &Path) -> Result<PathBuf> {
    let out = dir.join("scenarios");
    std::fs::create_dir_all(&out)?;
    let repo = repo().canonicalize()?;
    for name in ["static_behind", "static_ahead_4m", "nobody", "crossing"] {
        let text = std::fs::read_to_string(repo.join(format!("scenarios/{name}.toml")))?;
        let mut lines: Vec<String> = Vec::new();
        for line in text.lines() {
            lines.push(if line.starts_with("duration_s") {
                "duration_s = 8.0".to_owned()
            } else {
                line.replace("\"../", &format!("\"{}/", repo.display()))
            });
        }
        std::fs::write(out.join(format!("{name}.toml")), lines.join("\n"))?;
    }
    Ok(out)
}

/// An eval report without its wall-clock figures: the report's `timing` and every result's
/// `wall_s`.
fn without_timing(path: &Path) -> Result<serde_json::Value> {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(o) => {
                o.remove("timing");
                o.remove("wall_s");
                o.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut v: serde_json::Value = serde_json::from_str(&text)?;
    strip(&mut v);
    Ok(v)
}

/// scripts/slurm/eval.sbatch as an array of 4 shards, then eval-merge.sbatch after it: the
/// merged report equals a one-machine `rover eval` of the same scenarios, field for field
/// apart from timing. Then a shard cancelled with scancel while it runs: the merge job names
/// it missing and writes nothing; that shard re-run alone completes the set, and the merge
/// gives the same report again.
#[test]
fn eval_shards_on_slurm_equal_a_one_machine_run() -> Result<()> {
    let Some(cluster) = Cluster::start_or_skip() else {
        return Ok(());
    };
    let rover = PathBuf::from(env!("CARGO_BIN_EXE_rover"));
    let dir = cluster.dir.path().to_owned();
    let scenarios = scenarios(&dir)?;
    let scripts = Scripts::new("eval");

    // One machine.
    let one = dir.join("one");
    let started = Instant::now();
    let status = Command::new(&rover)
        .arg("eval")
        .arg(&scenarios)
        .args(["--jobs", "2", "--out"])
        .arg(&one)
        .stdout(Stdio::null())
        .status()?;
    ensure!(
        one.join("eval.json").is_file(),
        "the one-machine eval wrote no report ({status})"
    );
    let one_s = started.elapsed().as_secs_f64();

    // The array and its merge.
    let out = dir.join("array");
    let env = [
        ("ROVER", rover.as_path()),
        ("ROVER_SCENARIOS", scenarios.as_path()),
        ("ROVER_OUT", out.as_path()),
    ];
    let started = Instant::now();
    let (_, merge) = cluster.submit(&scripts, &[], "afterany", &env)?;
    cluster.wait(&merge, Duration::from_secs(600))?;
    let wall_s = started.elapsed().as_secs_f64();
    let merged = out.join("eval.json");
    ensure!(
        merged.is_file(),
        "the merge job wrote no eval.json; its log:\n{}",
        cluster.log(&format!("rover-eval-merge-{merge}.log"))
    );
    for i in 0..4 {
        ensure!(out.join(format!("eval-shard-{i}-of-4.json")).is_file());
    }
    let (a, b) = (
        without_timing(&merged)?,
        without_timing(&one.join("eval.json"))?,
    );
    ensure!(
        a == b,
        "the merged report differs from the one-machine run's:\n{}\n--- one machine:\n{}",
        serde_json::to_string_pretty(&a)?,
        serde_json::to_string_pretty(&b)?
    );
    println!(
        "4 scenarios: one machine --jobs 2 {one_s:.1} s ({:.1} scenarios/min); 4 shards on Slurm and their merge {wall_s:.1} s ({:.1} scenarios/min); the report equals the one-machine run's",
        4.0 * 60.0 / one_s,
        4.0 * 60.0 / wall_s
    );

    // A shard cancelled mid-run.
    let out = dir.join("cancelled");
    let env = [
        ("ROVER", rover.as_path()),
        ("ROVER_SCENARIOS", scenarios.as_path()),
        ("ROVER_OUT", out.as_path()),
    ];
    let (array, merge) = cluster.submit(&scripts, &[], "afterany", &env)?;
    let task = format!("{array}_1");
    let running = format!("{task} RUNNING");
    // Cancelled a second into its run.
    let started = |queue: &[String]| {
        let running = queue.contains(&running);
        if running {
            std::thread::sleep(Duration::from_secs(1));
        }
        running
    };
    let limit = Duration::from_secs(120);
    let log =
        cluster.cancel_then_merge(&array, &task, limit, started, &merge, "rover-eval-merge")?;
    ensure!(
        log.contains("shard 1 of 4 missing") && !out.join("eval.json").exists(),
        "the merge did not name shard 1 missing:\n{log}"
    );
    ensure!(!out.join("eval-shard-1-of-4.json").exists());

    // Shard 1 alone, then the merge again.
    let (_, merge) = cluster.rerun_shard_1(&scripts, &env)?;
    cluster.wait(&merge, Duration::from_secs(600))?;
    ensure!(
        out.join("eval.json").is_file(),
        "the merge after the re-run wrote nothing:\n{}",
        cluster.log(&format!("rover-eval-merge-{merge}.log"))
    );
    ensure!(
        without_timing(&out.join("eval.json"))? == without_timing(&one.join("eval.json"))?,
        "the completed set's report differs from the one-machine run's"
    );
    println!("re-running shard 1 alone completed the set: the same report");
    Ok(())
}

/// How many images the Slurm dataset test makes (24 per shard; `ROVER_SLURM_DATASET_IMAGES`
/// sets another number, to measure throughput on a dataset large enough that start-up does not
/// dominate) and from which seed.
fn dataset_images() -> String {
    std::env::var("ROVER_SLURM_DATASET_IMAGES").unwrap_or_else(|_| "96".into())
}
const DATASET_SEED: &str = "7";

/// What dataset.sbatch reads: rover, the world, the image count, the seed, the output folder.
fn dataset_env<'a>(
    rover: &'a Path,
    world: &'a Path,
    images: &'a Path,
    out: &'a Path,
) -> [(&'static str, &'a Path); 5] {
    [
        ("ROVER", rover),
        ("ROVER_WORLD", world),
        ("ROVER_IMAGES", images),
        ("ROVER_SEED", Path::new(DATASET_SEED)),
        ("ROVER_OUT", out),
    ]
}

/// `rover dataset --jobs 2` of the playground world on one machine, into `out`.
fn one_machine_dataset(rover: &Path, world: &Path, out: &Path) -> Result<f64> {
    let started = Instant::now();
    let output = Command::new(rover)
        .arg("dataset")
        .arg("--world")
        .arg(world)
        .args(["--images", &dataset_images(), "--seed", DATASET_SEED])
        .args(["--jobs", "2", "--out"])
        .arg(out)
        .output()?;
    ensure!(
        output.status.success(),
        "the one-machine dataset failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    Ok(started.elapsed().as_secs_f64())
}

/// The labels, records, COCO JSON, data.yaml and manifest of two dataset folders are equal
/// file for file (SHA-256); so are the images. Returns how many files were compared.
fn same_dataset(merged: &Path, one: &Path) -> Result<usize> {
    let (a, b) = (
        rover_tests::file_hashes(merged)?,
        rover_tests::file_hashes(one)?,
    );
    let only = |x: &std::collections::BTreeMap<String, String>,
                y: &std::collections::BTreeMap<String, String>| {
        x.keys()
            .filter(|k| !y.contains_key(*k))
            .cloned()
            .collect::<Vec<_>>()
    };
    ensure!(
        a.keys().eq(b.keys()),
        "different files: only in the merge {:?}, only in the one-machine run {:?}",
        only(&a, &b),
        only(&b, &a)
    );
    let differing: Vec<&String> = a.keys().filter(|k| a[*k] != b[*k]).collect();
    ensure!(
        differing.is_empty(),
        "{} files differ from the one-machine run's, e.g. {:?}",
        differing.len(),
        &differing[..differing.len().min(5)]
    );
    ensure!(
        a.keys().any(|k| k.starts_with("labels/"))
            && a.contains_key("annotations/instances_train.json")
            && a.contains_key("data.yaml"),
        "the dataset lacks labels, COCO JSON or data.yaml: {:?}",
        a.keys().take(10).collect::<Vec<_>>()
    );
    Ok(a.len())
}

/// scripts/slurm/dataset.sbatch as an array of 4 shards, then dataset-merge.sbatch after it:
/// the merged dataset's labels, records, COCO JSON and images are SHA-256-equal to a
/// one-machine run of the same seed. Then shard 1 cancelled with scancel after its first
/// images: the merge names it missing and writes nothing; shard 1 re-run alone goes on from
/// the images it kept, and the merge equals the one-machine run again.
#[test]
fn dataset_shards_on_slurm_equal_a_one_machine_run() -> Result<()> {
    let Some(cluster) = Cluster::start_or_skip() else {
        return Ok(());
    };
    let rover = PathBuf::from(env!("CARGO_BIN_EXE_rover"));
    let dir = cluster.dir.path().to_owned();
    let world = repo().canonicalize()?.join("worlds/playground.toml");
    let scripts = Scripts::new("dataset");
    let count = dataset_images();
    let images: f64 = count.parse()?;

    let one = dir.join("one");
    let one_s = one_machine_dataset(&rover, &world, &one)?;

    let images_arg = PathBuf::from(&count);
    let env = |out| dataset_env(&rover, &world, &images_arg, out);
    let out = dir.join("array");
    let started = Instant::now();
    let (array, merge) = cluster.submit(&scripts, &[], "afterany", &env(&out))?;
    cluster.wait(&merge, Duration::from_secs(600))?;
    let wall_s = started.elapsed().as_secs_f64();
    let merged = out.join("dataset");
    ensure!(
        merged.join("data.yaml").is_file(),
        "the merge job wrote no dataset; its log:\n{}\nshard 0's log:\n{}",
        cluster.log(&format!("rover-dataset-merge-{merge}.log")),
        cluster.log(&format!("rover-dataset-{array}_0.log"))
    );
    let files = same_dataset(&merged, &one)?;
    println!(
        "{count} images: one machine --jobs 2 {one_s:.1} s ({:.1} images/s); 4 shards on Slurm and their merge {wall_s:.1} s ({:.1} images/s); {files} files SHA-256-equal to the one-machine run's",
        images / one_s,
        images / wall_s
    );

    // Shard 1 cancelled after its first complete images.
    let out = dir.join("cancelled");
    let (array, merge) = cluster.submit(&scripts, &[], "afterany", &env(&out))?;
    let task = format!("{array}_1");
    let records = out.join("shards/shard-1-of-4/ground_truth/train");
    let made_two = |_: &[String]| std::fs::read_dir(&records).map_or(0, |d| d.count()) >= 2;
    let limit = Duration::from_secs(180);
    let log = cluster.cancel_then_merge(
        &array,
        &task,
        limit,
        made_two,
        &merge,
        "rover-dataset-merge",
    )?;
    ensure!(
        log.contains("shard 1 of 4 missing") && !out.join("dataset").exists(),
        "the merge did not name shard 1 missing:\n{log}"
    );

    // Shard 1 alone goes on from its complete images; then the merge again.
    let (rerun, merge) = cluster.rerun_shard_1(&scripts, &env(&out))?;
    cluster.wait(&merge, Duration::from_secs(600))?;
    let rerun_log = cluster.log(&format!("rover-dataset-{rerun}_1.log"));
    ensure!(
        out.join("dataset/data.yaml").is_file(),
        "the merge after the re-run wrote nothing:\n{}\nre-run:\n{rerun_log}",
        cluster.log(&format!("rover-dataset-merge-{merge}.log"))
    );
    ensure!(
        rerun_log.contains("resuming"),
        "the re-run did not go on from the cancelled shard's images:\n{rerun_log}"
    );
    same_dataset(&out.join("dataset"), &one)?;
    println!(
        "re-running shard 1 alone went on from its kept images and completed the set: the same dataset ({})",
        rerun_log
            .lines()
            .find(|l| l.contains("resuming"))
            .unwrap_or_default()
    );
    Ok(())
}
