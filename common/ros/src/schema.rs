//! The ros2msg definitions of every type Tactile publishes, as the ROS 2 Jazzy
//! interface files define their fields (comments and default values left out), and
//! the schema text MCAP and rosbag2 store: the type's definition, then each type it
//! uses, once, after a line of 80 `=` and `MSG: pkg/Type`.

/// `(name, definition)` of each type, `pkg/Type` as field declarations spell them.
pub const DEFINITIONS: &[(&str, &str)] = &[
    ("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"),
    ("builtin_interfaces/Duration", "int32 sec\nuint32 nanosec\n"),
    ("std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"),
    ("std_msgs/String", "string data\n"),
    ("std_msgs/ColorRGBA", "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n"),
    ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
    ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
    ("geometry_msgs/Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"),
    (
        "geometry_msgs/Pose",
        "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    ),
    (
        "geometry_msgs/PoseStamped",
        "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
    ),
    (
        "geometry_msgs/Wrench",
        "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n",
    ),
    (
        "geometry_msgs/WrenchStamped",
        "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n",
    ),
    (
        "geometry_msgs/Transform",
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    ),
    (
        "geometry_msgs/TransformStamped",
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    ),
    ("tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"),
    (
        "sensor_msgs/JointState",
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    ),
    (
        "sensor_msgs/CompressedImage",
        "std_msgs/Header header\nstring format\nuint8[] data\n",
    ),
    ("visualization_msgs/UVCoordinate", "float32 u\nfloat32 v\n"),
    ("visualization_msgs/MeshFile", "string filename\nuint8[] data\n"),
    (
        "visualization_msgs/Marker",
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
         int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
         int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n\
         int32 ARROW_STRIP=12\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
         std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
         geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
         builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
         std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n\
         visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
         visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    ),
    (
        "visualization_msgs/MarkerArray",
        "visualization_msgs/Marker[] markers\n",
    ),
    (
        "std_msgs/MultiArrayDimension",
        "string label\nuint32 size\nuint32 stride\n",
    ),
    (
        "std_msgs/MultiArrayLayout",
        "std_msgs/MultiArrayDimension[] dim\nuint32 data_offset\n",
    ),
    (
        "std_msgs/Float64MultiArray",
        "std_msgs/MultiArrayLayout layout\nfloat64[] data\n",
    ),
    (
        "trajectory_msgs/JointTrajectoryPoint",
        "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\nfloat64[] effort\n\
         builtin_interfaces/Duration time_from_start\n",
    ),
    (
        "trajectory_msgs/JointTrajectory",
        "std_msgs/Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint[] points\n",
    ),
    ("std_msgs/Bool", "bool data\n"),
    (
        "sensor_msgs/Joy",
        "std_msgs/Header header\nfloat32[] axes\nint32[] buttons\n",
    ),
    // The omni_common drivers' own (omni_msgs/msg/*.msg).
    ("omni_msgs/OmniButtonEvent", "int32 grey_button\nint32 white_button\n"),
    (
        "omni_msgs/OmniFeedback",
        "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 position\n",
    ),
    (
        "tactile_msgs/SampleTiming",
        "uint64 sample\nbool answered\nint64 round_trip_ns\nint64 overhead_ns\n\
         uint32[3] delay_forward\nuint32[3] delay_backward\nuint32 flags_forward\n\
         uint32 flags_backward\nuint32 flags_master\nfloat64[3] observer_master\n\
         float64[3] observer_slave\n",
    ),
];

/// The definition of `name` (`pkg/Type` or `pkg/msg/Type`).
pub fn definition(name: &str) -> Option<&'static str> {
    let short = name.replacen("/msg/", "/", 1);
    DEFINITIONS
        .iter()
        .find(|(n, _)| *n == short)
        .map(|(_, d)| *d)
}

/// The complex types a definition's fields use, in order.
fn uses(def: &str) -> impl Iterator<Item = &str> {
    def.lines().filter_map(|l| {
        let ty = l.split_whitespace().next()?;
        let ty = ty.split('[').next()?;
        ty.contains('/').then_some(ty)
    })
}

/// The ros2msg schema of `name` (`pkg/msg/Type`): its definition, then every type it
/// uses, depth first, each once. `None` for a type this crate does not define.
pub fn ros2msg(name: &str) -> Option<String> {
    let mut text = definition(name)?.to_string();
    let mut seen: Vec<&str> = Vec::new();
    let mut todo: Vec<&str> = uses(definition(name)?).collect();
    todo.reverse();
    while let Some(t) = todo.pop() {
        if seen.contains(&t) {
            continue;
        }
        seen.push(t);
        let d = definition(t)?;
        text.push_str(&"=".repeat(80));
        text.push_str("\nMSG: ");
        text.push_str(t);
        text.push('\n');
        text.push_str(d);
        let mut more: Vec<&str> = uses(d).collect();
        more.reverse();
        todo.extend(more);
    }
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_used_type_is_defined() {
        for (name, def) in DEFINITIONS {
            for t in uses(def) {
                assert!(definition(t).is_some(), "{name} uses undefined {t}");
            }
        }
    }

    #[test]
    fn a_schema_lists_each_dependency_once() {
        let s = ros2msg("geometry_msgs/msg/WrenchStamped").expect("defined");
        assert!(s.starts_with("std_msgs/Header header\n"));
        assert_eq!(s.matches("MSG: geometry_msgs/Vector3\n").count(), 1);
        assert_eq!(s.matches("MSG: builtin_interfaces/Time\n").count(), 1);
        assert_eq!(ros2msg("foo_msgs/msg/Bar"), None);
    }
}
