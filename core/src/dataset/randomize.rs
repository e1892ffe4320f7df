//! Laying out one randomized scene per image: where the robot (and so its camera) stands,
//! where the labelled things stand and which way they face, what people wear, where the sun
//! is and how strong, how noisy the camera is. Image `i` depends only on the seed and `i`
//! (its own random stream), so images can be made in any order, resumed or sharded.

use std::f64::consts::PI;

use glam::{Quat, Vec3};
use rover_sim::{
    SplitMix64,
    geometry::{Pose, Rgba, Shape, pose_from_position_yaw},
    model::{GaussianNoise, World},
    physics::Simulation,
    render::Light,
};
use serde::{Deserialize, Serialize};

/// What is randomized, and how much. Saved in the dataset's manifest: resuming needs the same.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Randomization {
    /// Place the robot (its camera) anew for every image: facing a labelled thing from a
    /// distance in `distance_m` (or anywhere, for background images).
    pub robot: bool,
    /// Distances from the robot to the thing it faces (m): min, max.
    pub distance_m: [f64; 2],
    /// Fraction of images with the robot placed anywhere, facing anywhere (background images,
    /// most with nothing labelled in view).
    pub background: f64,
    /// Move people and labelled objects and models by up to this much in x and y (m).
    pub move_m: f64,
    /// Turn labelled objects and models by up to this much about z (deg); people face any way.
    pub turn_deg: f64,
    /// Dress people in random shirt and trousers colours.
    pub clothes: bool,
    /// Give people other bodies (MakeHuman's shape sliders: gender, age — children too —,
    /// muscle and weight; height), skin tones and hair colours, and catch half of them
    /// mid-stride at any phase of the walk.
    #[serde(default)]
    pub bodies: bool,
    /// Put the sun anywhere 20-80 degrees above the horizon, vary its and the sky's strength.
    pub light: bool,
    /// Gaussian noise with a standard deviation drawn from 0 up to this (0..1 of full scale; 0:
    /// the camera's own `<noise>`).
    pub noise_max: f64,
}

impl Default for Randomization {
    fn default() -> Self {
        Self {
            robot: true,
            distance_m: [1.5, 8.0],
            background: 0.05,
            move_m: 0.5,
            turn_deg: 180.0,
            clothes: true,
            bodies: true,
            light: true,
            noise_max: 0.02,
        }
    }
}

impl Randomization {
    /// Checks the ranges; the error says what was expected.
    pub fn check(&self) -> Result<(), String> {
        let [near, far] = self.distance_m;
        if !(near.is_finite() && far.is_finite() && 0.0 < near && near <= far && far <= 1e3) {
            return Err(format!(
                "distances must be MIN,MAX with 0 < MIN <= MAX <= 1000 m, found {near},{far}"
            ));
        }
        let checks = [
            ("background fraction", self.background, 1.0),
            ("move", self.move_m, 100.0),
            ("turn", self.turn_deg, 180.0),
            ("noise", self.noise_max, 1.0),
        ];
        for (what, value, max) in checks {
            if !(value.is_finite() && (0.0..=max).contains(&value)) {
                return Err(format!("{what} must be between 0 and {max}, found {value}"));
            }
        }
        Ok(())
    }
}

/// Image `index`'s random stream: rover's own SplitMix64 ([`SplitMix64`], fixed forever: a
/// dataset's images and labels must not change with a random-number crate's next version, or
/// resumed datasets would mix two streams).
#[derive(Debug, Clone)]
pub(crate) struct Rng(SplitMix64);

impl Rng {
    /// The stream of image `index` of a dataset seeded with `seed`.
    pub(crate) fn for_image(seed: u64, index: u64) -> Self {
        let mut mix = SplitMix64(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
        let first = mix.next_u64();
        Self(SplitMix64(first ^ index))
    }

    /// Uniform in [0, 1).
    pub(crate) fn uniform(&mut self) -> f64 {
        self.0.unit()
    }

    /// Uniform in [lo, hi).
    pub(crate) fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }

    fn color(&mut self) -> Rgba {
        let mut c = || self.between(0.04, 0.95) as f32;
        Rgba::rgb(c(), c(), c())
    }
}

/// Skin tones, light to dark (sRGB), people's skin is drawn from.
const SKIN_TONES: [[f32; 3]; 6] = [
    [0.96, 0.80, 0.69],
    [0.89, 0.70, 0.56],
    [0.78, 0.57, 0.42],
    [0.63, 0.43, 0.29],
    [0.45, 0.29, 0.19],
    [0.29, 0.18, 0.12],
];
/// Hair colours: black, dark brown, brown, blond, red, grey.
const HAIR_COLORS: [[f32; 3]; 6] = [
    [0.05, 0.04, 0.04],
    [0.18, 0.11, 0.07],
    [0.36, 0.22, 0.12],
    [0.78, 0.64, 0.40],
    [0.55, 0.22, 0.09],
    [0.62, 0.62, 0.60],
];
/// Fraction of people drawn as children (MakeHuman's age 0.19-0.35, 1.1-1.5 m).
const CHILD_FRACTION: f64 = 0.2;
/// Hair styles and how often each is drawn.
const HAIR_STYLES: [(rover_sim::model::human::HairStyle, f64); 3] = [
    (rover_sim::model::human::HairStyle::Short, 0.5),
    (rover_sim::model::human::HairStyle::Long, 0.35),
    (rover_sim::model::human::HairStyle::Bald, 0.15),
];
/// Fraction of people drawn in a skirt (knee-length or long, one as often as the other).
const SKIRT_FRACTION: f64 = 0.3;

/// A person's random look: MakeHuman's body in a random shape and height (a person drawn as
/// rover's figure or an actor's skin keeps it), a skin tone, a hair colour and style,
/// trousers or a skirt, and half of them mid-stride.
fn random_look(person: &rover_sim::model::Person, rng: &mut Rng) -> rover_sim::physics::PersonLook {
    let child = rng.uniform() < CHILD_FRACTION;
    let (age, height_m) = if child {
        (rng.between(0.19, 0.35), rng.between(1.1, 1.5))
    } else {
        (rng.between(0.4, 0.9), rng.between(1.55, 1.95))
    };
    let shape = rover_sim::model::human::BodyShape {
        gender: rng.uniform() as f32,
        age: age as f32,
        muscle: rng.between(0.2, 0.8) as f32,
        weight: rng.between(0.1, 0.9) as f32,
    };
    let pick = |palette: &[[f32; 3]; 6], rng: &mut Rng| {
        let [r, g, b] = palette[rng.below(palette.len())];
        Rgba::rgb(r, g, b)
    };
    let skin_color = pick(&SKIN_TONES, rng);
    let hair_color = pick(&HAIR_COLORS, rng);
    let still_gait_phase_rad = if rng.uniform() < 0.5 {
        0.0
    } else {
        rng.between(0.01, 2.0 * PI)
    };
    let mut style_draw = rng.uniform();
    let hair = HAIR_STYLES
        .iter()
        .find(|(_, share)| {
            style_draw -= share;
            style_draw < 0.0
        })
        .map_or(rover_sim::model::human::HairStyle::Short, |(h, _)| *h);
    let legwear = match rng.uniform() {
        u if u < SKIRT_FRACTION / 2.0 => rover_sim::model::human::Legwear::Skirt,
        u if u < SKIRT_FRACTION => rover_sim::model::human::Legwear::LongSkirt,
        _ => rover_sim::model::human::Legwear::Trousers,
    };
    rover_sim::physics::PersonLook {
        shape: person.shape.map(|_| shape),
        outfit: rover_sim::model::human::Outfit::new(hair, legwear),
        height_m: if person.shape.is_some() {
            height_m
        } else {
            person.height_m
        },
        skin_color,
        hair_color,
        still_gait_phase_rad,
    }
}

/// Where things start (the world as loaded), so every image is laid out from the same base.
#[derive(Debug, Clone)]
pub(crate) struct BaseLayout {
    people: Vec<([f64; 2], f64)>,
    /// Labelled objects: index, position, yaw.
    objects: Vec<(usize, [f64; 3], f64)>,
    /// Labelled models: index, pose.
    models: Vec<(usize, Pose)>,
    /// Footprints the robot must not stand in: centre (x, y) and radius (m), every object,
    /// model and person as laid out.
    robot_base: Pose,
    sun_direction: [f64; 3],
}

impl BaseLayout {
    pub(crate) fn new(sim: &Simulation) -> Self {
        let world = sim.world();
        Self {
            people: world
                .people
                .iter()
                .map(|p| (p.position_m, p.heading_rad))
                .collect(),
            objects: world
                .objects
                .iter()
                .enumerate()
                .filter(|(_, o)| o.class.is_some())
                .map(|(i, o)| (i, o.position_m, o.yaw_rad))
                .collect(),
            models: world
                .models
                .iter()
                .enumerate()
                .filter(|(_, m)| m.class.is_some())
                .map(|(i, m)| (i, m.world_from_model))
                .collect(),
            robot_base: sim.world_from_base(),
            sun_direction: world.sun_direction,
        }
    }

    /// How many labelled things there are to face.
    pub(crate) fn targets(&self) -> usize {
        self.people.len() + self.objects.len() + self.models.len()
    }
}

/// What one image's layout came out as (saved with its labels).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Shot {
    /// The robot's base: x, y (m), yaw (deg).
    pub robot: [f64; 3],
    /// The labelled thing the robot faces (its name); `None`: a background image.
    pub facing: Option<String>,
    /// Direction the sunlight travels (world frame, unit).
    pub sun_direction: [f64; 3],
    /// The sun's strength.
    pub sun: f64,
    /// The sky's strength (multiple of rover's default).
    pub ambient: f64,
    /// Gaussian noise standard deviation (0..1 of full scale; `None`: the camera's own).
    pub noise_stddev: Option<f64>,
    /// How each person looked (world order).
    #[serde(default)]
    pub people: Vec<PersonShot>,
}

/// How one person looked in an image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PersonShot {
    /// Their name in the world.
    pub name: String,
    /// MakeHuman's sliders (gender, age, muscle, weight; 0..1), `None` for rover's figure or
    /// an actor's skin.
    pub shape: Option<[f32; 4]>,
    /// Standing height (m).
    pub height_m: f64,
    /// Where in the gait cycle they were caught (deg; 0: standing).
    pub gait_phase_deg: f64,
    /// Skin, hair, shirt and trousers colours (sRGB, 0..1).
    pub colors: [[f32; 3]; 4],
    /// MakeHuman's hair style (`short`, `long`, `bald`), `None` for rover's figure or an
    /// actor's skin.
    #[serde(default)]
    pub hair_style: Option<String>,
    /// Trousers or a skirt, as `hair_style`.
    #[serde(default)]
    pub legwear: Option<String>,
}

impl PersonShot {
    fn of(person: &rover_sim::model::Person) -> Self {
        let rgb = |c: Rgba| [c.0[0], c.0[1], c.0[2]];
        Self {
            name: person.name.clone(),
            shape: person.shape.map(|s| [s.gender, s.age, s.muscle, s.weight]),
            height_m: person.height_m,
            gait_phase_deg: person.gait_phase_rad(0.0).to_degrees(),
            colors: [
                rgb(person.skin_color),
                rgb(person.hair_color),
                rgb(person.shirt_color),
                rgb(person.trousers_color),
            ],
            hair_style: person.shape.map(|_| person.outfit.hair.as_str().to_owned()),
            legwear: person
                .shape
                .map(|_| person.outfit.legwear.as_str().to_owned()),
        }
    }
}

/// Lays out image `rng`'s scene in `sim` and `camera`. Returns what it did.
pub(crate) fn lay_out(
    sim: &mut Simulation,
    camera: &mut rover_sim::sensors::CameraSensor,
    base: &BaseLayout,
    how: &Randomization,
    rng: &mut Rng,
) -> rover_sim::Result<Shot> {
    // Things first (the robot faces where they now are).
    let mut spots: Vec<(String, [f64; 2])> = Vec::with_capacity(base.targets());
    for (i, &(position, heading)) in base.people.iter().enumerate() {
        let (position, heading) = if how.move_m > 0.0 {
            let m = how.move_m;
            let p = [
                position[0] + rng.between(-m, m),
                position[1] + rng.between(-m, m),
            ];
            (p, rng.between(-PI, PI))
        } else {
            (position, heading)
        };
        sim.place_person(i, position, heading)?;
        if how.clothes {
            let (shirt, trousers) = (rng.color(), rng.color());
            sim.dress_person(i, shirt, trousers)?;
        }
        if how.bodies {
            let look = random_look(&sim.world().people[i], rng);
            sim.restyle_person(i, &look)?;
        }
        spots.push((sim.world().people[i].name.clone(), position));
    }
    let turn = how.turn_deg.to_radians();
    for &(i, position, yaw) in &base.objects {
        let m = how.move_m;
        let p = [
            position[0] + rng.between(-m, m),
            position[1] + rng.between(-m, m),
            position[2],
        ];
        sim.place_object(i, p, yaw + rng.between(-turn, turn))?;
        spots.push((sim.world().objects[i].name.clone(), [p[0], p[1]]));
    }
    for &(i, pose) in &base.models {
        let m = how.move_m as f32;
        let (dx, dy) = (
            rng.between(-f64::from(m), f64::from(m)) as f32,
            rng.between(-f64::from(m), f64::from(m)) as f32,
        );
        let dyaw = rng.between(-turn, turn) as f32;
        let moved = Pose::from_parts(
            pose.translation + Vec3::new(dx, dy, 0.0),
            Quat::from_rotation_z(dyaw) * pose.rotation,
        );
        sim.place_model(i, moved)?;
        let t = moved.translation;
        spots.push((
            sim.world().models[i].name.clone(),
            [f64::from(t.x), f64::from(t.y)],
        ));
    }
    let (robot, facing) = place_robot(sim, base, how, rng, &spots)?;
    let mut shot = Shot {
        robot,
        facing,
        sun_direction: base.sun_direction,
        sun: f64::from(Light::default().sun),
        ambient: f64::from(Light::default().ambient),
        noise_stddev: None,
        people: sim.world().people.iter().map(PersonShot::of).collect(),
    };
    if how.light {
        let azimuth = rng.between(-PI, PI);
        let elevation = rng.between(20f64.to_radians(), 80f64.to_radians());
        shot.sun_direction = [
            -elevation.cos() * azimuth.cos(),
            -elevation.cos() * azimuth.sin(),
            -elevation.sin(),
        ];
        shot.sun = rng.between(0.45, 0.95);
        shot.ambient = rng.between(0.7, 1.2);
    }
    camera.set_light(
        shot.sun_direction,
        Light {
            sun: shot.sun as f32,
            ambient: shot.ambient as f32,
        },
    );
    if how.noise_max > 0.0 {
        let stddev = rng.between(0.0, how.noise_max);
        shot.noise_stddev = Some(stddev);
        camera.set_noise(Some(GaussianNoise { mean: 0.0, stddev }));
    }
    Ok(shot)
}

/// How close the robot's base may stand to anything's centre: its own reach plus the thing's.
fn footprints(world: &World) -> Vec<([f64; 2], f64)> {
    let mut out = Vec::new();
    for o in &world.objects {
        let r = match &o.shape {
            Shape::Box { size_m } => 0.5 * f64::from(size_m.x.hypot(size_m.y)),
            Shape::Cylinder { radius_m, .. }
            | Shape::Sphere { radius_m }
            | Shape::Capsule { radius_m, .. } => f64::from(*radius_m),
            Shape::Mesh { .. } => 0.5,
        };
        out.push(([o.position_m[0], o.position_m[1]], r));
    }
    for p in &world.people {
        out.push((p.position_m, p.body_radius_m()));
    }
    for m in &world.models {
        let t = m.world_from_model.translation;
        out.push(([f64::from(t.x), f64::from(t.y)], 0.5));
    }
    out
}

/// The robot's base stands this far clear of every footprint (m).
const ROBOT_CLEARANCE_M: f64 = 0.45;
/// Draws tried before taking the last one anyway (a crowded world).
const PLACEMENT_TRIES: usize = 20;

fn place_robot(
    sim: &mut Simulation,
    base: &BaseLayout,
    how: &Randomization,
    rng: &mut Rng,
    spots: &[(String, [f64; 2])],
) -> rover_sim::Result<([f64; 3], Option<String>)> {
    if !how.robot {
        let p = base.robot_base;
        sim.place_robot(p)?;
        let yaw = rover_sim::geometry::yaw_of(p.rotation);
        return Ok((
            [
                f64::from(p.translation.x),
                f64::from(p.translation.y),
                yaw.to_degrees(),
            ],
            None,
        ));
    }
    let footprints = footprints(sim.world());
    let half_fov = sim
        .robot()
        .cameras
        .first()
        .map_or(0.5, |c| c.horizontal_fov_rad / 2.0);
    let background = spots.is_empty() || rng.uniform() < how.background;
    let target = (!background).then(|| rng.below(spots.len()));
    let (mut x, mut y, mut yaw) = (0.0, 0.0, 0.0);
    for _ in 0..PLACEMENT_TRIES {
        match target {
            Some(t) => {
                let [tx, ty] = spots[t].1;
                let distance = rng.between(how.distance_m[0], how.distance_m[1]);
                let bearing = rng.between(-PI, PI);
                (x, y) = (tx + distance * bearing.cos(), ty + distance * bearing.sin());
                // Facing the thing, off-centre by up to 80 % of half the field of view.
                yaw = (ty - y).atan2(tx - x) + rng.between(-0.8, 0.8) * half_fov;
            }
            None => {
                let (lo, hi) = spread(spots, base);
                (x, y) = (rng.between(lo[0], hi[0]), rng.between(lo[1], hi[1]));
                yaw = rng.between(-PI, PI);
            }
        }
        let clear = footprints
            .iter()
            .all(|(c, r)| (c[0] - x).hypot(c[1] - y) >= r + ROBOT_CLEARANCE_M);
        if clear {
            break;
        }
    }
    let z = f64::from(base.robot_base.translation.z);
    sim.place_robot(pose_from_position_yaw([x, y, z], yaw))?;
    Ok(([x, y, yaw.to_degrees()], target.map(|t| spots[t].0.clone())))
}

/// The area background images are taken in: around the labelled things and the robot's
/// spawn, 3 m beyond them.
fn spread(spots: &[(String, [f64; 2])], base: &BaseLayout) -> ([f64; 2], [f64; 2]) {
    let t = base.robot_base.translation;
    let mut lo = [f64::from(t.x), f64::from(t.y)];
    let mut hi = lo;
    for (_, p) in spots {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    ([lo[0] - 3.0, lo[1] - 3.0], [hi[0] + 3.0, hi[1] + 3.0])
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    reason = "tests: a failed unwrap is a failed test"
)]
mod tests {
    use super::*;

    #[test]
    fn each_image_has_its_own_stream_fixed_by_seed_and_index() {
        let draws = |seed, index| {
            let mut r = Rng::for_image(seed, index);
            [r.uniform(), r.uniform(), r.uniform()]
        };
        assert_eq!(draws(7, 3), draws(7, 3));
        assert_ne!(draws(7, 3), draws(7, 4));
        assert_ne!(draws(7, 3), draws(8, 3));
        let mut r = Rng::for_image(1, 0);
        let mean = (0..10_000).map(|_| r.uniform()).sum::<f64>() / 10_000.0;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }

    #[test]
    fn ranges_are_checked() {
        assert!(Randomization::default().check().is_ok());
        let bad = Randomization {
            distance_m: [3.0, 1.0],
            ..Randomization::default()
        };
        assert!(bad.check().unwrap_err().contains("MIN,MAX"));
        let bad = Randomization {
            noise_max: f64::NAN,
            ..Randomization::default()
        };
        assert!(bad.check().unwrap_err().contains("noise"));
    }
}
