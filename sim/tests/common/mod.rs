//! What the sensor tests share: the tutorial car with a `<gazebo>` block of the test's own.

use std::path::Path;

use rover_sim::model::RobotModel;

/// The tests' result type.
pub type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The tutorial car (assets/robots/my_robot.urdf) with `gazebo` added before `</robot>`, read
/// as if it were that file (errors name it, with the line).
pub fn car_with(gazebo: &str) -> Result<RobotModel> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/robots/my_robot.urdf");
    let text = std::fs::read_to_string(&path)?;
    let text = text.replacen("</robot>", &format!("{gazebo}\n</robot>"), 1);
    Ok(RobotModel::from_str(&text, &path)?)
}

/// Asserts that the car with each `(gazebo block, expected text)` fails to load with an error
/// containing the text and located in my_robot.urdf (file and line).
pub fn assert_located_errors<'a>(
    cases: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> Result<()> {
    for (block, expected) in cases {
        let err = car_with(block)
            .err()
            .ok_or("expected an error")?
            .to_string();
        assert!(err.contains(expected), "{err}");
        assert!(err.contains("my_robot.urdf:"), "located: {err}");
    }
    Ok(())
}
