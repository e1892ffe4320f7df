//! Reading launch files from disk: scoping and error rules, and what rover does itself.

use std::path::{Path, PathBuf};

use super::{LaunchOptions, NodeRole, ParamSource, ParamValue, RoverPart, load};

type TestResult = Result<(), Box<dyn std::error::Error>>;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        let _ = std::fs::create_dir_all(parent);
    }
    if let Err(e) = std::fs::write(&path, text) {
        panic!("cannot write {}: {e}", path.display());
    }
    path
}

fn options(dir: &Path, rover: bool) -> LaunchOptions {
    LaunchOptions {
        resources: rover_sim::description::ResourcePaths::default().with_package("pkg", dir),
        rover,
        ..Default::default()
    }
}

fn error(dir: &Path, text: &str) -> String {
    let path = write(dir, "bad.launch", text);
    match load(&path, &options(dir, true)) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn include_args_follow_roslaunch_rules() -> TestResult {
    let dir = tempfile::tempdir()?;
    let d = dir.path();
    write(d, "package.xml", "<package><name>pkg</name></package>");
    write(
        d,
        "inc.launch",
        "<launch>\n<arg name=\"a\"/>\n<arg name=\"b\" default=\"2\"/>\n<param name=\"sum\" value=\"$(eval a + b)\"/>\n</launch>\n",
    );
    let ok = write(
        d,
        "ok.launch",
        "<launch><include file=\"$(find pkg)/inc.launch\" ns=\"n\"><arg name=\"a\" value=\"1\"/></include></launch>",
    );
    let launch = load(&ok, &options(d, true))?;
    assert_eq!(launch.params["/n/sum"].value, ParamValue::Int(3));
    assert_eq!(launch.files.len(), 2);

    let unused = error(
        d,
        "<launch>\n<include file=\"$(dirname)/inc.launch\">\n<arg name=\"a\" value=\"1\"/><arg name=\"c\" value=\"1\"/>\n</include>\n</launch>",
    );
    assert!(unused.contains("bad.launch:2: unused args [c]"), "{unused}");
    let missing = error(
        d,
        "<launch>\n\n<include file=\"$(dirname)/inc.launch\"/>\n</launch>",
    );
    assert!(
        missing.contains("inc.launch:4: name 'a' is not defined: arg \"a\" is not defined"),
        "{missing}"
    );
    let fixed = error(
        d,
        "<launch>\n<arg name=\"x\" value=\"1\"/>\n<arg name=\"x\" default=\"2\"/>\n</launch>",
    );
    assert!(
        fixed.contains("bad.launch:3: arg \"x\" has already been declared"),
        "{fixed}"
    );
    let both = error(d, "<launch><group if=\"1\" unless=\"0\"/></launch>");
    assert!(both.contains("cannot set both"), "{both}");
    let not_bool = error(
        d,
        "<launch>\n<param name=\"p\" value=\"1\" if=\"maybe\"/></launch>",
    );
    assert!(
        not_bool.contains("bad.launch:2:") && not_bool.contains("maybe"),
        "{not_bool}"
    );
    let xml = error(d, "<launch>\n<param name=\"p\" value=\"1\">\n</launch>");
    assert!(xml.contains("bad.launch:3: not well-formed XML"), "{xml}");
    let root = error(d, "<robot/>");
    assert!(root.contains("expected a <launch> root element"), "{root}");
    Ok(())
}

#[test]
fn a_cyclic_include_is_an_error_where_it_closes() -> TestResult {
    let dir = tempfile::tempdir()?;
    let d = dir.path();
    let a = write(
        d,
        "a.launch",
        "<launch>\n<include file=\"$(dirname)/b.launch\"/>\n</launch>",
    );
    write(
        d,
        "b.launch",
        "<launch>\n\n<include file=\"$(dirname)/a.launch\"/>\n</launch>",
    );
    let Err(e) = load(&a, &options(d, true)) else {
        return Err("a cycle loaded".into());
    };
    let e = e.to_string();
    assert!(e.contains("b.launch:3: cyclic include: "), "{e}");
    assert!(e.contains("a.launch -> ") && e.ends_with("a.launch"), "{e}");
    Ok(())
}

#[test]
fn rover_does_gazebo_spawn_darknet_and_controllers_itself() -> TestResult {
    let dir = tempfile::tempdir()?;
    let d = dir.path();
    write(d, "package.xml", "<package><name>pkg</name></package>");
    write(
        d,
        "robot.urdf.xacro",
        "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\"><xacro:arg name=\"w\" default=\"1\"/><link name=\"$(arg w)\"/></robot>",
    );
    write(
        d,
        "controllers.yaml",
        "arm_controller:\n  type: position_controllers/JointTrajectoryController\n  joints: [a]\n",
    );
    write(
        d,
        "net.yaml",
        "yolo_model:\n  threshold:\n    value: 0.45\n",
    );
    let path = write(
        d,
        "all.launch",
        r#"<launch>
  <param name="robot_description" command="$(find xacro)/xacro '$(find pkg)/robot.urdf.xacro' w:=base"/>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="world_name" value="$(find pkg)/my.world"/>
    <arg name="paused" value="true"/>
    <arg name="gui" value="false"/>
  </include>
  <node name="spawn" pkg="gazebo_ros" type="spawn_model" args="-urdf -param robot_description -model car -x 1.5 -y -2 -Y 0.5"/>
  <node name="rsp" pkg="robot_state_publisher" type="robot_state_publisher"/>
  <rosparam file="$(find pkg)/controllers.yaml" command="load"/>
  <node name="spawner" pkg="controller_manager" type="spawner" args="arm_controller"/>
  <include file="$(find darknet_ros)/launch/darknet_ros.launch">
    <arg name="network_param_file" value="$(find pkg)/net.yaml"/>
  </include>
  <node name="mine" pkg="pkg" type="mine.py"/>
</launch>"#,
    );
    let launch = load(&path, &options(d, true))?;
    let description = &launch.params["/robot_description"];
    match (&description.source, &description.value) {
        (ParamSource::Xacro { file, args }, ParamValue::Str(urdf)) => {
            assert!(file.ends_with("robot.urdf.xacro"));
            assert_eq!(args.get("w").map(String::as_str), Some("base"));
            assert!(urdf.contains("<link name=\"base\""), "{urdf}");
        }
        other => panic!("robot_description from {other:?}"),
    }
    let part = RoverPart::of(&launch)?;
    let world = part.world.clone().ok_or("no world")?;
    assert!(
        world
            .world_name
            .as_deref()
            .is_some_and(|w| w.ends_with("my.world"))
    );
    assert!(world.paused && !world.gui && world.use_sim_time);
    let spawn = part.spawn.clone().ok_or("no spawn")?;
    assert_eq!((spawn.xyz_m, spawn.yaw_rad), ([1.5, -2.0, 0.0], 0.5));
    assert_eq!(spawn.param.as_deref(), Some("robot_description"));
    assert_eq!(part.detector.as_ref().and_then(|d| d.threshold), Some(0.45));
    assert_eq!(
        part.controllers_file()
            .map(|f| f.ends_with("controllers.yaml")),
        Some(true)
    );
    assert_eq!(
        part.roles,
        vec![
            NodeRole::Spawn,
            NodeRole::RobotStatePublisher,
            NodeRole::ControllerSpawner(vec!["arm_controller".into()]),
            NodeRole::Process
        ]
    );
    Ok(())
}
