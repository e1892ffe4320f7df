//! Every bad input gives an error naming the file, the line or key, and what was expected.

use std::path::Path;

use rover_core::Script;
use rover_sim::{RobotModel, World};
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
    let caster = robot
        .link_index("caster_link")
        .map(|i| robot.links[i].friction);
    assert_eq!(caster, Some(Some(0.0)), "mu1/mu2 from <gazebo reference>");
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
            RobotModel::load(&urdf)?;
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
