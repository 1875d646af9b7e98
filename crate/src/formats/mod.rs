//! # File formats: robots' files read into the lab's own types
//!
//! Every reader takes bytes (the CLI reads them from disk, the page from a
//! file picker) and returns the lab's types, so the algorithms never see a
//! file format and the same data gives the same answer whichever file it
//! came in.
//!
//! | format | module | gives |
//! |---|---|---|
//! | CARMEN laser logs (`.log`, `.clf`, gzip or not) | [`carmen`] | [`crate::slam::logs::LogScan`]s |
//! | ROS `map_server` maps (YAML + PGM / PNG) | [`rosmap`] | [`rosmap::RosMap`] |
//! | ROS bags: ROS 1 `.bag`, MCAP, rosbag2 `.db3` | [`bag`] | topics and decoded messages |

pub mod bag;
pub mod carmen;
pub mod rosmap;
