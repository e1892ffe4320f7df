//! File formats -> model: ros_control controllers YAML (`controllers.rs`), URDF (`robot.rs` with `urdf.rs` for the elements and `gazebo.rs` for
//! the `<gazebo>` extensions), xacro (`xacro/`), Gazebo SDF worlds (`sdf.rs`), rover's TOML
//! worlds (`world_toml.rs`), mesh files and their textures (`mesh_file.rs`, COLLADA in
//! `collada.rs`), OGRE material
//! scripts (`ogre.rs`), MoveIt SRDF planning groups (`srdf.rs`), `package://` and `model://` lookup
//! (`resource.rs`), with the XML helpers they share (`xml.rs`). The entries are
//! [`RobotModel::load`](crate::model::RobotModel::load) and [`World::load`](crate::model::World::load);
//! nothing here is needed to run a model built in code.

pub(crate) mod bridge_map;
pub(crate) mod collada;
pub(crate) mod collada_skin;
pub(crate) mod controllers;
pub(crate) mod fuel;
pub(crate) mod gazebo;
pub(crate) mod mesh_file;
pub(crate) mod ogre;
pub(crate) mod parts;
pub(crate) mod resource;
pub(crate) mod robot;
pub(crate) mod ros2_controllers;
pub(crate) mod sdf;
pub(crate) mod sdf_include;
pub(crate) mod sdf_robot;
pub(crate) mod srdf;
pub(crate) mod toml;
pub(crate) mod trimesh;
pub(crate) mod urdf;
pub(crate) mod world_toml;
pub(crate) mod xacro;
pub(crate) mod xml;
pub(crate) mod yaml;

pub use bridge_map::{BridgeDirection, TopicBridge, TopicMap};
pub use controllers::{load_controllers, parse_controllers};
pub use mesh_file::{load_mesh, load_texture};
pub use resource::{NotFound, ResourcePaths};
pub use robot::LoadOptions;
pub use srdf::{
    ArmGroup, DisabledCollisions, load_arm_group, load_disabled_collisions, parse_arm_group,
    parse_disabled_collisions,
};
pub use toml::{load_toml, parse_toml};
pub use trimesh::{TriMesh, TriMeshPart};
pub use world_toml::WorldFile;
pub use xacro::{Expanded, expand_file as expand_xacro, uses_xacro};
