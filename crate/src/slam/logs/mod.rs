//! # SLAM for recorded laser logs
//!
//! A log (a CARMEN file or a ROS bag, read by [`crate::formats`]) is a list
//! of [`LogScan`]s with the odometry at each; [`logslam`] replays them in
//! order through scan-to-map matching, a pose graph and loop closures.
//!
//! | stage | file | follows |
//! |---|---|---|
//! | one scan of a log, its beams and poses | [`scan`] | — |
//! | the replay: matching, key scans, loop closures | [`logslam`] | Karto / slam_toolbox, Cartographer |
//! | the smoothed scans fused with the odometry, noises measured from the log | [`fusion`] | a fixed-interval smoother; the Allan variance's lag fit |

pub mod fusion;
pub mod logslam;
pub mod scan;

pub use logslam::{LogSlam, LogSlamConfig};
pub use scan::LogScan;
