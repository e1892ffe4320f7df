//! Object classes: which of COCO's 80 names (`rover_assets::COCO80`: what YOLO models trained
//! on COCO report, and the names a world may give its objects) the Gazebo models are known to be.

use rover_assets::COCO80;

/// Gazebo models (by `model://` name, or the model's own name) that are a COCO class, as
/// osrf/gazebo_models ships them. Users extend it with a `class` per model.
pub const MODEL_CLASSES: &[(&str, &str)] = &[
    ("fire_hydrant", "fire hydrant"),
    ("stop_sign", "stop sign"),
    ("hatchback", "car"),
    ("hatchback_blue", "car"),
    ("hatchback_red", "car"),
    ("suv", "car"),
    ("pickup", "truck"),
    ("ambulance", "truck"),
    ("fire_truck", "truck"),
    ("bus", "bus"),
    ("school_bus", "bus"),
    ("cafe_table", "dining table"),
    ("table", "dining table"),
    ("table_marble", "dining table"),
    ("bowl", "bowl"),
    // COCO has no can: YOLO calls osrf's Coke can a "bottle" (0.16-0.47 from the arm car's
    // mast), and its 11 cm beer can "cup" or "bottle".
    ("coke_can", "bottle"),
    ("beer", "bottle"),
    ("plastic_cup", "cup"),
    ("person_standing", "person"),
    ("person_walking", "person"),
];

/// Gazebo models of which COCO boxes only a part: the part at least this high (m) in the
/// model's frame is labelled. osrf's `stop_sign` is one mesh, a 1.57 m pole and a 0.6 m face
/// from 1.22 m to 1.82 m; COCO's stop signs are the face alone.
pub const MODEL_LABEL_PARTS: &[(&str, f32)] = &[("stop_sign", 1.22)];

/// The height above which a Gazebo model (by `model://` name or its own name) is labelled
/// ([`MODEL_LABEL_PARTS`]); `None`: all of it.
pub fn label_part_of_model(name: &str) -> Option<f32> {
    MODEL_LABEL_PARTS
        .iter()
        .find(|(model, _)| *model == name)
        .map(|(_, above_m)| *above_m)
}

/// The COCO class of a Gazebo model, from its `model://` name or its own name.
pub fn class_of_model(name: &str) -> Option<&'static str> {
    MODEL_CLASSES
        .iter()
        .find(|(model, _)| *model == name)
        .map(|(_, class)| *class)
}

/// Whether `class` is one of COCO's 80 ([`rover_assets::COCO80`]).
pub fn is_known_class(class: &str) -> bool {
    COCO80.contains(&class)
}

/// A labelled thing of a world: what a ground-truth box is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Labelled {
    /// A person (index in the world's people).
    Person(usize),
    /// A TOML world object with a `class` (index in the world's objects).
    Object(usize),
    /// A Gazebo model of a known class (index in the world's models).
    Model(usize),
}

/// The labelled things of a world numbered 1, 2, ... in one fixed order (people, then labelled
/// objects, then labelled models, each in world order): the numbers the renderer's id pass
/// writes (0 is "nothing labelled"), shared by the renderer and the ground truth.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EntityIds {
    /// Entity `id` is `entities[id - 1]`, with its class.
    entities: Vec<(Labelled, String)>,
    people: Vec<u32>,
    objects: Vec<u32>,
    models: Vec<u32>,
}

impl EntityIds {
    /// The id the renderer writes for the robot's own links: never a labelled thing (no box,
    /// no silhouette), it tells a self filter which pixels are the robot (MoveIt's
    /// robot_self_filter and mesh filter).
    pub const ROBOT: u32 = u32::MAX;

    /// Numbers `world`'s labelled things.
    pub fn new(world: &crate::model::world::World) -> Self {
        let mut ids = Self::default();
        let next = |ids: &mut Self, label: Labelled, class: &str| {
            ids.entities.push((label, class.to_owned()));
            ids.entities.len() as u32
        };
        for i in 0..world.people.len() {
            let id = next(&mut ids, Labelled::Person(i), "person");
            ids.people.push(id);
        }
        for (i, object) in world.objects.iter().enumerate() {
            let id = match &object.class {
                Some(class) => next(&mut ids, Labelled::Object(i), class),
                None => 0,
            };
            ids.objects.push(id);
        }
        for (i, model) in world.models.iter().enumerate() {
            let id = match &model.class {
                Some(class) => next(&mut ids, Labelled::Model(i), class),
                None => 0,
            };
            ids.models.push(id);
        }
        ids
    }

    /// How many labelled things there are (the largest id).
    pub fn len(&self) -> usize {
        self.entities.len()
    }

    /// Whether the world has nothing labelled.
    pub fn is_empty(&self) -> bool {
        self.entities.is_empty()
    }

    /// The id of person `index` (never 0: people are always labelled).
    pub fn person(&self, index: usize) -> u32 {
        self.people.get(index).copied().unwrap_or(0)
    }

    /// The id of world object `index`, 0 when it has no class.
    pub fn object(&self, index: usize) -> u32 {
        self.objects.get(index).copied().unwrap_or(0)
    }

    /// The id of Gazebo model `index`, 0 when it has no known class.
    pub fn model(&self, index: usize) -> u32 {
        self.models.get(index).copied().unwrap_or(0)
    }

    /// What entity `id` is and its class (`None` for 0 or an id past the last).
    pub fn entity(&self, id: u32) -> Option<(Labelled, &str)> {
        let i = (id as usize).checked_sub(1)?;
        self.entities.get(i).map(|(l, c)| (*l, c.as_str()))
    }
}
