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
