//! `rover dataset` as users run it: the real binary, renderer and ground truth. Formats
//! (every YOLO line valid, COCO JSON loaded by pycocotools, YOLO and COCO boxes agreeing),
//! determinism (two runs, one seed: identical files), resuming, refusals, a full disk, and
//! COCO parity: pycocotools' COCOeval on the exported dataset and the detector's exported
//! results gives rover's AP50 and AP50:95.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use anyhow::{Context, Result, ensure};

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn rover(args: &[&str]) -> Result<Output> {
    Ok(Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()?)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn dataset(out: &Path, images: u32, seed: u32, extra: &[&str]) -> Result<Output> {
    let world = repo("worlds/playground.toml").display().to_string();
    let (images, seed, out) = (
        images.to_string(),
        seed.to_string(),
        out.display().to_string(),
    );
    let mut args = vec![
        "dataset", "--world", &world, "--out", &out, "--images", &images, "--seed", &seed, "--val",
        "0.25",
    ];
    args.extend_from_slice(extra);
    rover(&args)
}

fn hashes(dir: &Path) -> Result<BTreeMap<String, String>> {
    rover_tests::file_hashes(dir)
}

fn has_pycocotools() -> bool {
    Command::new("python3")
        .args(["-c", "import numpy, pycocotools.cocoeval"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Checks every YOLO label line and that it matches the COCO annotation of the same thing
/// within 0.5 px. Returns how many boxes were compared.
fn check_formats(dir: &Path) -> Result<usize> {
    let mut compared = 0;
    for split in ["train", "val"] {
        let coco: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(
            dir.join(format!("annotations/instances_{split}.json")),
        )?)?;
        let categories: BTreeMap<u64, String> = coco["categories"]
            .as_array()
            .context("categories")?
            .iter()
            .map(|c| {
                (
                    c["id"].as_u64().unwrap_or(0),
                    c["name"].as_str().unwrap_or("").to_owned(),
                )
            })
            .collect();
        ensure!(categories.len() == 80, "{} categories", categories.len());
        for image in coco["images"].as_array().context("images")? {
            let id = image["id"].as_u64().context("image id")?;
            let file = image["file_name"].as_str().context("file_name")?;
            let (w, h) = (
                image["width"].as_f64().unwrap_or(0.0),
                image["height"].as_f64().unwrap_or(0.0),
            );
            let picture = image::open(dir.join("images").join(split).join(file))?;
            ensure!(
                (picture.width(), picture.height()) == (w as u32, h as u32),
                "{file}: size"
            );
            let stem = file.trim_end_matches(".png");
            let label = std::fs::read_to_string(dir.join(format!("labels/{split}/{stem}.txt")))?;
            let lines: Vec<Vec<f64>> = label
                .lines()
                .map(|l| {
                    let fields: Vec<&str> = l.split(' ').collect();
                    ensure!(
                        fields.len() == 5,
                        "{stem}.txt: '{l}' has {} fields",
                        fields.len()
                    );
                    let class: usize = fields[0]
                        .parse()
                        .with_context(|| format!("class in '{l}'"))?;
                    ensure!(class < 80, "{stem}.txt: class {class}");
                    let v: Vec<f64> = fields
                        .iter()
                        .map(|f| f.parse::<f64>())
                        .collect::<Result<_, _>>()?;
                    ensure!(
                        v[1..].iter().all(|x| (0.0..=1.0).contains(x)),
                        "{stem}.txt: '{l}' outside 0..1"
                    );
                    ensure!(v[3] > 0.0 && v[4] > 0.0, "{stem}.txt: empty box '{l}'");
                    Ok(v)
                })
                .collect::<Result<_>>()?;
            let crowd_free: Vec<&serde_json::Value> = coco["annotations"]
                .as_array()
                .context("annotations")?
                .iter()
                .filter(|a| a["image_id"].as_u64() == Some(id) && a["iscrowd"] == 0)
                .collect();
            ensure!(
                lines.len() == crowd_free.len(),
                "{stem}: {} YOLO lines, {} COCO boxes",
                lines.len(),
                crowd_free.len()
            );
            for (line, a) in lines.iter().zip(crowd_free) {
                let b: Vec<f64> = a["bbox"]
                    .as_array()
                    .context("bbox")?
                    .iter()
                    .filter_map(|v| v.as_f64())
                    .collect();
                let name = &categories[&a["category_id"].as_u64().context("category")?];
                ensure!(
                    rover_assets::COCO80[line[0] as usize] == name,
                    "{stem}: class {} vs {name}",
                    line[0]
                );
                let yolo = [
                    (line[1] - line[3] / 2.0) * w,
                    (line[2] - line[4] / 2.0) * h,
                    line[3] * w,
                    line[4] * h,
                ];
                for k in 0..4 {
                    ensure!(
                        (yolo[k] - b[k]).abs() <= 0.5,
                        "{stem}: YOLO {yolo:?} vs COCO {b:?}"
                    );
                }
                compared += 1;
            }
        }
    }
    Ok(compared)
}

#[test]
fn a_dataset_is_valid_yolo_and_coco_and_the_same_twice() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let out = dataset(&a, 12, 5, &["--jobs", "1"])?;
    let stdout = text(&out.stdout);
    ensure!(out.status.success(), "{stdout}{}", text(&out.stderr));
    assert!(stdout.contains("12 images (12 made now"), "{stdout}");
    let yaml = std::fs::read_to_string(a.join("data.yaml"))?;
    assert!(
        yaml.contains("train: images/train\nval: images/val\nnc: 80\n"),
        "{yaml}"
    );
    assert!(
        yaml.contains("  0: person\n") && yaml.contains("  79: toothbrush\n"),
        "{yaml}"
    );
    let compared = check_formats(&a)?;
    assert!(compared >= 6, "only {compared} labelled boxes in 12 images");
    println!("{stdout}{compared} boxes agree between YOLO and COCO within 0.5 px");

    // The second run makes its images three at a time: the files must not depend on it.
    let out = dataset(&b, 12, 5, &["--jobs", "3"])?;
    ensure!(out.status.success(), "{}", text(&out.stderr));
    let (ha, hb) = (hashes(&a)?, hashes(&b)?);
    assert_eq!(ha.keys().collect::<Vec<_>>(), hb.keys().collect::<Vec<_>>());
    let differing: Vec<&String> = ha.keys().filter(|k| ha[*k] != hb[*k]).collect();
    assert!(
        differing.is_empty(),
        "differ between two runs with one seed: {differing:?}"
    );
    println!(
        "two runs with seed 5 (--jobs 1 and 3): {} files, sha256-identical (images, labels, COCO JSON, records)",
        ha.len()
    );
    assert!(
        ha.keys().all(|k| !k.ends_with(".tmp")),
        "temporaries left: {ha:?}"
    );

    if has_pycocotools() {
        let script = "import sys\nfrom pycocotools.coco import COCO\nfor s in ('train', 'val'):\n    c = COCO(sys.argv[1] + f'/annotations/instances_{s}.json')\n    print(s, len(c.getImgIds()), len(c.getAnnIds()))\n";
        let out = Command::new("python3")
            .args(["-c", script])
            .arg(&a)
            .output()?;
        ensure!(out.status.success(), "COCO() failed: {}", text(&out.stderr));
        println!("pycocotools COCO() loads: {}", text(&out.stdout));
    } else {
        rover_tests::skip(
            "the COCO() part: python3 cannot import pycocotools (./test installs it)",
        )?;
    }
    Ok(())
}

#[test]
fn a_stopped_dataset_resumes_to_the_same_files_and_another_run_is_refused() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let dir = tmp.path().join("d");
    let out = dataset(&dir, 6, 9, &["--format", "yolo"])?;
    ensure!(out.status.success(), "{}", text(&out.stderr));
    let before = hashes(&dir)?;
    // As a run stopped mid-way leaves it: one image without its record, one record without its
    // image, a temporary file.
    let find = |name: &str| before.keys().find(|k| k.contains(name)).cloned();
    let record = find("ground_truth/").context("a record")?;
    let stem = Path::new(&record)
        .file_stem()
        .context("stem")?
        .to_string_lossy()
        .into_owned();
    std::fs::remove_file(dir.join(&record))?;
    let other = before
        .keys()
        .find(|k| k.starts_with("images/") && !k.contains(&stem))
        .cloned()
        .context("another image")?;
    std::fs::remove_file(dir.join(&other))?;
    std::fs::write(dir.join("images/train/.rover-000001.png.tmp"), b"half")?;
    let out = dataset(&dir, 6, 9, &["--format", "yolo"])?;
    let stdout = text(&out.stdout);
    ensure!(out.status.success(), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("4 of 6 images already complete"),
        "{stdout}"
    );
    assert!(stdout.contains("2 made now"), "{stdout}");
    let after = hashes(&dir)?;
    assert_eq!(before, after, "the resumed dataset differs from the first");

    // Growing it is a resume too; another seed or format is refused, naming the difference.
    let out = dataset(&dir, 8, 9, &["--format", "yolo"])?;
    ensure!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("6 of 8 images already complete"),
        "{}",
        text(&out.stdout)
    );
    let out = dataset(&dir, 8, 10, &["--format", "yolo"])?;
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("holds another dataset") && stderr.contains("seed: 9 (folder) vs 10 (now)"),
        "{stderr}"
    );
    let out = dataset(&dir, 4, 9, &["--format", "yolo"])?;
    assert!(
        text(&out.stderr).contains("holds a dataset of 8 images"),
        "{}",
        text(&out.stderr)
    );
    let full = tmp.path().join("full");
    std::fs::create_dir(&full)?;
    std::fs::write(full.join("notes.txt"), "mine")?;
    let out = dataset(&full, 2, 9, &[])?;
    assert!(
        text(&out.stderr).contains("is not empty, and has no rover-dataset.json"),
        "{}",
        text(&out.stderr)
    );
    let out = rover(&["dataset", "--out", "/tmp/x", "--distance", "5,1"])?;
    assert!(
        text(&out.stderr).contains("MIN,MAX with 0 < MIN <= MAX"),
        "{}",
        text(&out.stderr)
    );
    Ok(())
}

/// A small tmpfs fills up mid-dataset: the run stops with a clear message, every image it
/// counts is complete, no temporary is left; with room again the same command finishes.
/// Needs root (mount); skips saying why otherwise.
#[test]
fn a_full_disk_stops_the_dataset_cleanly_and_it_resumes() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let mount = tmp.path().join("small");
    std::fs::create_dir(&mount)?;
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=2m", "tmpfs"])
        .arg(&mount)
        .output();
    if !mounted.as_ref().is_ok_and(|o| o.status.success()) {
        return rover_tests::skip(format!(
            "cannot mount a small tmpfs here (needs root): {mounted:?}"
        ));
    }
    let result = (|| -> Result<()> {
        let dir = mount.join("d");
        let out = dataset(&dir, 16, 3, &[])?;
        let stderr = text(&out.stderr);
        assert!(!out.status.success(), "a 2 MB disk held 16 images?");
        assert!(
            stderr.contains("no space left on the device; stopped with"),
            "{stderr}"
        );
        let files = hashes(&dir)?;
        assert!(
            files.keys().all(|k| !k.ends_with(".tmp")),
            "temporaries left: {files:?}"
        );
        let records: Vec<&String> = files
            .keys()
            .filter(|k| k.starts_with("ground_truth/"))
            .collect();
        assert!(
            !records.is_empty() && records.len() < 16,
            "{} records",
            records.len()
        );
        for r in &records {
            let split_stem = r
                .trim_start_matches("ground_truth/")
                .trim_end_matches(".json");
            assert!(
                files.contains_key(&format!("images/{split_stem}.png")),
                "{r} without its image"
            );
            assert!(
                files.contains_key(&format!("labels/{split_stem}.txt")),
                "{r} without its label"
            );
        }
        println!(
            "stopped with {} complete images: {}",
            records.len(),
            stderr.trim()
        );
        let grown = Command::new("mount")
            .args(["-o", "remount,size=64m"])
            .arg(&mount)
            .status()?;
        ensure!(grown.success(), "remount failed");
        let out = dataset(&dir, 16, 3, &[])?;
        ensure!(out.status.success(), "{}", text(&out.stderr));
        let again = text(&out.stdout);
        assert!(
            again.contains(&format!("{} of 16 images already complete", records.len())),
            "{again}"
        );
        let tmp2 = tempfile::tempdir()?;
        let out = dataset(&tmp2.path().join("d"), 16, 3, &[])?;
        ensure!(out.status.success(), "{}", text(&out.stderr));
        let (resumed, whole) = (hashes(&dir)?, hashes(&tmp2.path().join("d"))?);
        let labels = |h: &BTreeMap<String, String>| -> Vec<(String, String)> {
            h.iter()
                .filter(|(k, _)| k.starts_with("labels/") || k.starts_with("annotations/"))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect()
        };
        assert_eq!(
            labels(&resumed),
            labels(&whole),
            "labels after a full disk and a resume differ from one run's"
        );
        Ok(())
    })();
    let _ = Command::new("umount").arg(&mount).status();
    result
}

/// pycocotools' COCOeval on rover's own export — a real world's dataset (osrf's textured
/// street models with Gazebo's sun, or without ../shared the playground's people), the
/// detector's results exported by `--detect` — gives rover's AP50 and AP50:95 within 1e-3.
#[test]
fn pycocotools_on_the_exported_dataset_gives_rovers_detector_metrics() -> Result<()> {
    if !has_pycocotools() {
        return rover_tests::skip(
            "python3 cannot import pycocotools and numpy (./test installs them)",
        );
    }
    let tmp = tempfile::tempdir()?;
    let mut runs = vec![(
        "playground",
        repo("worlds/playground.toml"),
        Vec::<String>::new(),
    )];
    if let Some(models) = rover_tests::shared("corpus/gazebo_models") {
        let world = tmp.path().join("street.world");
        std::fs::write(&world, rover_tests::STREET_WORLD)?;
        runs.push((
            "street",
            world,
            vec!["--model-path".into(), models.display().to_string()],
        ));
    }
    for (name, world, extra) in runs {
        let dir = tmp.path().join(name);
        let (w, d) = (world.display().to_string(), dir.display().to_string());
        let mut args = vec![
            "dataset",
            "--world",
            &w,
            "--out",
            &d,
            "--images",
            "16",
            "--seed",
            "2",
            "--val",
            "0.5",
            "--detect",
            "--distance",
            "3,9",
        ];
        args.extend(extra.iter().map(String::as_str));
        let out = rover(&args)?;
        let stdout = text(&out.stdout);
        ensure!(out.status.success(), "{stdout}{}", text(&out.stderr));
        println!("{name}:\n{stdout}");
        let metrics: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json"))?)?;
        let mut compared = Vec::new();
        for split in ["train", "val"] {
            let script = "import sys, json, io, contextlib\nfrom pycocotools.coco import COCO\nfrom pycocotools.cocoeval import COCOeval\nstats = None\nwith contextlib.redirect_stdout(io.StringIO()):\n    gt = COCO(sys.argv[1])\n    dets = json.load(open(sys.argv[2]))\n    if dets:\n        e = COCOeval(gt, gt.loadRes(dets), 'bbox'); e.evaluate(); e.accumulate(); e.summarize()\n        stats = [e.stats[0], e.stats[1]]\nprint(json.dumps(stats))\n";
            let out = Command::new("python3")
                .args(["-c", script])
                .arg(dir.join(format!("annotations/instances_{split}.json")))
                .arg(dir.join(format!("detections/{split}.json")))
                .output()?;
            ensure!(out.status.success(), "pycocotools: {}", text(&out.stderr));
            let theirs: serde_json::Value = serde_json::from_str(text(&out.stdout).trim())?;
            let ours = &metrics[split];
            // Both sides agree on whether the split has anything to score.
            ensure!(
                theirs.as_array().is_some() == ours["ap50_95"].as_f64().is_some(),
                "{name} {split}: one side scored the split and the other did not: rover {ours}, pycocotools {theirs}"
            );
            let (Some(t), Some(ap), Some(ap50)) = (
                theirs.as_array(),
                ours["ap50_95"].as_f64(),
                ours["ap50"].as_f64(),
            ) else {
                println!(
                    "{name} {split}: no ground truth or detections to score (rover {ours}, pycocotools {theirs})"
                );
                continue;
            };
            compared.push(split);
            let (t_ap, t_ap50) = (
                t[0].as_f64().unwrap_or(f64::NAN),
                t[1].as_f64().unwrap_or(f64::NAN),
            );
            println!(
                "{name} {split}: AP50:95 rover {ap:.6} pycocotools {t_ap:.6}; AP50 rover {ap50:.6} pycocotools {t_ap50:.6}"
            );
            assert!(
                (ap - t_ap).abs() <= 1e-3 && (ap50 - t_ap50).abs() <= 1e-3,
                "{name} {split}: rover {ap} / {ap50} vs pycocotools {t_ap} / {t_ap50}"
            );
        }
        ensure!(
            !compared.is_empty(),
            "{name}: no split had scores to compare (rover {metrics})"
        );
        println!("{name}: compared {compared:?}");
    }
    Ok(())
}

/// `--shard I/N` and `--merge` without a cluster (app/tests/slurm.rs runs them on Slurm): three
/// shards merged equal a one-machine run file for file; a missing shard, an unfinished one and
/// a shard of another seed are refused with what is wrong; merging twice changes nothing.
#[test]
fn shards_merge_into_the_one_machine_dataset_and_a_broken_set_is_refused() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let (one, shards) = (tmp.path().join("one"), tmp.path().join("shards"));
    let out = dataset(&one, 10, 3, &[])?;
    ensure!(out.status.success(), "{}", text(&out.stderr));
    for i in 0..3 {
        let shard = format!("{i}/3");
        let out = dataset(&shards, 10, 3, &["--shard", &shard, "--jobs", "1"])?;
        ensure!(out.status.success(), "{}", text(&out.stderr));
        let made = text(&out.stdout);
        let owned = (0..10).filter(|n| n % 3 == i).count();
        ensure!(
            made.contains(&format!("{owned} images ({owned} made now")),
            "shard {shard}: {made}"
        );
    }
    let dir = |i: u32| shards.join(format!("shard-{i}-of-3")).display().to_string();
    let merged = tmp.path().join("merged").display().to_string();
    let merge = |dirs: &[String], out: &str| {
        let mut args = vec!["dataset", "--out", out, "--merge"];
        args.extend(dirs.iter().map(String::as_str));
        rover(&args)
    };

    let out = merge(&[dir(0), dir(2)], &merged)?;
    let error = text(&out.stderr);
    ensure!(
        !out.status.success() && error.contains("shard 1 of 3 missing"),
        "{error}"
    );
    std::fs::rename(
        Path::new(&dir(1)).join("rover-shard.json"),
        tmp.path().join("kept.json"),
    )?;
    let out = merge(&[dir(0), dir(1), dir(2)], &merged)?;
    let error = text(&out.stderr);
    ensure!(
        !out.status.success()
            && error.contains("shard 1 of 3 missing")
            && error.contains("shard 1 of 3 did not finish"),
        "{error}"
    );
    std::fs::rename(
        tmp.path().join("kept.json"),
        Path::new(&dir(1)).join("rover-shard.json"),
    )?;
    let other = tmp.path().join("other");
    let out = dataset(&other, 10, 4, &["--shard", "1/3"])?;
    ensure!(out.status.success(), "{}", text(&out.stderr));
    let out = merge(
        &[
            dir(0),
            other.join("shard-1-of-3").display().to_string(),
            dir(2),
        ],
        &merged,
    )?;
    let error = text(&out.stderr);
    ensure!(
        !out.status.success() && error.contains("seed: Some(3) vs Some(4)"),
        "{error}"
    );
    ensure!(!Path::new(&merged).exists(), "a refused merge wrote files");

    for round in 0..2 {
        let out = merge(&[dir(2), dir(0), dir(1)], &merged)?;
        ensure!(out.status.success(), "{}", text(&out.stderr));
        let (a, b) = (hashes(Path::new(&merged))?, hashes(&one)?);
        ensure!(
            a == b,
            "merge {round}: differs from the one-machine run: {:?}",
            a.keys()
                .filter(|k| a.get(*k) != b.get(*k))
                .collect::<Vec<_>>()
        );
        println!(
            "merge {round}: {} files equal to the one-machine run's",
            a.len()
        );
    }
    Ok(())
}
