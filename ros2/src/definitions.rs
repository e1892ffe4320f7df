//! The message definitions an MCAP file carries with each schema (`ros2msg`): the type's own
//! fields, then every type it uses under a line of 80 `=` and `MSG: pkg/Type` (the layout of
//! MCAP's `ros2msg` encoding), so `ros2 bag play`, Foxglove, rosbags and Rerun decode the file
//! without the packages installed. Written from the ROS 2 Humble/Jazzy definitions (comments left out);
//! app/tests/mcap.rs checks every field against rosbags' Humble types.

/// A dependency block: the separator line, its `MSG:` line, its fields.
macro_rules! block {
    ($name:literal, $fields:expr) => {
        concat!(
            "================================================================================\nMSG: ",
            $name,
            "\n",
            $fields
        )
    };
}

macro_rules! time {
    () => {
        block!("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n")
    };
}

macro_rules! header {
    () => {
        concat!(
            block!(
                "std_msgs/Header",
                "builtin_interfaces/Time stamp\nstring frame_id\n"
            ),
            time!()
        )
    };
}

macro_rules! vector3 {
    () => {
        block!("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n")
    };
}

macro_rules! point {
    () => {
        block!("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n")
    };
}

macro_rules! quaternion {
    () => {
        block!(
            "geometry_msgs/Quaternion",
            "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"
        )
    };
}

macro_rules! twist_fields {
    () => {
        "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n"
    };
}

macro_rules! transform_stamped {
    () => {
        concat!(
            block!(
                "geometry_msgs/TransformStamped",
                "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"
            ),
            header!(),
            block!(
                "geometry_msgs/Transform",
                "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"
            ),
            vector3!(),
            quaternion!()
        )
    };
}

/// `geometry_msgs/msg/Twist`.
pub const TWIST: &str = concat!(twist_fields!(), vector3!());

/// `geometry_msgs/msg/TwistStamped`.
pub const TWIST_STAMPED: &str = concat!(
    "std_msgs/Header header\ngeometry_msgs/Twist twist\n",
    header!(),
    block!("geometry_msgs/Twist", twist_fields!()),
    vector3!()
);

/// `std_msgs/msg/Float64`.
pub const FLOAT64: &str = "float64 data\n";

/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: &str = concat!(
    "std_msgs/Header header\nstring child_frame_id\n",
    "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n",
    header!(),
    block!(
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose pose\nfloat64[36] covariance\n"
    ),
    block!(
        "geometry_msgs/Pose",
        "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"
    ),
    point!(),
    quaternion!(),
    block!(
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist twist\nfloat64[36] covariance\n"
    ),
    block!("geometry_msgs/Twist", twist_fields!()),
    vector3!()
);

/// `rosgraph_msgs/msg/Clock`.
pub const CLOCK: &str = concat!("builtin_interfaces/Time clock\n", time!());

/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: &str = concat!(
    "geometry_msgs/TransformStamped[] transforms\n",
    transform_stamped!()
);

/// `sensor_msgs/msg/JointState`.
pub const JOINT_STATE: &str = concat!(
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    header!()
);

/// `sensor_msgs/msg/Image`.
pub const IMAGE: &str = concat!(
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n",
    "uint32 step\nuint8[] data\n",
    header!()
);

/// `sensor_msgs/msg/CameraInfo`.
pub const CAMERA_INFO: &str = concat!(
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n",
    "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\n",
    "sensor_msgs/RegionOfInterest roi\n",
    header!(),
    block!(
        "sensor_msgs/RegionOfInterest",
        "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"
    )
);

/// `sensor_msgs/msg/LaserScan`.
pub const LASER_SCAN: &str = concat!(
    "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n",
    "float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\n",
    "float32[] ranges\nfloat32[] intensities\n",
    header!()
);

/// `sensor_msgs/msg/PointCloud2`.
pub const POINT_CLOUD2: &str = concat!(
    "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n",
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
    header!(),
    block!(
        "sensor_msgs/PointField",
        "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n"
    )
);

/// `sensor_msgs/msg/Imu`.
pub const IMU: &str = concat!(
    "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n",
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n",
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n",
    "float64[9] linear_acceleration_covariance\n",
    header!(),
    quaternion!(),
    vector3!()
);

/// `sensor_msgs/msg/NavSatFix`.
pub const NAV_SAT_FIX: &str = concat!(
    "uint8 COVARIANCE_TYPE_UNKNOWN=0\nuint8 COVARIANCE_TYPE_APPROXIMATED=1\n",
    "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2\nuint8 COVARIANCE_TYPE_KNOWN=3\n",
    "std_msgs/Header header\nsensor_msgs/NavSatStatus status\nfloat64 latitude\n",
    "float64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\n",
    "uint8 position_covariance_type\n",
    header!(),
    block!(
        "sensor_msgs/NavSatStatus",
        "int8 STATUS_NO_FIX=-1\nint8 STATUS_FIX=0\nint8 STATUS_SBAS_FIX=1\nint8 STATUS_GBAS_FIX=2\nuint16 SERVICE_GPS=1\nuint16 SERVICE_GLONASS=2\nuint16 SERVICE_COMPASS=4\nuint16 SERVICE_GALILEO=8\nint8 status\nuint16 service\n"
    )
);

/// `geometry_msgs/msg/Vector3Stamped`.
pub const VECTOR3_STAMPED: &str = concat!(
    "std_msgs/Header header\ngeometry_msgs/Vector3 vector\n",
    header!(),
    vector3!()
);

/// `darknet_ros_msgs/msg/BoundingBoxes` (darknet_ros's ROS 2 branch).
pub const BOUNDING_BOXES: &str = concat!(
    "std_msgs/Header header\nstd_msgs/Header image_header\n",
    "darknet_ros_msgs/BoundingBox[] bounding_boxes\n",
    header!(),
    block!(
        "darknet_ros_msgs/BoundingBox",
        "float64 probability\nint64 xmin\nint64 ymin\nint64 xmax\nint64 ymax\nint16 id\nstring class_id\n"
    )
);

/// `darknet_ros_msgs/msg/ObjectCount`.
pub const OBJECT_COUNT: &str = concat!("std_msgs/Header header\nint8 count\n", header!());

/// `std_msgs/msg/String`.
pub const STRING: &str = "string data\n";

/// `gazebo_msgs/msg/ModelStates`.
pub const MODEL_STATES: &str = concat!(
    "string[] name\ngeometry_msgs/Pose[] pose\ngeometry_msgs/Twist[] twist\n",
    block!(
        "geometry_msgs/Pose",
        "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"
    ),
    point!(),
    quaternion!(),
    block!("geometry_msgs/Twist", twist_fields!()),
    vector3!()
);

/// `gazebo_msgs/msg/ContactsState`.
pub const CONTACTS_STATE: &str = concat!(
    "std_msgs/Header header\ngazebo_msgs/ContactState[] states\n",
    header!(),
    block!(
        "gazebo_msgs/ContactState",
        "string info\nstring collision1_name\nstring collision2_name\ngeometry_msgs/Wrench[] wrenches\ngeometry_msgs/Wrench total_wrench\ngeometry_msgs/Vector3[] contact_positions\ngeometry_msgs/Vector3[] contact_normals\nfloat64[] depths\n"
    ),
    block!(
        "geometry_msgs/Wrench",
        "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n"
    ),
    vector3!()
);

/// `geometry_msgs/msg/PointStamped`.
pub const POINT_STAMPED: &str = concat!(
    "std_msgs/Header header\ngeometry_msgs/Point point\n",
    header!(),
    point!()
);

/// `trajectory_msgs/msg/JointTrajectory`.
pub const JOINT_TRAJECTORY: &str = concat!(
    "std_msgs/Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint[] points\n",
    header!(),
    block!(
        "trajectory_msgs/JointTrajectoryPoint",
        "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\nfloat64[] effort\nbuiltin_interfaces/Duration time_from_start\n"
    ),
    block!("builtin_interfaces/Duration", "int32 sec\nuint32 nanosec\n")
);

/// `std_msgs/msg/Float64MultiArray`.
pub const FLOAT64_MULTI_ARRAY: &str = concat!(
    "std_msgs/MultiArrayLayout layout\nfloat64[] data\n",
    block!(
        "std_msgs/MultiArrayLayout",
        "std_msgs/MultiArrayDimension[] dim\nuint32 data_offset\n"
    ),
    block!(
        "std_msgs/MultiArrayDimension",
        "string label\nuint32 size\nuint32 stride\n"
    )
);

/// `pkg::msg::dds_::Type_` as `pkg/msg/Type`, the name ROS 2 tools give a type.
pub fn ros_type_name(dds_type: &str) -> String {
    dds_type
        .trim_end_matches('_')
        .replace("::dds_::", "::")
        .replace("::", "/")
}

/// `rcl_interfaces/msg/ParameterEvent`: a node's parameters as they appear, change or go.
pub const PARAMETER_EVENT: &str = concat!(
    "builtin_interfaces/Time stamp\nstring node\nParameter[] new_parameters\n",
    "Parameter[] changed_parameters\nParameter[] deleted_parameters\n",
    time!(),
    block!(
        "rcl_interfaces/Parameter",
        "string name\nParameterValue value\n"
    ),
    block!(
        "rcl_interfaces/ParameterValue",
        concat!(
            "uint8 type\nbool bool_value\nint64 integer_value\nfloat64 double_value\n",
            "string string_value\nbyte[] byte_array_value\nbool[] bool_array_value\n",
            "int64[] integer_array_value\nfloat64[] double_array_value\n",
            "string[] string_array_value\n"
        )
    )
);

/// `rcl_interfaces/msg/Log`: a node's log line, on `/rosout`.
pub const LOG: &str = concat!(
    "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n",
    "builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n",
    "string function\nuint32 line\n",
    time!()
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dds_type_names_become_ros_type_names() {
        assert_eq!(
            ros_type_name("geometry_msgs::msg::dds_::Twist_"),
            "geometry_msgs/msg/Twist"
        );
        assert_eq!(
            ros_type_name("tf2_msgs::msg::dds_::TFMessage_"),
            "tf2_msgs/msg/TFMessage"
        );
    }

    /// Every type a definition names is defined once in it.
    #[test]
    fn every_used_type_is_defined_once() {
        for def in [
            TWIST,
            TWIST_STAMPED,
            FLOAT64,
            ODOMETRY,
            CLOCK,
            TF_MESSAGE,
            JOINT_STATE,
            IMAGE,
            CAMERA_INFO,
            LASER_SCAN,
            IMU,
            NAV_SAT_FIX,
            VECTOR3_STAMPED,
            POINT_CLOUD2,
            CONTACTS_STATE,
            BOUNDING_BOXES,
            OBJECT_COUNT,
            STRING,
            MODEL_STATES,
            POINT_STAMPED,
            JOINT_TRAJECTORY,
            FLOAT64_MULTI_ARRAY,
            LOG,
        ] {
            let defined: Vec<&str> = def
                .lines()
                .filter_map(|l| l.strip_prefix("MSG: "))
                .collect();
            for used in def.lines().filter_map(|l| l.split_whitespace().next()) {
                let Some((pkg, name)) = used.trim_end_matches("[]").split_once('/') else {
                    continue;
                };
                let name = name.split('[').next().unwrap_or(name);
                let full = format!("{pkg}/{name}");
                let count = defined.iter().filter(|d| **d == full).count();
                assert_eq!(count, 1, "{full} defined {count} times in\n{def}");
            }
        }
    }
}
