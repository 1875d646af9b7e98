//! # The ROS messages the lab reads, whatever their encoding
//!
//! Plain structs for the few message types a 2-D laser SLAM needs. Only the
//! fields the lab uses are kept (no covariances, no twist, no intensities).
//! Times are `header.stamp` in nanoseconds (ROS 1's `time` is unsigned
//! seconds and nanoseconds, ROS 2's `builtin_interfaces/Time` signed
//! seconds and unsigned nanoseconds; both fit an `i64` of nanoseconds).

/// `std_msgs/Header` (ROS 1's `seq` is read and dropped).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Header {
    pub stamp_ns: i64,
    pub frame_id: String,
}

/// `sensor_msgs/LaserScan`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LaserScanMsg {
    pub header: Header,
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
}

/// A position and an orientation (`geometry_msgs/Pose`, or a
/// `geometry_msgs/Transform`'s translation and rotation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose3 {
    pub position: [f64; 3],
    /// Quaternion `[x, y, z, w]`.
    pub orientation: [f64; 4],
}

/// `nav_msgs/Odometry` (pose only), `geometry_msgs/PoseStamped`,
/// `geometry_msgs/PoseWithCovarianceStamped` (pose only) and
/// `geometry_msgs/TransformStamped`: a stamped pose of `child_frame_id` in
/// `header.frame_id` (`child_frame_id` empty where the type has none).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StampedPose {
    pub header: Header,
    pub child_frame_id: String,
    pub pose: Pose3,
}

/// `nav_msgs/OccupancyGrid`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OccupancyGridMsg {
    pub header: Header,
    /// m per cell.
    pub resolution: f32,
    pub width: u32,
    pub height: u32,
    /// The pose of cell (0, 0)'s corner in `header.frame_id`.
    pub origin: Pose3,
    /// Row-major from the origin's row: −1 unknown, 0..100 occupancy.
    pub data: Vec<i8>,
}
