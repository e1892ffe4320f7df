//! Every bad input gives an error naming the file, the line or key, and what was expected.

use std::path::Path;

use rover_core::Script;
use rover_sim::model::{RobotModel, World};
use rover_tests::repo;

fn robot_text() -> String {
    std::fs::read_to_string(repo("assets/robots/my_robot.urdf")).unwrap_or_default()
}

fn urdf_error(text: &str) -> String {
    match RobotModel::from_str(text, Path::new("bad.urdf")) {
        Ok(_) => String::from("(loaded without error)"),
        Err(e) => e.to_string(),
    }
}

/// Replaces `from` with `to` in the robot's URDF and checks the load error names the line of
/// `to` and says `expect`.
fn assert_edit_is_refused_at_its_line(
    robot: &str,
    from: &str,
    to: &str,
    expect: &str,
) -> anyhow::Result<()> {
    anyhow::ensure!(robot.contains(from), "my_robot.urdf has no {from}");
    let text = robot.replacen(from, to, 1);
    let message = urdf_error(&text);
    let line = line_of(&text, to);
    assert!(
        message.contains(&format!("bad.urdf:{line}:")) && message.contains(expect),
        "{message}"
    );
    Ok(())
}

/// The error loading a world file gives ("" when it loads).
fn world_error(path: &Path) -> String {
    World::load(path)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default()
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map_or(0, |i| i + 1)
}

#[test]
fn the_bundled_robot_loads_with_its_plugins() -> anyhow::Result<()> {
    let robot = RobotModel::load(&repo("assets/robots/my_robot.urdf"))?;
    let dd = robot
        .diff_drive
        .clone()
        .ok_or_else(|| anyhow::anyhow!("no diff drive"))?;
    assert_eq!(
        (dd.left_joint.as_str(), dd.right_joint.as_str()),
        ("left_wheel_joint", "right_wheel_joint")
    );
    assert_eq!((dd.wheel_separation_m, dd.wheel_diameter_m), (0.3, 0.1));
    assert_eq!(dd.wheel_torque_nm, 5.0, "Gazebo's default");
    assert_eq!(dd.update_rate_hz, 100.0, "Gazebo's default");
    let cam = &robot.cameras[0];
    assert_eq!(
        (cam.width_px, cam.height_px, cam.link.as_str()),
        (640, 480, "camera_link")
    );
    assert_eq!(
        (cam.update_rate_hz, cam.horizontal_fov_rad),
        (30.0, 1.3962634)
    );
    assert_eq!((cam.clip_near_m, cam.clip_far_m), (0.02, 300.0));
    let caster = robot.link_id("caster_link").map(|i| robot.link(i).friction);
    assert_eq!(caster, Some(Some(0.0)), "mu1/mu2 from <gazebo reference>");
    Ok(())
}

/// `<kp>` (ODE's contact stiffness) is read per link; one that is not a positive number is
/// left out with a warning, the robot still loads (a soft-contact tuning is no reason to refuse
/// a robot).
#[test]
fn contact_stiffness_is_read_and_a_bad_one_is_left_out() -> anyhow::Result<()> {
    let kp = |text: &str| -> anyhow::Result<Option<f32>> {
        let robot = RobotModel::from_str(text, Path::new("kp.urdf"))?;
        let caster = robot
            .link_id("caster_link")
            .ok_or_else(|| anyhow::anyhow!("no caster_link"))?;
        Ok(robot.link(caster).contact_kp_n_per_m)
    };
    let text = robot_text();
    assert_eq!(kp(&text)?, None);
    let soft = text.replace("<mu1>0.0</mu1>", "<mu1>0.0</mu1><kp>1000000.0</kp>");
    assert_eq!(kp(&soft)?, Some(1e6));
    let bad = text.replace("<mu1>0.0</mu1>", "<mu1>0.0</mu1><kp>soft</kp>");
    assert_eq!(kp(&bad)?, None);
    Ok(())
}

#[test]
fn plugin_naming_a_missing_joint_lists_the_joints_that_exist() {
    let text = robot_text().replace(
        "<leftJoint>left_wheel_joint</leftJoint>",
        "<leftJoint>left_joint</leftJoint>",
    );
    let err = urdf_error(&text);
    let line = line_of(&text, "libgazebo_ros_diff_drive.so");
    assert!(err.starts_with(&format!("bad.urdf:{line}: ")), "{err}");
    assert!(
        err.contains("<leftJoint>left_joint</leftJoint>: no such joint"),
        "{err}"
    );
    assert!(
        err.contains("\"left_wheel_joint\", \"right_wheel_joint\""),
        "{err}"
    );
}

#[test]
fn wheel_joint_that_is_not_continuous_or_revolute() {
    let text = robot_text().replace(
        "<joint name=\"left_wheel_joint\" type=\"continuous\">",
        "<joint name=\"left_wheel_joint\" type=\"fixed\">",
    );
    let err = urdf_error(&text);
    assert!(
        err.contains("the joint is fixed, expected a continuous or revolute wheel joint"),
        "{err}"
    );
}

#[test]
fn joint_naming_a_missing_link() {
    let text = robot_text().replace(
        "<child link=\"right_wheel\"/>",
        "<child link=\"rigth_wheel\"/>",
    );
    let err = urdf_error(&text);
    let line = line_of(&text, "<joint name=\"right_wheel_joint\"");
    assert!(err.starts_with(&format!("bad.urdf:{line}: ")), "{err}");
    assert!(
        err.contains(
            "<child link=\"rigth_wheel\">: no such link; links in this robot: \"base_link\""
        ),
        "{err}"
    );
}

#[test]
fn malformed_xml_reports_the_line() {
    let text = robot_text().replacen("</link>", "</lnk>", 1);
    let err = urdf_error(&text);
    let line = line_of(&text, "</lnk>");
    assert!(
        err.starts_with(&format!("bad.urdf:{line}: malformed XML")),
        "{err}"
    );
}

#[test]
fn malformed_numbers_report_element_and_expectation() {
    let text = robot_text().replace(
        "<origin xyz=\"0.15 0 0.1\"",
        "<origin xyz=\"0.15 zero 0.1\"",
    );
    let err = urdf_error(&text);
    let line = line_of(&text, "0.15 zero 0.1");
    assert!(err.starts_with(&format!("bad.urdf:{line}: <origin xyz=\"0.15 zero 0.1\">: expected 3 numbers; 'zero' is not a finite number")), "{err}");

    let text = robot_text().replace(
        "<wheelDiameter>0.1</wheelDiameter>",
        "<wheelDiameter>ten cm</wheelDiameter>",
    );
    let err = urdf_error(&text);
    assert!(err.contains("<wheelDiameter> in the libgazebo_ros_diff_drive.so plugin: expected a number (metres), found 'ten cm'"), "{err}");

    let text = robot_text().replace("<box size=\"0.3 0.2 0.1\"/>", "<box size=\"0.3 0.2\"/>");
    let err = urdf_error(&text);
    assert!(
        err.contains("<box size=\"0.3 0.2\">: expected 3 numbers; found 2 value(s)"),
        "{err}"
    );

    let text = robot_text().replace("<width>640</width>", "<width>-640</width>");
    let err = urdf_error(&text);
    assert!(
        err.contains("<width> in <sensor name=\"camera1\">: expected a whole number of pixels"),
        "{err}"
    );
}

#[test]
fn a_missing_file_names_it() {
    let err = RobotModel::load(Path::new("/nonexistent/robot.urdf"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.starts_with("cannot read /nonexistent/robot.urdf:"),
        "{err}"
    );
}

/// A world object's `class` must be a COCO class: the error names the key and lists them.
#[test]
fn a_world_object_of_an_unknown_class_is_refused_with_the_known_ones() -> anyhow::Result<()> {
    let text = "[[box]]\nsize_m = [1.0, 1.0, 1.0]\nposition_m = [5.0, 0.0]\nclass = \"hydrant\"\n";
    let err = World::from_str(text, Path::new("w.toml"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("at `box[0].class`: \"hydrant\" is not a COCO class")
            && err.contains("fire hydrant, stop sign"),
        "{err}"
    );
    let ok = "[[cylinder]]\nradius_m = 0.2\nlength_m = 0.6\nposition_m = [3.0, 1.0]\nclass = \"fire hydrant\"\n";
    let world = World::from_str(ok, Path::new("w.toml"))?;
    assert_eq!(world.objects[0].class.as_deref(), Some("fire hydrant"));
    Ok(())
}

#[test]
fn world_unknown_keys_and_bad_values_name_the_key_path() {
    let err = |text: &str| {
        World::from_str(text, Path::new("w.toml"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let e =
        err("[[box]]\nsize_m = [1.0, 1.0, 1.0]\nposition_m = [1.0, 0.0]\ncolour = \"#ff0000\"\n");
    assert!(
        e.starts_with("w.toml:4: at `box[0].colour`: unknown field `colour`"),
        "{e}"
    );
    let e = err("[[box]]\nsize_m = [1.0, -1.0, 1.0]\nposition_m = [1.0, 0.0]\n");
    assert!(
        e.contains("at `box[0].size_m`: expected positive numbers (m)"),
        "{e}"
    );
    let e = err("[ground]\ncolor = \"green\"\n");
    assert!(
        e.contains("at `ground.color`: expected a colour like"),
        "{e}"
    );
    let e = err("[physics]\nstep_hz = \"fast\"\n");
    assert!(e.starts_with("w.toml:2: at `physics.step_hz`"), "{e}");
    let e = err("[robot]\nplace = [0.5, 0.2]\n");
    assert!(
        e.starts_with("w.toml:2: at `robot.place`: expected a world object's name"),
        "{e}"
    );
    let e = err("[robot]\nplace = [0.5, 0.2, 1e12]\n");
    assert!(e.contains("at `robot.place`"), "{e}");
    let e = err("[robot]\nfetch = [0.27]\n");
    assert!(e.starts_with("w.toml:2: at `robot.fetch`"), "{e}");
    let e = err("[robot]\nfetch = [0.27, 1e12]\n");
    assert!(
        e.contains("at `robot.fetch`") && e.contains("out of range"),
        "{e}"
    );
    let e = err(
        "[robot.drive]\nleft_joint = \"l\"\nright_joint = \"r\"\nwheel_acceleration_mps2 = \"fast\"\n",
    );
    assert!(e.contains("wheel_acceleration_mps2"), "{e}");
    let e = err("[physics]\ncontact_hz = 0.0\n");
    assert!(
        e.contains("at `physics.contact_hz`: expected a contact stiffness of 1..=1000 Hz"),
        "{e}"
    );
    let e = err("[[person]]\nposition_m = [4.0, 0.0]\nheight_m = 7.0\n");
    assert!(
        e.contains("at `person[0].height_m`: expected a height between 0.5 and 2.5 m"),
        "{e}"
    );
    let e = err("[[wall]]\nfrom_m = [0.0, 0.0]\nto_m = [0.0, 0.0]\n");
    assert!(e.contains("at `wall[0].to_m`"), "{e}");
}

#[test]
fn script_unknown_step_kinds_are_errors() {
    let err = |text: &str| {
        Script::from_str(text, Path::new("s.toml"))
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default()
    };
    let e = err("steps = [ { at = 1.0, jump = true } ]");
    assert!(
        e.contains("s.toml:1: at `steps[0].jump`: unknown field `jump`"),
        "{e}"
    );
    let e = err("steps = [ { at = 1.0, key = \"y\" } ]");
    assert!(e.contains("key \"y\" is not a teleop key"), "{e}");
}

#[test]
fn the_bundled_worlds_load() -> anyhow::Result<()> {
    for entry in std::fs::read_dir(repo("worlds"))? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "toml") {
            let world = World::load(&path)?;
            let urdf = world
                .robot
                .urdf
                .clone()
                .unwrap_or_else(|| repo("assets/robots/my_robot.urdf"));
            // The panda's world finds the arm in PyPI's example-robot-data.
            let options = if path.ends_with("panda_pick.toml") {
                let Some(options) = rover_tests::example_robot_data_options() else {
                    continue;
                };
                options
            } else {
                rover_sim::description::LoadOptions::default()
            };
            RobotModel::load_with(&urdf, &options)?;
        }
    }
    let playground = World::load(&repo("worlds/playground.toml"))?;
    assert_eq!(playground.people.len(), 1);
    assert!(
        playground.people[0].position_m[0] > 2.0,
        "a person a few metres ahead"
    );
    Ok(())
}

/// Writes `files` into a fresh folder and loads the first as a robot (xacro or URDF).
fn load_robot_files(files: &[(&str, &str)]) -> anyhow::Result<(tempfile::TempDir, String)> {
    let dir = tempfile::tempdir()?;
    for (name, text) in files {
        let p = dir.path().join(name);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(p, text)?;
    }
    let message = match RobotModel::load_with(
        &dir.path().join(files[0].0),
        &rover_sim::description::LoadOptions::default(),
    ) {
        Ok(_) => String::from("(loaded without error)"),
        Err(e) => e.to_string(),
    };
    Ok((dir, message))
}

const XACRO_HEAD: &str = r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">"#;

#[test]
fn xacro_errors_name_the_xacro_file_line_and_the_undefined_thing() -> anyhow::Result<()> {
    let cases = [
        (
            format!("{XACRO_HEAD}\n<link name=\"${{wheel_radius * 2}}\"/>\n</robot>"),
            "r.urdf.xacro:2: in \"${wheel_radius * 2}\": undefined property \"wheel_radius\"",
        ),
        (
            format!("{XACRO_HEAD}\n<link name=\"a\"/>\n<xacro:wheel/>\n</robot>"),
            "r.urdf.xacro:3: unknown macro \"xacro:wheel\"",
        ),
        (
            format!("{XACRO_HEAD}\n<link name=\"$(arg prefix)base\"/>\n</robot>"),
            "r.urdf.xacro:2: in \"$(arg prefix)base\": undefined arg \"prefix\"",
        ),
        (
            format!(
                "{XACRO_HEAD}\n<xacro:include filename=\"$(find no_such_pkg)/urdf/x.xacro\"/>\n</robot>"
            ),
            "$(find no_such_pkg): ROS package \"no_such_pkg\" not found; searched:",
        ),
    ];
    for (text, expected) in cases {
        let (_dir, message) = load_robot_files(&[("r.urdf.xacro", &text)])?;
        assert!(
            message.contains(expected),
            "{message}\nexpected: {expected}"
        );
    }
    let (_dir, message) = load_robot_files(&[
        (
            "r.urdf.xacro",
            &format!("{XACRO_HEAD}\n<xacro:include filename=\"b.xacro\"/>\n</robot>"),
        ),
        (
            "b.xacro",
            &format!("{XACRO_HEAD}\n\n<xacro:include filename=\"r.urdf.xacro\"/>\n</robot>"),
        ),
    ])?;
    assert!(
        message.contains("b.xacro:3: include cycle:") && message.contains("r.urdf.xacro -> "),
        "{message}"
    );
    // A URDF error found after expansion points at the xacro line the element came from.
    let (_dir, message) = load_robot_files(&[(
        "r.urdf.xacro",
        &format!(
            "{XACRO_HEAD}\n<xacro:macro name=\"j\" params=\"p\">\n<joint name=\"j\" type=\"fixed\"><parent link=\"${{p}}\"/><child link=\"a\"/></joint>\n</xacro:macro>\n<link name=\"a\"/>\n<xacro:j p=\"nowhere\"/>\n</robot>"
        ),
    )])?;
    assert!(
        message.contains("r.urdf.xacro:3:")
            && message.contains("<parent link=\"nowhere\">: no such link"),
        "{message}"
    );
    Ok(())
}

#[test]
fn missing_mesh_names_the_uri_and_every_folder_searched() -> anyhow::Result<()> {
    let urdf = r#"<robot name="r"><link name="a"><visual><geometry>
<mesh filename="package://my_pkg/meshes/gone.stl"/></geometry></visual></link></robot>"#;
    let (dir, message) = load_robot_files(&[
        ("my_pkg/urdf/r.urdf", urdf),
        (
            "my_pkg/package.xml",
            "<package><name>my_pkg</name></package>",
        ),
    ])?;
    let searched = dir.path().join("my_pkg/meshes/gone.stl");
    assert!(
        message.contains("r.urdf:1: <link name=\"a\"> <mesh>: file package://my_pkg/meshes/gone.stl not found; searched:")
            && message.contains(&searched.display().to_string()),
        "{message}"
    );
    let (_dir, message) = load_robot_files(&[("r.urdf", &urdf.replace("my_pkg", "other_pkg"))])?;
    assert!(
        message.contains(
            "package://other_pkg/meshes/gone.stl: ROS package \"other_pkg\" not found; searched:"
        ),
        "{message}"
    );
    Ok(())
}

#[test]
fn collada_without_triangles_and_malformed_sdf_are_clear_errors() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let dae = dir.path().join("empty.dae");
    std::fs::write(
        &dae,
        r##"<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1"><asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="6">0 0 0 1 0 0</float_array><technique_common><accessor source="#pa" count="2" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<lines count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1</p></lines>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>"##,
    )?;
    let message = rover_sim::description::load_mesh(&dae, glam::Vec3::ONE)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.contains("empty.dae") && message.contains("mesh has no triangles"),
        "{message}"
    );

    let world = dir.path().join("bad.world");
    std::fs::write(
        &world,
        "<sdf version='1.6'>\n<world name='w'>\n<model name='m'>\n</world></sdf>",
    )?;
    let message = world_error(&world);
    assert!(message.contains("bad.world:4: malformed XML"), "{message}");

    std::fs::write(
        &world,
        "<sdf version='1.6'><world name='w'>\n<include><uri>model://no_such_model</uri></include></world></sdf>",
    )?;
    let message = World::load_with(
        &world,
        &rover_sim::description::ResourcePaths::default().with_model_path(dir.path()),
    )
    .err()
    .map(|e| e.to_string())
    .unwrap_or_default();
    assert!(
        message.contains("bad.world:2: <include><uri>model://no_such_model</uri>: Gazebo model \"no_such_model\" (model://no_such_model) not found; searched:"),
        "{message}"
    );
    std::fs::write(
        &world,
        "<sdf version='1.6'><world name='w'><model name='m'><link name='l'>\n<visual name='v'><pose>0 0 one 0 0 0</pose><geometry><box><size>1 1 1</size></box></geometry></visual></link></model></world></sdf>",
    )?;
    let message = world_error(&world);
    assert!(
        message.contains("bad.world:2: <pose>0 0 one 0 0 0</pose>: expected 6 finite numbers"),
        "{message}"
    );
    Ok(())
}

/// NaN and infinities anywhere a number goes (robot, world TOML, SDF world, script, scenario)
/// are refused at load, naming the file and the element or key path, before any physics runs.
#[test]
fn nan_and_infinity_are_refused_at_load_with_the_key_path() -> anyhow::Result<()> {
    let robot = robot_text();
    for (from, to, expect) in [
        (
            "<origin xyz=\"-0.045 0 0\"",
            "<origin xyz=\"nan 0 0\"",
            "<origin xyz=\"nan 0 0\">: expected 3 numbers; 'nan' is not a finite number",
        ),
        (
            "<mass value=\"",
            "<mass value=\"inf",
            "is not a finite number",
        ),
        (
            "<wheelSeparation>",
            "<wheelSeparation>-inf",
            "<wheelSeparation> in the libgazebo_ros_diff_drive.so plugin: expected a number",
        ),
    ] {
        assert_edit_is_refused_at_its_line(&robot, from, to, expect)?;
    }

    let dir = tempfile::tempdir()?;
    let world_text = std::fs::read_to_string(repo("worlds/playground.toml"))?;
    for (value, shown) in [("nan", "NaN"), ("inf", "inf"), ("-inf", "-inf")] {
        let path = dir.path().join("w.toml");
        std::fs::write(
            &path,
            world_text.replacen(
                "position_m = [4.0, 0.0]",
                &format!("position_m = [4.0, {value}]"),
                1,
            ),
        )?;
        let message = world_error(&path);
        assert!(
            message.contains("w.toml: at `person[0].position_m`: expected finite numbers")
                && message.contains(shown),
            "{message}"
        );
    }

    let sdf = dir.path().join("nan.world");
    std::fs::write(
        &sdf,
        "<sdf version='1.6'><world name='w'>\n<model name='m'><pose>1 nan 0 0 0 0</pose><link name='l'/></model></world></sdf>",
    )?;
    let message = world_error(&sdf);
    assert!(
        message.contains("nan.world:2:") && message.contains("expected 6 finite numbers"),
        "{message}"
    );

    let script = Script::from_str("steps = [ { at = inf, key = \"k\" } ]", Path::new("s.toml"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        script.contains("s.toml: at `steps[0]`: `at` must be"),
        "{script}"
    );

    let scenario = dir.path().join("scenarios/nan.toml");
    std::fs::create_dir_all(scenario.parent().unwrap_or(dir.path()))?;
    let text = std::fs::read_to_string(repo("scenarios/default_world.toml"))?
        .replace(
            "../worlds/playground.toml",
            &repo("worlds/playground.toml").display().to_string(),
        )
        .replacen("duration_s = 35.0", "duration_s = nan", 1);
    std::fs::write(&scenario, text)?;
    let message = rover_core::Scenario::load(&scenario)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        message.contains("nan.toml") && message.contains("scenario.duration_s"),
        "{message}"
    );
    Ok(())
}

/// Finite but absurd magnitudes (a 1e30 m box, a robot 1e30 m from the origin, a 1e30 kg
/// mass) are refused at load with the file and the element or key path, before they reach
/// rapier and parry (whose contact code can fail on them). The accepted ranges: positions
/// within 1e5 m of the origin, sizes up to 1e5 m, masses up to 1e6 kg (docs/RELIABILITY.md).
#[test]
fn absurd_magnitudes_are_refused_at_load_with_the_key_path() -> anyhow::Result<()> {
    let robot = robot_text();
    for (from, to, expect) in [
        (
            "<origin xyz=\"-0.045 0 0\"",
            "<origin xyz=\"1e30 0 0\"",
            "1e30 is out of range: expected positions (m) up to 1e5",
        ),
        (
            "<mass value=\"",
            "<mass value=\"1e30",
            "is out of range: expected a mass (kg) up to 1e6",
        ),
    ] {
        assert_edit_is_refused_at_its_line(&robot, from, to, expect)?;
    }
    let message = urdf_error(&robot.replacen(
        "<box size=\"0.3 0.2 0.1\"/>",
        "<box size=\"3e30 0.2 0.1\"/>",
        1,
    ));
    assert!(
        message.contains("3e30 is out of range: expected sizes (m) up to 1e5"),
        "{message}"
    );

    let dir = tempfile::tempdir()?;
    let world_text = std::fs::read_to_string(repo("worlds/playground.toml"))?;
    for (from, to, expect) in [
        (
            "position_m = [4.0, 0.0]",
            "position_m = [1e30, 0.0]",
            "at `person[0].position_m`: 1000000000000000000000000000000 m is out of range: expected positions within 1e5 m of the origin",
        ),
        (
            "[[box]]\n",
            "[[box]]\nmass_kg = 1e30\n",
            "kg is out of range: expected a mass up to 1e6 kg",
        ),
    ] {
        anyhow::ensure!(world_text.contains(from), "playground.toml has no {from:?}");
        let path = dir.path().join("w.toml");
        std::fs::write(&path, world_text.replacen(from, to, 1))?;
        let message = world_error(&path);
        assert!(
            message.contains("w.toml: at `") && message.contains(expect),
            "{message}"
        );
    }
    let path = dir.path().join("big.toml");
    std::fs::write(
        &path,
        "[[box]]\nsize_m = [1e30, 1.0, 1.0]\nposition_m = [0.0, 0.0]\n",
    )?;
    let message = world_error(&path);
    assert!(
        message.contains("at `box[0].size_m`") && message.contains("expected sizes up to 1e5 m"),
        "{message}"
    );

    let sdf = dir.path().join("far.world");
    std::fs::write(
        &sdf,
        "<sdf version='1.6'><world name='w'>\n<model name='m'><pose>1e30 0 0 0 0 0</pose><link name='l'/></model></world></sdf>",
    )?;
    let message = world_error(&sdf);
    assert!(
        message.contains("far.world:2:")
            && message.contains("expected 6 finite numbers of magnitude up to 1e6"),
        "{message}"
    );
    std::fs::write(
        &sdf,
        "<sdf version='1.6'><world name='w'>\n<model name='m'><pose>0 5e5 0 0 0 0</pose><link name='l'/></model></world></sdf>",
    )?;
    let message = world_error(&sdf);
    assert!(
        message.contains("far.world:2:")
            && message.contains("500000 m is out of range: expected positions within 1e5 m"),
        "{message}"
    );
    Ok(())
}

/// A `<transmission>` names a joint that is missing, a fixed joint, or no command interface;
/// a `<mimic>` names a missing joint: each refused at its line.
#[test]
fn transmissions_and_mimics_that_make_no_sense() -> anyhow::Result<()> {
    let robot = robot_text();
    let transmission = |joint: &str, interface: &str| {
        format!(
            "<transmission name=\"t\"><type>transmission_interface/SimpleTransmission</type><joint name=\"{joint}\"><hardwareInterface>{interface}</hardwareInterface></joint><actuator name=\"m\"><mechanicalReduction>1</mechanicalReduction></actuator></transmission></robot>"
        )
    };
    for (joint, interface, expect) in [
        (
            "elbow",
            "hardware_interface/PositionJointInterface",
            "<joint name=\"elbow\">: no such joint; joints in this robot:",
        ),
        (
            "caster_joint",
            "hardware_interface/PositionJointInterface",
            "the joint is fixed or floating; a transmission drives a revolute, continuous or prismatic joint",
        ),
        (
            "left_wheel_joint",
            "hardware_interface/TorqueInterface",
            "<hardwareInterface> is hardware_interface/TorqueInterface; expected hardware_interface/PositionJointInterface",
        ),
    ] {
        assert_edit_is_refused_at_its_line(
            &robot,
            "</robot>",
            &transmission(joint, interface),
            expect,
        )?;
    }
    assert_edit_is_refused_at_its_line(
        &robot,
        "<joint name=\"right_wheel_joint\" type=\"continuous\">",
        "<joint name=\"right_wheel_joint\" type=\"continuous\"><mimic joint=\"wrist\"/>",
        "<mimic joint=\"wrist\">: no such joint",
    )?;
    Ok(())
}

/// A joint command that is not a number, or names a joint without an actuator, is refused
/// with the reason; the last command stays in force.
#[test]
fn joint_commands_that_make_no_sense() -> anyhow::Result<()> {
    let robot = RobotModel::load(&repo("assets/robots/my_robot.urdf"))?;
    let mut sim = rover_sim::physics::Simulation::new(
        World::flat()?,
        robot,
        &rover_sim::physics::SimOptions::default(),
    )?;
    let err = |r: rover_sim::Result<()>| r.err().map(|e| e.to_string()).unwrap_or_default();
    let missing = err(sim.command_joint("elbow", rover_sim::physics::JointCommand::Position(1.0)));
    assert!(
        missing.contains("has no joint \"elbow\"; its moving joints: \"left_wheel_joint\""),
        "{missing}"
    );
    let wheel = err(sim.command_joint(
        "left_wheel_joint",
        rover_sim::physics::JointCommand::Position(1.0),
    ));
    assert!(wheel.contains("has no actuator"), "{wheel}");
    Ok(())
}

/// A texture that will not decode is a warning and a flat colour, never a failed load: an OBJ
/// whose MTL names a "PNG" that is not one still gives its triangles, with no textured run.
#[test]
fn a_texture_that_will_not_decode_leaves_the_mesh_in_its_colour() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    std::fs::write(
        dir.path().join("quad.obj"),
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl skin\nf 1/1 2/2 3/3 4/4\n",
    )?;
    std::fs::write(
        dir.path().join("quad.mtl"),
        "newmtl skin\n\tKd 0.2 0.4 0.6\n\tmap_Kd broken.png\n",
    )?;
    std::fs::write(dir.path().join("broken.png"), b"not a png at all")?;
    let path = dir.path().join("quad.obj");
    let tri = rover_sim::description::load_mesh(&path, glam::Vec3::ONE)?;
    assert_eq!(tri.parts.len(), 1);
    assert!(
        tri.parts[0]
            .texture
            .as_ref()
            .is_some_and(|t| t.ends_with("broken.png")),
        "the indented map_Kd is read: {:?}",
        tri.parts[0]
    );
    assert_eq!(
        tri.parts[0].color,
        Some(rover_sim::geometry::Rgba::rgb(0.2, 0.4, 0.6))
    );
    let err = rover_sim::description::load_texture(&dir.path().join("broken.png"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("broken.png") && err.contains("cannot decode texture"),
        "{err}"
    );
    let mesh = rover_sim::render::shape_mesh(&rover_sim::geometry::Shape::Mesh {
        path,
        scale: glam::Vec3::ONE,
    })?;
    assert_eq!(mesh.indices.len(), 6);
    assert!(mesh.textured.is_empty(), "drawn in its flat colour");
    assert_eq!(
        mesh.color,
        Some(rover_sim::geometry::Rgba::rgb(0.2, 0.4, 0.6))
    );
    Ok(())
}

/// Modern Gazebo's inputs (issue 62), each refused at its line: a gz-sim DiffDrive without
/// joints, one naming a joint that is not there, a bridge map entry of an unknown type or
/// direction, a ros_gz_bridge map bridging a topic as a type rover does not publish on it.
#[test]
fn gz_sim_systems_and_bridge_maps_are_refused_at_their_lines() -> anyhow::Result<()> {
    let gz = std::fs::read_to_string(repo("assets/robots/my_robot_gz.urdf"))?;
    // A joint that is not there: the plugin's line, and the joints that are.
    let text = gz.replacen("left_wheel_joint</left_joint>", "nope</left_joint>", 1);
    let message = urdf_error(&text);
    let line = line_of(&text, "gz-sim-diff-drive-system");
    assert!(
        message.contains(&format!("bad.urdf:{line}:"))
            && message.contains("<left_joint>nope</left_joint>: no such joint")
            && message.contains("\"left_wheel_joint\""),
        "{message}"
    );
    let text = gz
        .replacen("<left_joint>left_wheel_joint</left_joint>", "", 1)
        .replacen("<right_joint>right_wheel_joint</right_joint>", "", 1);
    let message = urdf_error(&text);
    let line = line_of(&text, "gz-sim-diff-drive-system");
    assert!(
        message.contains(&format!("bad.urdf:{line}:"))
            && message.contains("expected at least one <left_joint> and one <right_joint>"),
        "{message}"
    );

    let map = std::fs::read_to_string(repo("assets/robots/my_robot_gz_bridge.yaml"))?;
    let map_error = |text: &str| -> String {
        match rover_sim::description::TopicMap::parse(text, Path::new("bridge.yaml")) {
            Ok(m) => {
                let mut robot = match RobotModel::from_str(&gz, &repo("assets/robots/x.urdf")) {
                    Ok(r) => r,
                    Err(e) => return e.to_string(),
                };
                match robot.bridge_topics(&m) {
                    Ok(_) => String::from("(bridged without error)"),
                    Err(e) => e.to_string(),
                }
            }
            Err(e) => e.to_string(),
        }
    };
    for (from, to, expect) in [
        (
            "direction: ROS_TO_GZ",
            "direction: ROS2GZ",
            "invalid direction 'ROS2GZ'",
        ),
        (
            "\"sensor_msgs/msg/LaserScan\"",
            "\"sensor_msgs/msg/LaserScann\"",
            "unknown type 'sensor_msgs/msg/LaserScann'",
        ),
        (
            "\"geometry_msgs/msg/Twist\"\n  gz_type_name: \"gz.msgs.Twist\"\n  direction: ROS_TO_GZ",
            "\"geometry_msgs/msg/Twist\"\n  gz_type_name: \"gz.msgs.Twist\"\n  direction: GZ_TO_ROS",
            "the map bridges it the other way",
        ),
    ] {
        anyhow::ensure!(map.contains(from), "the bridge file has no {from}");
        let text = map.replacen(from, to, 1);
        let message = map_error(&text);
        assert!(message.contains(expect), "{message}");
        assert!(message.contains("bridge.yaml:"), "{message}");
    }
    Ok(())
}
