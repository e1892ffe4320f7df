//! People with MakeHuman's body (issue 46): the real MPFB2 assets from the PyPI wheel that
//! set-up fetched, posed, walking without sliding their feet, seen as people by the real
//! detector from every side, and bad asset files reported with their file and line.

use std::f64::consts::FRAC_1_SQRT_2;
use std::path::Path;

use rover_core::{RunConfig, SWEEP_DISTANCES_M, SweepPosture, sweep};
use rover_perception::{Detector, DetectorConfig};
use rover_sim::model::human::{
    BodyShape, HairStyle, Human, Layer, Legwear, Outfit, PosedBody, Posture, STANCE_FRACTION,
};
use rover_tests::{makehuman, repo};

#[test]
fn the_body_stands_its_height_with_its_feet_on_the_ground() -> anyhow::Result<()> {
    let Some(human) = makehuman()? else {
        return Ok(());
    };
    for (shape, height_m) in [
        (BodyShape::default(), 1.75),
        (
            BodyShape {
                gender: 0.0,
                age: 0.15,
                muscle: 0.3,
                weight: 0.8,
            },
            1.2,
        ),
    ] {
        let body = human.body(shape, height_m, Outfit::default())?;
        let mut posed = PosedBody::default();
        body.pose(Posture::Standing, &mut posed);
        let low = posed.positions.iter().map(|p| p.z).fold(f32::MAX, f32::min);
        let high = posed.positions.iter().map(|p| p.z).fold(f32::MIN, f32::max);
        println!(
            "{shape:?}: {} vertices, z {low:.3}..{high:.3} m",
            body.vertex_count()
        );
        assert!(low.abs() < 0.02, "feet at {low} m");
        assert!(
            (f64::from(high) - height_m).abs() < 0.03,
            "{high} m tall, asked {height_m}"
        );
        let layers: Vec<Layer> = body.layers().iter().map(|l| l.0).collect();
        for layer in [Layer::Skin, Layer::Shirt, Layer::Trousers, Layer::Hair] {
            assert!(layers.contains(&layer), "no {layer:?} in {layers:?}");
        }
        // Facing +x: the nose is the front-most point of the head.
        let head = posed
            .positions
            .iter()
            .filter(|p| p.z > 0.9 * high)
            .fold(f32::MIN, |m, p| m.max(p.x));
        assert!(head > 0.05, "the face looks along +x ({head})");
    }
    Ok(())
}

#[test]
fn outfits_cut_the_hair_and_dress_the_legs() -> anyhow::Result<()> {
    let Some(human) = makehuman()? else {
        return Ok(());
    };
    let height_m = 1.75_f32;
    let mut posed = PosedBody::default();
    // The lowest point of a layer's drawn vertices, and whether it has any vertex in a band
    // of heights near the body's middle plane (|y| < 3 cm), as fractions of the height.
    let mut look = |outfit: Outfit| -> anyhow::Result<(usize, f32, f32, bool, bool)> {
        let body = human.body(BodyShape::default(), f64::from(height_m), outfit)?;
        body.pose(Posture::Standing, &mut posed);
        let layer = |which: Layer| {
            body.layers()
                .iter()
                .find(|l| l.0 == which)
                .map(|l| l.1.clone())
                .unwrap_or_default()
        };
        let z = |i: &u32| posed.positions[*i as usize].z / height_m;
        let hair = layer(Layer::Hair);
        let hair_low = hair.iter().map(z).fold(f32::MAX, f32::min);
        let trousers = layer(Layer::Trousers);
        let legs_low = trousers.iter().map(z).fold(f32::MAX, f32::min);
        // At the shins: a long skirt spans the gap between the legs, trousers do not.
        let between_shins = trousers.iter().any(|&i| {
            let p = posed.positions[i as usize];
            (0.12..0.2).contains(&(p.z / height_m)) && p.y.abs() < 0.01
        });
        // Bare shins: skin drawn half-way between knee and ankle.
        let shins = layer(Layer::Skin)
            .iter()
            .any(|i| (0.15..0.2).contains(&z(i)));
        println!(
            "{outfit:?}: {} vertices, hair {} triangles down to {hair_low:.2} h, legwear down to \
             {legs_low:.2} h, between the shins {between_shins}, bare shins {shins}",
            body.vertex_count(),
            hair.len() / 3
        );
        Ok((hair.len(), hair_low, legs_low, between_shins, shins))
    };
    let short = look(Outfit::default())?;
    let long = look(Outfit::new(HairStyle::Long, Legwear::Trousers))?;
    let bald = look(Outfit::new(HairStyle::Bald, Legwear::Trousers))?;
    let skirt = look(Outfit::new(HairStyle::Short, Legwear::Skirt))?;
    let long_skirt = look(Outfit::new(HairStyle::Long, Legwear::LongSkirt))?;
    // Short hair ends at the jaw (~87 % of the height), long hair far below it.
    assert!(short.1 > 0.85, "short hair reaches {} h", short.1);
    assert!(long.1 < short.1 - 0.05, "long hair reaches {} h", long.1);
    assert!(long.0 > short.0, "long hair has more triangles");
    assert_eq!(bald.0, 0, "a bald head has no hair");
    // Trousers reach the shoes, one leg each, over no skin; a skirt stops below the knees
    // (~27 % of the height) over bare shins; a long skirt reaches the ankles in one piece.
    assert!(short.2 < 0.1 && !short.3 && !short.4, "trousers: {short:?}");
    assert!((0.2..0.3).contains(&skirt.2) && skirt.4, "skirt: {skirt:?}");
    assert!(
        long_skirt.2 < 0.1 && long_skirt.3,
        "long skirt: {long_skirt:?}"
    );
    Ok(())
}

#[test]
fn a_skirt_and_long_hair_are_a_person_from_every_side() -> anyhow::Result<()> {
    if makehuman()?.is_none() {
        return Ok(());
    }
    // worlds/people.toml with its person in a skirt and long hair.
    let dir = tempfile::tempdir()?;
    let world = dir.path().join("people_skirt.toml");
    let text = std::fs::read_to_string(repo("worlds/people.toml"))?
        .replace("\"../", &format!("\"{}/", repo("").display()))
        .replace(
            "body = \"makehuman\"",
            "body = \"makehuman\"\nhair_style = \"long\"\nlegwear = \"skirt\"",
        );
    std::fs::write(&world, text)?;
    found_from_every_side(world, "skirt, long hair")
}

#[test]
fn far_people_are_drawn_with_fewer_triangles_of_the_same_vertices() -> anyhow::Result<()> {
    let Some(human) = makehuman()? else {
        return Ok(());
    };
    let body = human.body(BodyShape::default(), 1.75, Outfit::default())?;
    let full: usize = body.layers().iter().map(|l| l.1.len() / 3).sum();
    let mut last = full;
    for cell_m in [0.03, 0.06] {
        let coarse = body.coarse_layers(cell_m);
        let triangles: usize = coarse.iter().map(|l| l.len() / 3).sum();
        println!("cell {cell_m} m: {triangles} of {full} triangles");
        assert!(
            triangles < last / 2,
            "{triangles} triangles at {cell_m} m, {last} before"
        );
        assert!(
            triangles > 200,
            "the coarse body keeps its shape ({triangles} triangles)"
        );
        assert_eq!(
            coarse.len(),
            body.layers().len(),
            "every layer keeps a level"
        );
        let n = body.vertex_count() as u32;
        assert!(
            coarse.iter().flatten().all(|&i| i < n),
            "indices address the posed vertices"
        );
        last = triangles;
    }
    Ok(())
}

#[test]
fn a_walking_body_keeps_its_planted_foot_still() -> anyhow::Result<()> {
    let Some(human) = makehuman()? else {
        return Ok(());
    };
    let body = human.body(BodyShape::default(), 1.75, Outfit::default())?;
    let mut posed = PosedBody::default();
    let stride_m = 1.3;
    // The left sole over the middle of its stance: the lowest vertex of the left half of the
    // body, in the world, as the body walks along +x.
    let steps = 40;
    let mut xs = Vec::new();
    for k in 0..=steps {
        let cycle = STANCE_FRACTION * (0.25 + 0.5 * k as f32 / steps as f32);
        let phase = f64::from(cycle) * std::f64::consts::TAU;
        body.pose(
            Posture::Walking {
                phase_rad: phase,
                stride_m,
            },
            &mut posed,
        );
        let sole = posed
            .positions
            .iter()
            .filter(|p| p.y > 0.03)
            .min_by(|a, b| a.z.total_cmp(&b.z))
            .copied()
            .unwrap_or_default();
        let walked_m = stride_m * phase / std::f64::consts::TAU;
        xs.push(walked_m + f64::from(sole.x));
        assert!(
            sole.z.abs() < 0.02,
            "the planted sole is on the ground: {sole}"
        );
    }
    let slide =
        xs.iter().copied().fold(f64::MIN, f64::max) - xs.iter().copied().fold(f64::MAX, f64::min);
    println!("planted foot slide over mid-stance: {:.1} mm", slide * 1e3);
    assert!(slide < 0.05, "the planted foot slid {slide} m");
    Ok(())
}

#[test]
fn makehumans_body_is_a_person_from_every_side() -> anyhow::Result<()> {
    if makehuman()?.is_none() {
        return Ok(());
    }
    found_from_every_side(repo("worlds/people.toml"), "default")
}

/// The sweep of `world`'s first person with MakeHuman's default shape, standing and a
/// quarter into the walk: every view must find them (`who` names them in the output).
fn found_from_every_side(world: std::path::PathBuf, who: &str) -> anyhow::Result<()> {
    let config = RunConfig {
        world: Some(world),
        ..RunConfig::default()
    };
    let mut detector = Detector::load(DetectorConfig::default())?;
    for posture in [SweepPosture::Standing, SweepPosture::Walking(0.25)] {
        let views = sweep(
            &config,
            &mut detector,
            Some(BodyShape::default()),
            posture,
            None,
        )?;
        let found = views.iter().filter(|v| v.found).count();
        let near = views
            .iter()
            .filter(|v| v.distance_m == SWEEP_DISTANCES_M[0] && v.found)
            .count();
        println!(
            "{who}, {posture}: {found}/{} found, {near}/8 at 1.5 m",
            views.len()
        );
        let missed: Vec<_> = views
            .iter()
            .filter(|v| !v.found)
            .map(|v| format!("{} deg {} m", v.heading_deg, v.distance_m))
            .collect();
        assert_eq!(found, views.len(), "{who}, {posture}: missed {missed:?}");
    }
    Ok(())
}

/// What loading the assets under `dir` says is wrong (empty when they load).
fn load_error(dir: &Path) -> String {
    let e = Human::load(dir)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    println!("{e}");
    e
}

fn copy_assets(to: &Path) -> anyhow::Result<()> {
    let from = rover_sim::model::human::fetch::assets_dir();
    for relative in [
        "3dobjs/base.obj",
        "rigs/standard/rig.default.json",
        "rigs/standard/weights.default.json",
    ] {
        let out = to.join(relative);
        std::fs::create_dir_all(out.parent().unwrap_or(to))?;
        std::fs::copy(from.join(relative), out)?;
    }
    Ok(())
}

#[test]
fn broken_assets_are_located_errors() -> anyhow::Result<()> {
    if makehuman()?.is_none() {
        return Ok(());
    }
    let dir = tempfile::tempdir()?;
    copy_assets(dir.path())?;
    let obj = dir.path().join("3dobjs/base.obj");
    let text = std::fs::read_to_string(&obj)?;
    // A face naming a vertex past the end, on line 40,600.
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(40_599, "f 1 2 999999");
    std::fs::write(&obj, lines.join("\n"))?;
    let e = load_error(dir.path());
    assert!(e.contains("base.obj:40600:") && e.contains("999999"), "{e}");

    copy_assets(dir.path())?;
    let rig = dir.path().join("rigs/standard/rig.default.json");
    let text = std::fs::read_to_string(&rig)?.replacen(
        "\"parent\": \"spine02\"",
        "\"parent\": \"spine99\"",
        1,
    );
    std::fs::write(&rig, text)?;
    let e = load_error(dir.path());
    assert!(
        e.contains("rig.default.json") && e.contains("spine99"),
        "{e}"
    );

    copy_assets(dir.path())?;
    let text = std::fs::read_to_string(&rig)?.replacen("\"joint-spine-1\"", "\"joint-nowhere\"", 1);
    std::fs::write(&rig, text)?;
    let e = load_error(dir.path());
    assert!(e.contains("joint-nowhere"), "{e}");

    copy_assets(dir.path())?;
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\ng body\nf 1 2 3\n")?;
    let e = load_error(dir.path());
    assert!(
        e.contains("weights.default.json") && e.contains("the mesh has 3"),
        "{e}"
    );
    Ok(())
}

#[test]
fn a_dataset_varies_bodies_clothes_and_gaits() -> anyhow::Result<()> {
    if makehuman()?.is_none() {
        return Ok(());
    }
    let dir = tempfile::tempdir()?;
    let spec = rover_core::DatasetSpec {
        out: dir.path().join("people"),
        images: 16,
        seed: 3,
        val_fraction: 0.0,
        image_format: rover_core::ImageFormat::Png,
        formats: vec![rover_core::DatasetFormat::Coco],
        randomization: rover_core::Randomization {
            background: 0.0,
            distance_m: [2.0, 4.0],
            ..rover_core::Randomization::default()
        },
        detect: false,
        shard: None,
        jobs: 1,
    };
    let config = RunConfig {
        world: Some(repo("worlds/playground.toml")),
        ..RunConfig::default()
    };
    rover_core::write_dataset(&config, &spec, &mut |_| {})?;
    let mut looks = Vec::new();
    let mut box_heights = Vec::new();
    for entry in std::fs::read_dir(spec.out.join("ground_truth/train"))? {
        let record: rover_core::ImageRecord =
            serde_json::from_str(&std::fs::read_to_string(entry?.path())?)?;
        for (person, thing) in record.shot.people.iter().zip(&record.objects) {
            looks.push(person.clone());
            if !thing.ignore {
                box_heights.push(thing.bbox[3]);
            }
        }
    }
    let count = |f: &dyn Fn(&rover_core::PersonShot) -> bool| looks.iter().filter(|p| f(p)).count();
    let children = count(&|p| p.shape.is_some_and(|s| s[1] < 0.36));
    let mid_stride = count(&|p| p.gait_phase_deg > 0.0);
    let shapes: std::collections::BTreeSet<String> = looks
        .iter()
        .filter_map(|p| p.shape.map(|s| format!("{s:?}")))
        .collect();
    let skins: std::collections::BTreeSet<String> =
        looks.iter().map(|p| format!("{:?}", p.colors[0])).collect();
    println!(
        "{} people: {} shapes, {children} children, {mid_stride} mid-stride, {} skin tones; \
         box heights {:.0}-{:.0} px",
        looks.len(),
        shapes.len(),
        skins.len(),
        box_heights.iter().copied().fold(f64::MAX, f64::min),
        box_heights.iter().copied().fold(0.0, f64::max)
    );
    assert_eq!(looks.len(), 16);
    assert_eq!(shapes.len(), 16, "every image its own body");
    assert!((1..=8).contains(&children), "{children} children");
    assert!(
        (3..=13).contains(&mid_stride),
        "{mid_stride} caught mid-stride"
    );
    assert!(skins.len() >= 4, "{} skin tones", skins.len());
    let skirts = count(&|p| p.legwear.as_deref() == Some("skirt"));
    let long_hair = count(&|p| p.hair_style.as_deref() == Some("long"));
    let bald = count(&|p| p.hair_style.as_deref() == Some("bald"));
    println!("{skirts} skirts, {long_hair} long-haired, {bald} bald");
    assert!((1..=10).contains(&skirts), "{skirts} skirts");
    assert!((1..=12).contains(&long_hair), "{long_hair} long-haired");
    Ok(())
}

/// The laser's hits within `radius_m` of `centre` (world xy), as clusters of neighbouring rays:
/// each cluster's nearest range from the sensor.
fn laser_clusters(
    sim: &rover_sim::physics::Simulation,
    laser: &mut rover_sim::sensors::LaserSensor,
    centre: [f64; 2],
    radius_m: f64,
) -> Vec<f64> {
    let world_from_sensor = laser.world_from_sensor(sim);
    let scan = laser.scan_now(sim).clone();
    let mut clusters: Vec<f64> = Vec::new();
    let mut last: Option<(usize, f32)> = None;
    for (i, &r) in scan.ranges_m.iter().enumerate() {
        if !r.is_finite() {
            continue;
        }
        let a = scan.angle_rad(i);
        let p = world_from_sensor.transform_point(glam::Vec3::new(r * a.cos(), r * a.sin(), 0.0));
        let near = (f64::from(p.x) - centre[0]).hypot(f64::from(p.y) - centre[1]) < radius_m;
        if !near {
            continue;
        }
        if std::env::var("LASER_DEBUG").is_ok() {
            println!("ray {i} angle {a:.3} range {r:.3} at {:.3} {:.3}", p.x, p.y);
        }
        match last {
            Some((j, rj)) if i == j + 1 && (r - rj).abs() < 0.08 => {
                if let Some(c) = clusters.last_mut() {
                    *c = c.min(f64::from(r));
                }
            }
            _ => clusters.push(f64::from(r)),
        }
        last = Some((i, r));
    }
    clusters
}

#[test]
fn the_laser_sees_the_legs_of_a_posed_body() -> anyhow::Result<()> {
    if makehuman()?.is_none() {
        return Ok(());
    }
    let config = RunConfig {
        world: Some(repo("worlds/people.toml")),
        robot: Some(repo("assets/robots/my_robot_laser.urdf.xacro")),
        // 1.5 m from the person, who is 45 degrees to the left (not where the scan wraps).
        spawn: Some([-1.5 * FRAC_1_SQRT_2, -1.5 * FRAC_1_SQRT_2, 0.0]),
        ..RunConfig::default()
    };
    let mut report = Vec::new();
    // Side on (facing across the line of sight), at the left foot's touch-down: two legs a
    // stride apart; standing: the legs together.
    for (heading_deg, phase_rad, want) in [(135.0f64, 0.01, 2), (135.0, 0.0, 1)] {
        let (mut world, robot) = config.load_world_and_robot()?;
        world.people[0].heading_rad = heading_deg.to_radians();
        world.people[0].still_gait_phase_rad = phase_rad;
        let sim = rover_sim::physics::Simulation::new(world, robot, &config.options)?;
        let mut laser = rover_sim::sensors::LaserSensor::new(&sim, 0)?;
        let clusters = laser_clusters(&sim, &mut laser, [0.0, 0.0], 0.6);
        report.push(format!(
            "phase {phase_rad:.2} rad: {} cluster(s) {clusters:.2?}",
            clusters.len()
        ));
        assert_eq!(clusters.len(), want, "{report:?}");
        // The shins, a stride apart: hits from 1.3 to 1.7 m (the sensor is 1.5 m from the
        // person's centre line; the old capsule's surface was at 1.37 m from every side).
        assert!(
            clusters.iter().all(|r| (1.3..1.7).contains(r)),
            "{report:?}"
        );
    }
    println!("{}", report.join("; "));
    Ok(())
}
