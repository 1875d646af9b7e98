//! Real-data suite (`./build.sh test-real`): the rosbag2 `.db3` reader and
//! the message decoders on the two real SQLite bags of
//! `../shared/data/bags` (or `$SLAMLAB_DATA/bags`). Fails when the data is
//! missing.
//!
//! * `ros2/mit-csail-db3/`: the MIT CSAIL log as a rosbag2 (metadata
//!   version 9, CDR): 1988 scans of 361 beams over 180°, 1988 odometry
//!   messages, 1988 `/tf` and 2 `/tf_static` messages.
//! * `other/mumble-hallway_room_loop/`: an Isaac Sim robot (metadata
//!   version 5, an older `topics` table without `type_description_hash`):
//!   896 scans of 360 beams over 0..2π, 12 m, and 3698 IMU messages
//!   (listed, not decoded).
//!
//! Topics, types and counts must match each bag's `metadata.yaml`, every
//! LaserScan, Odometry and TFMessage must decode, and a few values were
//! checked against the `rosbags` Python package when the test was written.

#[path = "real_support/mod.rs"]
mod support;

use slamlab::formats::bag::messages::{
    laser_scan, stamped_pose, tf_message, LaserScanMsg, StampedPose,
};
use slamlab::formats::bag::rosbag2::{Db3Reader, Metadata};
use slamlab::formats::bag::{BagError, BagReader, MessageSink, RawMessage, ReadEnd, Topic};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

fn bag_dir(name: &str) -> PathBuf {
    let dir = support::data_dir().join("bags").join(name);
    assert!(
        dir.is_dir(),
        "real data not found: {} is missing",
        dir.display()
    );
    dir
}

/// Everything decoded from one bag.
#[derive(Default)]
struct Decoded {
    topics: Vec<Topic>,
    counts: BTreeMap<String, u64>,
    scans: Vec<LaserScanMsg>,
    odometry: Vec<StampedPose>,
    transforms: BTreeMap<String, Vec<StampedPose>>,
    log_times: Vec<u64>,
}

impl MessageSink for Decoded {
    fn topic(&mut self, topic: &Topic) {
        self.topics.push(topic.clone());
    }

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        let topic = self
            .topics
            .iter()
            .find(|t| t.id == m.topic)
            .ok_or_else(|| BagError::new(m.record, "a message of an unknown topic"))?;
        let fail = |e: String| BagError::new(m.record, e).on_topic(&topic.name);
        *self.counts.entry(topic.name.clone()).or_default() += 1;
        self.log_times.push(m.log_time_ns);
        match topic.msg_type.as_str() {
            "sensor_msgs/LaserScan" => self
                .scans
                .push(laser_scan(m.data, &topic.encoding).map_err(fail)?),
            "nav_msgs/Odometry" => self
                .odometry
                .push(stamped_pose(m.data, &topic.msg_type, &topic.encoding).map_err(fail)?),
            "tf2_msgs/TFMessage" => {
                let tf = tf_message(m.data, &topic.encoding).map_err(fail)?;
                self.transforms
                    .entry(topic.name.clone())
                    .or_default()
                    .extend(tf);
            }
            _ => {}
        }
        Ok(())
    }
}

/// Reads `<dir>/metadata.yaml` and its one `.db3`, pushed in 64 KB pieces;
/// returns the metadata, what was decoded, the end and the seconds taken.
fn read_bag(name: &str) -> (Metadata, Decoded, ReadEnd, f64) {
    let dir = bag_dir(name);
    let yaml = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    let meta = Metadata::parse(&yaml).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(meta.storage_identifier, "sqlite3");
    assert_eq!(meta.relative_file_paths.len(), 1);
    let path = dir.join(&meta.relative_file_paths[0]);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let start = Instant::now();
    let mut reader = Db3Reader::new().with_metadata(&meta).unwrap();
    let mut got = Decoded::default();
    for piece in bytes.chunks(65536) {
        reader.push(piece, &mut got).unwrap();
    }
    let end = reader
        .finish(&mut got)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let seconds = start.elapsed().as_secs_f64();
    eprintln!(
        "{name}: {} messages read and decoded in {:.1} ms",
        got.log_times.len(),
        seconds * 1e3
    );
    (meta, got, end, seconds)
}

/// The topics, types and counts agree with `metadata.yaml`; the messages
/// come in time order from the recording's start to its end.
fn matches_metadata(meta: &Metadata, got: &Decoded) {
    assert_eq!(got.topics.len(), meta.topics.len());
    for t in &meta.topics {
        let topic = got
            .topics
            .iter()
            .find(|g| g.name == t.name)
            .unwrap_or_else(|| panic!("topic {} missing", t.name));
        assert_eq!(topic.msg_type, t.msg_type, "{}", t.name);
        assert_eq!(
            got.counts.get(&t.name).copied().unwrap_or(0),
            t.message_count,
            "{}",
            t.name
        );
    }
    assert_eq!(got.log_times.len() as u64, meta.message_count);
    assert!(
        got.log_times.windows(2).all(|w| w[0] <= w[1]),
        "not in time order"
    );
    assert_eq!(got.log_times[0] as i64, meta.starting_time_ns);
    assert_eq!(
        got.log_times.last().unwrap() - got.log_times[0],
        meta.duration_ns
    );
}

#[test]
fn mit_csail_db3_reads_and_every_message_decodes() {
    let (meta, got, end, _) = read_bag("ros2/mit-csail-db3");
    assert_eq!(meta.version, 9);
    matches_metadata(&meta, &got);
    assert_eq!(end.lost, None);
    assert_eq!(end.compression, ["none"]);
    assert_eq!(got.scans.len(), 1988);
    assert_eq!(got.odometry.len(), 1988);
    assert_eq!(got.transforms["/tf"].len(), 1988);
    let first = &got.scans[0];
    assert_eq!(first.ranges.len(), 361);
    assert_eq!(first.angle_min, -std::f32::consts::FRAC_PI_2);
    assert_eq!(first.angle_max, std::f32::consts::FRAC_PI_2);
    assert_eq!(first.angle_increment, (std::f64::consts::PI / 360.0) as f32);
    assert_eq!(first.range_max, 81.9f32);
    assert_eq!(first.header.frame_id, "laser");
    assert_eq!(first.header.stamp_ns, 1_134_864_629_895_181_894);
    assert_eq!(&first.ranges[..3], &[1.4f32, 1.39, 1.39]);
    assert!(got.scans.iter().all(|s| s.ranges.len() == 361));
    let odom = &got.odometry[0];
    assert_eq!(
        (odom.header.frame_id.as_str(), odom.child_frame_id.as_str()),
        ("odom", "base_link")
    );
    assert_eq!(odom.pose.position, [576.536523, 0.106594, 0.0]);
    let q = odom.pose.orientation;
    assert!((q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0).abs() < 1e-9);
    let statics = &got.transforms["/tf_static"];
    assert!(
        statics
            .iter()
            .all(|t| (t.header.frame_id.as_str(), t.child_frame_id.as_str())
                == ("base_link", "laser"))
    );
    // Each /tf transform is the odometry's pose.
    for (tf, odom) in got.transforms["/tf"].iter().zip(&got.odometry) {
        assert_eq!(tf.child_frame_id, "base_link");
        assert_eq!(tf.pose, odom.pose);
    }
}

#[test]
fn mumble_hallway_db3_reads_and_every_scan_decodes() {
    let (meta, got, end, _) = read_bag("other/mumble-hallway_room_loop");
    assert_eq!(meta.version, 5);
    matches_metadata(&meta, &got);
    assert_eq!(end.lost, None);
    assert_eq!(got.counts["/imu_data"], 3698);
    assert_eq!(got.scans.len(), 896);
    for s in &got.scans {
        assert_eq!(s.ranges.len(), 360);
        assert_eq!(s.angle_min, 0.0);
        assert_eq!(s.angle_max, std::f32::consts::TAU);
        assert_eq!(s.range_max, 12.0);
        assert_eq!(s.header.frame_id, "laser_frame");
    }
    assert_eq!(got.scans[0].header.stamp_ns, 1_742_407_985_964_824_579);
}
