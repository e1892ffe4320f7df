//! Object classes: COCO's 80 names (what YOLO models trained on COCO report, and the names a
//! world may give its objects), and the Gazebo models that are known to be one of them.

/// COCO's 80 class names in YOLO order (the same list as the detector's default labels; a test
/// in `tests/` checks they agree).
pub const COCO_CLASSES: [&str; 80] = [
    "person",
    "bicycle",
    "car",
    "motorcycle",
    "airplane",
    "bus",
    "train",
    "truck",
    "boat",
    "traffic light",
    "fire hydrant",
    "stop sign",
    "parking meter",
    "bench",
    "bird",
    "cat",
    "dog",
    "horse",
    "sheep",
    "cow",
    "elephant",
    "bear",
    "zebra",
    "giraffe",
    "backpack",
    "umbrella",
    "handbag",
    "tie",
    "suitcase",
    "frisbee",
    "skis",
    "snowboard",
    "sports ball",
    "kite",
    "baseball bat",
    "baseball glove",
    "skateboard",
    "surfboard",
    "tennis racket",
    "bottle",
    "wine glass",
    "cup",
    "fork",
    "knife",
    "spoon",
    "bowl",
    "banana",
    "apple",
    "sandwich",
    "orange",
    "broccoli",
    "carrot",
    "hot dog",
    "pizza",
    "donut",
    "cake",
    "chair",
    "couch",
    "potted plant",
    "bed",
    "dining table",
    "toilet",
    "tv",
    "laptop",
    "mouse",
    "remote",
    "keyboard",
    "cell phone",
    "microwave",
    "oven",
    "toaster",
    "sink",
    "refrigerator",
    "book",
    "clock",
    "vase",
    "scissors",
    "teddy bear",
    "hair drier",
    "toothbrush",
];

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
    ("person_standing", "person"),
    ("person_walking", "person"),
];

/// The COCO class of a Gazebo model, from its `model://` name or its own name.
pub fn class_of_model(name: &str) -> Option<&'static str> {
    MODEL_CLASSES
        .iter()
        .find(|(model, _)| *model == name)
        .map(|(_, class)| *class)
}

/// Whether `class` is one of [`COCO_CLASSES`].
pub fn is_known_class(class: &str) -> bool {
    COCO_CLASSES.contains(&class)
}
