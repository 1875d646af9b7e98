//! # A bag read for the lab: every topic counted, a laser log built from it
//!
//! [`BagContents`] is the [`MessageSink`] a bag is read into, in one pass:
//! it counts every topic (what `bag-info` prints, as `ros2 bag info`
//! does) and decodes the messages a 2-D laser SLAM can use — every
//! `sensor_msgs/LaserScan` topic, every pose topic (`nav_msgs/Odometry`,
//! `geometry_msgs/PoseStamped`, `…/PoseWithCovarianceStamped`,
//! `…/TransformStamped`), `/tf` and `/tf_static`, and the last
//! `nav_msgs/OccupancyGrid` of each map topic. Everything else is counted
//! and never decoded, so a bag full of camera images costs only its
//! reading.
//!
//! Then [`BagContents::laser_log`] makes the log the SLAM replays, with
//! choices a user may override ([`Picks`]) and says what it chose and why
//! ([`Picked`]):
//!
//! * **the scan topic**: the one given, else the only `LaserScan` topic,
//!   else the one with the most messages;
//! * **the laser's pose on the robot**: the static transforms from the
//!   scan's `frame_id` up to the first frame that moves (the robot's base,
//!   the child of the odometry transform), composed; none when the scan's
//!   frame has no parent;
//! * **the odometry**: the `Odometry` topic given; else the only
//!   `Odometry` topic not named as ground truth (several: the one whose
//!   child frame is the base, else the one with the most messages); else
//!   the moving transform `odom → base` of `/tf`; else none — the SLAM then
//!   matches scan to map alone from a constant-velocity prediction
//!   (`--odom-frame NONE` forces that);
//! * **the ground truth**: the topic given, else a pose topic named as
//!   ground truth (`ground_truth`, `groundtruth`, `truth`, `gt`) or from a
//!   motion-capture system (`vicon`, `vrpn`, `optitrack`, `mocap`,
//!   `qualisys`). It is kept to score against and never reaches the SLAM.
//!
//! Each scan's odometry is the odometry interpolated at the scan's
//! `header.stamp` (linearly, the heading along the shorter way; the sample
//! itself where a stamp matches exactly; the first or last sample outside
//! their span). Its time is `header.stamp` in seconds.
//!
//! ## The same scans give the same answer
//!
//! A bag stores ranges and beam angles as `float32`, a CARMEN log as
//! decimal text, and poses as quaternions or as headings. Replayed through
//! a SLAM whose loop closures are yes/no decisions, a difference in the
//! last bit can become a different map. So every reader hands the SLAM
//! scans in one canonical form ([`crate::slam::logs::LogScan::canonical`]):
//! ranges rounded to `float32`, beam steps snapped to the `2π / N` of a
//! scanning laser's encoder when they are that close, poses to the
//! micrometre and microradian, times to the microsecond. This reader
//! builds every value from the message's own numbers and leaves the
//! rounding to that one function.

use super::messages::{self, LaserScanMsg, OccupancyGridMsg, Pose3, StampedPose};
use super::{BagError, Encoding, MessageSink, RawMessage, ReadEnd, Topic};
use crate::formats::rosmap::RosMap;
use crate::geom::{wrap_angle, Pose2};
use crate::slam::logs::LogScan;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// One topic as `bag-info` lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TopicInfo {
    pub name: String,
    /// Without ROS 2's `/msg/`: `sensor_msgs/LaserScan`.
    #[serde(rename = "type")]
    pub msg_type: String,
    /// `ros1`, `cdr`, or the container's own name for another encoding.
    pub encoding: String,
    pub count: u64,
    /// Log time of its first and last message (s).
    pub first_s: Option<f64>,
    pub last_s: Option<f64>,
}

/// A `LaserScan` as kept from the bag.
#[derive(Clone, Debug, PartialEq)]
struct ScanSample {
    stamp_ns: i64,
    frame_id: String,
    angle_min: f32,
    angle_increment: f32,
    range_max: f32,
    /// Ranges as the SLAM reads them ([`ranges_of`]).
    ranges: Arc<[f32]>,
}

/// A stamped 2-D pose.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PoseSample {
    stamp_ns: i64,
    pose: Pose2,
}

/// A pose topic: its frames (from its first message) and samples.
#[derive(Clone, Debug, Default, PartialEq)]
struct PoseTopic {
    msg_type: String,
    frame_id: String,
    child_frame_id: String,
    samples: Vec<PoseSample>,
}

/// Everything of a bag the lab reads, gathered as it streams past.
#[derive(Debug, Default)]
pub struct BagContents {
    /// Every topic, in order of first appearance.
    pub topics: Vec<TopicInfo>,
    /// The container's topic ids → index in `topics` (two ROS 1
    /// connections of one topic count as one topic).
    ids: HashMap<u32, (usize, Encoding)>,
    scans: BTreeMap<String, Vec<ScanSample>>,
    poses: BTreeMap<String, PoseTopic>,
    /// Moving transforms of `/tf`, by (parent, child).
    tf: BTreeMap<(String, String), Vec<PoseSample>>,
    /// Fixed transforms of `/tf_static`, by (parent, child).
    tf_static: BTreeMap<(String, String), Pose2>,
    /// The last map of each `OccupancyGrid` topic.
    maps: BTreeMap<String, OccupancyGridMsg>,
    /// Messages read.
    pub messages: u64,
    /// What the reader said at the end.
    pub end: ReadEnd,
}

/// A message's log time in seconds.
fn seconds(ns: u64) -> f64 {
    ns as f64 * 1e-9
}

/// The heading of a rotation about z (a 2-D robot's yaw), from a
/// quaternion `[x, y, z, w]`; roll and pitch are ignored.
pub fn yaw_of(q: &[f64; 4]) -> f64 {
    let [x, y, z, w] = *q;
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

fn pose2_of(p: &Pose3) -> Pose2 {
    Pose2::new(p.position[0], p.position[1], yaw_of(&p.orientation))
}

/// Strips a leading `/` (ROS 1 wrote `/base_link`, ROS 2 writes
/// `base_link`; tf treats them as one frame).
fn frame(name: &str) -> String {
    name.trim_start_matches('/').to_string()
}

/// True for a topic named as ground truth or coming from a motion-capture
/// system.
pub fn named_as_truth(topic: &str) -> bool {
    let t = topic.to_ascii_lowercase();
    let words = [
        "ground_truth",
        "groundtruth",
        "truth",
        "vicon",
        "vrpn",
        "optitrack",
        "mocap",
        "motion_capture",
        "qualisys",
    ];
    words.iter().any(|w| t.contains(w)) || t.split('/').any(|part| part == "gt")
}

/// The message types this module decodes.
const POSE_TYPES: [&str; 4] = [
    "nav_msgs/Odometry",
    "geometry_msgs/PoseStamped",
    "geometry_msgs/PoseWithCovarianceStamped",
    "geometry_msgs/TransformStamped",
];

impl BagContents {
    pub fn new() -> BagContents {
        BagContents::default()
    }

    fn decode(&mut self, index: usize, enc: &Encoding, data: &[u8]) -> Result<(), String> {
        let topic = &self.topics[index];
        let name = topic.name.clone();
        match topic.msg_type.as_str() {
            "sensor_msgs/LaserScan" => {
                let m: LaserScanMsg = messages::laser_scan(data, enc)?;
                self.scans.entry(name).or_default().push(ScanSample {
                    stamp_ns: m.header.stamp_ns,
                    frame_id: frame(&m.header.frame_id),
                    angle_min: m.angle_min,
                    angle_increment: m.angle_increment,
                    range_max: m.range_max,
                    ranges: ranges_of(&m),
                });
            }
            "tf2_msgs/TFMessage" | "tf/tfMessage" => {
                let fixed = name == "/tf_static" || name.ends_with("/tf_static");
                for t in messages::tf_message(data, enc)? {
                    self.add_transform(&t, fixed);
                }
            }
            "nav_msgs/OccupancyGrid" => {
                self.maps.insert(name, messages::occupancy_grid(data, enc)?);
            }
            t if POSE_TYPES.contains(&t) => {
                let m: StampedPose = messages::stamped_pose(data, t, enc)?;
                let msg_type = t.to_string();
                let entry = self.poses.entry(name).or_insert_with(|| PoseTopic {
                    msg_type,
                    frame_id: frame(&m.header.frame_id),
                    child_frame_id: frame(&m.child_frame_id),
                    samples: Vec::new(),
                });
                entry.samples.push(PoseSample {
                    stamp_ns: m.header.stamp_ns,
                    pose: pose2_of(&m.pose),
                });
            }
            _ => {}
        }
        Ok(())
    }

    fn add_transform(&mut self, t: &StampedPose, fixed: bool) {
        let key = (frame(&t.header.frame_id), frame(&t.child_frame_id));
        let pose = pose2_of(&t.pose);
        if fixed {
            self.tf_static.insert(key, pose);
        } else {
            self.tf.entry(key).or_default().push(PoseSample {
                stamp_ns: t.header.stamp_ns,
                pose,
            });
        }
    }

    /// The `LaserScan` topics and their message counts.
    pub fn scan_topics(&self) -> Vec<(String, usize)> {
        self.scans
            .iter()
            .map(|(k, v)| (k.clone(), v.len()))
            .collect()
    }

    /// Names of the topics holding an `OccupancyGrid`.
    pub fn map_topics(&self) -> Vec<String> {
        self.maps.keys().cloned().collect()
    }

    /// The last map of `topic` as a map the saved-maps merge takes
    /// (`name`: what reports call it). Cells are read as ROS 2's
    /// `map_saver` writes them: 0 to 25 free, 65 to 100 occupied, the rest
    /// (and −1) unknown.
    pub fn map(&self, topic: &str, name: &str) -> Result<RosMap, String> {
        let m = self
            .maps
            .get(topic)
            .ok_or_else(|| format!("no nav_msgs/OccupancyGrid on topic {topic}"))?;
        let data = m
            .data
            .iter()
            .map(|&v| match v {
                0..=25 => 0,
                65..=100 => 100,
                _ => -1,
            })
            .collect();
        RosMap::from_values(
            name,
            m.width as usize,
            m.height as usize,
            // The float32 as it was written (0.05, not 0.0500000007).
            m.resolution
                .to_string()
                .parse::<f64>()
                .unwrap_or(m.resolution as f64),
            pose2_of(&m.origin),
            data,
        )
        .map_err(|e| e.to_string())
    }

    /// Duration between the first and last message's log time (s).
    pub fn duration_s(&self) -> f64 {
        let first = self
            .topics
            .iter()
            .filter_map(|t| t.first_s)
            .reduce(f64::min);
        let last = self.topics.iter().filter_map(|t| t.last_s).reduce(f64::max);
        match (first, last) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }
}

impl MessageSink for BagContents {
    fn topic(&mut self, topic: &Topic) {
        let encoding = match &topic.encoding {
            Encoding::Ros1 => "ros1".to_string(),
            Encoding::Cdr => "cdr".to_string(),
            Encoding::Other(name) => name.clone(),
        };
        let index = match self
            .topics
            .iter()
            .position(|t| t.name == topic.name && t.msg_type == topic.msg_type)
        {
            Some(i) => i,
            None => {
                self.topics.push(TopicInfo {
                    name: topic.name.clone(),
                    msg_type: topic.msg_type.clone(),
                    encoding,
                    count: 0,
                    first_s: None,
                    last_s: None,
                });
                self.topics.len() - 1
            }
        };
        self.ids.insert(topic.id, (index, topic.encoding.clone()));
    }

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        let Some((index, enc)) = self.ids.get(&m.topic).cloned() else {
            return Err(BagError::new(
                m.record,
                format!(
                    "a message names topic id {}, which the bag never defined",
                    m.topic
                ),
            ));
        };
        self.messages += 1;
        let t = seconds(m.log_time_ns);
        let info = &mut self.topics[index];
        info.count += 1;
        info.first_s = Some(info.first_s.map_or(t, |f| f.min(t)));
        info.last_s = Some(info.last_s.map_or(t, |l| l.max(t)));
        let n = info.count;
        if matches!(enc, Encoding::Other(_)) {
            return Ok(());
        }
        self.decode(index, &enc, m.data).map_err(|e| {
            let info = &self.topics[index];
            BagError::new(
                m.record,
                format!(
                    "message {n} of the topic does not decode as {}: {e}",
                    info.msg_type
                ),
            )
            .on_topic(&info.name)
        })
    }
}

/// What the user asks of a bag's log (all optional).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Picks {
    /// The `LaserScan` topic to map.
    pub scan_topic: Option<String>,
    /// The `Odometry` (or other pose) topic to take as odometry; `tf`: the
    /// moving transform to the laser's base in `/tf`.
    pub odom_topic: Option<String>,
    /// No odometry at all: scan matching alone.
    pub odom_none: bool,
    /// The topic holding the ground truth.
    pub truth_topic: Option<String>,
    /// No ground truth, even where a topic is named as one.
    pub truth_none: bool,
}

/// What was picked, and why.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Picked {
    pub scan_topic: String,
    pub scan_reason: String,
    /// `/odom` (a topic), `tf odom → base_link`, or `None`.
    pub odometry: Option<String>,
    pub odometry_reason: String,
    pub truth_topic: Option<String>,
    pub truth_reason: String,
    /// The laser's frame, the robot's base frame, and the laser's pose on
    /// the base `[x, y, theta]`.
    pub laser_frame: String,
    pub base_frame: String,
    pub laser_offset: [f64; 3],
    pub offset_reason: String,
    /// What else there was to pick.
    pub scan_topics: Vec<String>,
    pub odometry_topics: Vec<String>,
    pub truth_topics: Vec<String>,
}

/// A bag's laser log, ready to replay.
#[derive(Clone, Debug, PartialEq)]
pub struct BagLog {
    /// The scans of the picked topic in the bag's order, canonical.
    pub scans: Vec<LogScan>,
    /// False when there is no odometry: `scans[].odometry` is then the
    /// identity and means nothing.
    pub has_odometry: bool,
    /// The ground truth `(time s, pose)`, in its own frame.
    pub truth: Vec<(f64, Pose2)>,
    pub picked: Picked,
}

/// The pose at `stamp` interpolated in `samples` (sorted by stamp): the
/// sample itself where a stamp matches, linear between the two around it
/// (the heading the shorter way), the first or last outside their span.
fn pose_at(samples: &[PoseSample], stamp: i64) -> Option<Pose2> {
    let first = samples.first()?;
    let k = samples.partition_point(|s| s.stamp_ns < stamp);
    if let Some(s) = samples.get(k).filter(|s| s.stamp_ns == stamp) {
        return Some(s.pose);
    }
    if k == 0 {
        return Some(first.pose);
    }
    let Some(b) = samples.get(k) else {
        return samples.last().map(|s| s.pose);
    };
    let a = &samples[k - 1];
    let u = (stamp - a.stamp_ns) as f64 / (b.stamp_ns - a.stamp_ns) as f64;
    let (p, q) = (a.pose, b.pose);
    Some(Pose2::new(
        p.x + u * (q.x - p.x),
        p.y + u * (q.y - p.y),
        wrap_angle(p.theta + u * wrap_angle(q.theta - p.theta)),
    ))
}

/// `samples` in stamp order (a bag holds them in log-time order, which
/// the stamps may not follow); equal stamps keep their order.
fn sorted(mut samples: Vec<PoseSample>) -> Vec<PoseSample> {
    samples.sort_by_key(|s| s.stamp_ns);
    samples
}

impl BagContents {
    /// The parent of `child` among the fixed transforms (and the moving
    /// ones that never move: a `/tf` edge published at a rate but always
    /// the same), with the transform.
    fn fixed_parent(&self, child: &str) -> Option<(String, Pose2)> {
        if let Some(((p, _), pose)) = self.tf_static.iter().find(|((_, c), _)| c == child) {
            return Some((p.clone(), *pose));
        }
        self.tf
            .iter()
            .find(|((_, c), s)| c == child && s.windows(2).all(|w| w[0].pose == w[1].pose))
            .and_then(|((p, _), s)| s.first().map(|f| (p.clone(), f.pose)))
    }

    /// The moving transform whose child is `child`: its parent.
    fn moving_parent(&self, child: &str) -> Option<&(String, String)> {
        self.tf
            .iter()
            .find(|((_, c), s)| c == child && s.windows(2).any(|w| w[0].pose != w[1].pose))
            .map(|(k, _)| k)
    }

    /// The laser's pose on the robot's base: the fixed transforms from the
    /// scan's frame up to the first frame with a moving parent (or with no
    /// parent), composed. Returns (base frame, offset, reason).
    fn laser_offset(&self, laser: &str) -> (String, Pose2, String) {
        let mut offset = Pose2::IDENTITY;
        let mut at = laser.to_string();
        let mut chain = vec![at.clone()];
        for _ in 0..16 {
            if self.moving_parent(&at).is_some() {
                break;
            }
            let Some((parent, pose)) = self.fixed_parent(&at) else {
                break;
            };
            offset = pose.compose(&offset);
            at = parent;
            chain.push(at.clone());
        }
        let reason = if chain.len() == 1 {
            if laser.is_empty() {
                "the scans name no frame: the laser is taken to sit at the robot's origin".into()
            } else {
                format!("no transform names {laser} as its child: the laser is taken to sit at the robot's origin")
            }
        } else {
            chain.reverse();
            format!("the fixed transforms {}", chain.join(" → "))
        };
        (at, offset, reason)
    }

    /// The laser log of the bag, as `picks` asks.
    pub fn laser_log(&self, picks: &Picks) -> Result<BagLog, String> {
        let mut picked = self.candidates();
        let scan_topic = self.pick_scan_topic(picks, &mut picked)?;
        let samples = &self.scans[&scan_topic];
        let laser = samples
            .first()
            .map(|s| s.frame_id.clone())
            .unwrap_or_default();
        let (base, offset, offset_reason) = self.laser_offset(&laser);
        picked.laser_frame = laser;
        picked.base_frame = base.clone();
        picked.laser_offset = [offset.x, offset.y, offset.theta];
        picked.offset_reason = offset_reason;
        let odometry = self.pick_odometry(picks, &base, &mut picked)?;
        let truth = self.pick_truth(picks, &mut picked)?;
        let mut scans = Vec::with_capacity(samples.len());
        for (k, s) in samples.iter().enumerate() {
            let odometry = odometry
                .as_ref()
                .and_then(|o| pose_at(o, s.stamp_ns))
                .unwrap_or(Pose2::IDENTITY);
            let scan = log_scan(k, s, odometry, offset)
                .canonical()
                .map_err(|e| format!("{scan_topic}, message {}: {e}", k + 1))?;
            scans.push(scan);
        }
        Ok(BagLog {
            scans,
            has_odometry: odometry.is_some(),
            truth,
            picked,
        })
    }

    /// The topics there are to pick from: `LaserScan` topics, `Odometry`
    /// topics not named as ground truth, and the other pose topics.
    fn candidates(&self) -> Picked {
        let mut picked = Picked {
            scan_topics: self.scans.keys().cloned().collect(),
            ..Picked::default()
        };
        for (name, t) in &self.poses {
            if t.msg_type == "nav_msgs/Odometry" && !named_as_truth(name) {
                picked.odometry_topics.push(name.clone());
            } else {
                picked.truth_topics.push(name.clone());
            }
        }
        picked
    }

    /// The scan topic: the one given, the only one, or the one with the
    /// most messages.
    fn pick_scan_topic(&self, picks: &Picks, picked: &mut Picked) -> Result<String, String> {
        let (topic, reason) = match &picks.scan_topic {
            Some(t) if self.scans.contains_key(t) => (t.clone(), "given".to_string()),
            Some(t) => {
                return Err(format!(
                    "--scan-topic {t}: no sensor_msgs/LaserScan messages on that topic (LaserScan topics: {})",
                    list(&picked.scan_topics)
                ))
            }
            None if self.scans.is_empty() => {
                let all: Vec<String> = self
                    .topics
                    .iter()
                    .map(|t| format!("{} ({})", t.name, t.msg_type))
                    .collect();
                return Err(format!(
                    "no sensor_msgs/LaserScan topic in the bag (its {} topics: {})",
                    all.len(),
                    list(&all)
                ));
            }
            None if self.scans.len() == 1 => (
                picked.scan_topics[0].clone(),
                "the bag's only LaserScan topic".to_string(),
            ),
            None => {
                let (t, v) = self
                    .scans
                    .iter()
                    .max_by_key(|(name, v)| (v.len(), std::cmp::Reverse((*name).clone())))
                    .ok_or("no scans")?;
                (
                    t.clone(),
                    format!(
                        "the LaserScan topic with the most messages ({} of {} topics)",
                        v.len(),
                        self.scans.len()
                    ),
                )
            }
        };
        if self.scans[&topic].is_empty() {
            return Err(format!("{topic}: no messages"));
        }
        picked.scan_topic = topic.clone();
        picked.scan_reason = reason;
        Ok(topic)
    }

    /// The odometry samples (in stamp order), or `None` for scan matching
    /// alone.
    fn pick_odometry(
        &self,
        picks: &Picks,
        base: &str,
        picked: &mut Picked,
    ) -> Result<Option<Vec<PoseSample>>, String> {
        let topic = |t: &str| Some(sorted(self.poses[t].samples.clone()));
        if picks.odom_none {
            picked.odometry_reason = "--odom-frame NONE: scan matching alone".into();
            return Ok(None);
        }
        if picks.odom_topic.as_deref() == Some("tf") {
            let Some((parent, child)) = self.moving_parent(base) else {
                return Err(format!(
                    "--odom-topic tf: no moving transform in /tf ends at the laser's base {base}"
                ));
            };
            picked.odometry = Some(format!("tf {parent} → {child}"));
            picked.odometry_reason = "given: the moving transform of /tf".into();
            return Ok(Some(sorted(
                self.tf[&(parent.clone(), child.clone())].clone(),
            )));
        }
        if let Some(t) = &picks.odom_topic {
            if !self.poses.contains_key(t) {
                return Err(format!(
                    "--odom-topic {t}: no Odometry or pose messages on that topic (Odometry topics: {})",
                    list(&picked.odometry_topics)
                ));
            }
            picked.odometry = Some(t.clone());
            picked.odometry_reason = "given".into();
            return Ok(topic(t));
        }
        let odoms = &picked.odometry_topics;
        if !odoms.is_empty() {
            let by_base: Vec<&String> = odoms
                .iter()
                .filter(|t| self.poses[*t].child_frame_id == base)
                .collect();
            let (t, why) = if odoms.len() == 1 {
                (
                    odoms[0].clone(),
                    "the bag's only Odometry topic not named as ground truth".to_string(),
                )
            } else if by_base.len() == 1 {
                (
                    by_base[0].clone(),
                    format!("the Odometry topic whose child frame is the laser's base {base}"),
                )
            } else {
                let most = odoms
                    .iter()
                    .max_by_key(|t| {
                        (
                            self.poses[*t].samples.len(),
                            std::cmp::Reverse((*t).clone()),
                        )
                    })
                    .cloned()
                    .unwrap_or_default();
                (
                    most,
                    "the Odometry topic with the most messages".to_string(),
                )
            };
            picked.odometry = Some(t.clone());
            picked.odometry_reason = why;
            return Ok(topic(&t));
        }
        if let Some((parent, child)) = self.moving_parent(base) {
            picked.odometry = Some(format!("tf {parent} → {child}"));
            picked.odometry_reason =
                format!("no Odometry topic: the moving transform {parent} → {child} of /tf");
            return Ok(Some(sorted(
                self.tf[&(parent.clone(), child.clone())].clone(),
            )));
        }
        picked.odometry_reason = "no Odometry topic and no moving transform to the laser's base: scan matching alone, from a constant-velocity prediction".into();
        Ok(None)
    }

    /// The ground truth `(time s, pose)`: the topic given, else the first
    /// pose topic named as ground truth, else none.
    fn pick_truth(&self, picks: &Picks, picked: &mut Picked) -> Result<Vec<(f64, Pose2)>, String> {
        if picks.truth_none {
            picked.truth_reason = "none, as asked".into();
            return Ok(Vec::new());
        }
        let topic = match &picks.truth_topic {
            Some(t) if self.poses.contains_key(t) => {
                picked.truth_reason = "given".into();
                t.clone()
            }
            Some(t) => {
                return Err(format!(
                "--truth-topic {t}: no Odometry or pose messages on that topic (pose topics: {})",
                list(&self.poses.keys().cloned().collect::<Vec<_>>())
            ))
            }
            None => match picked
                .truth_topics
                .iter()
                .find(|t| named_as_truth(t) && picked.odometry.as_deref() != Some(t.as_str()))
            {
                Some(t) => {
                    picked.truth_reason = "a pose topic named as ground truth".into();
                    t.clone()
                }
                None => {
                    picked.truth_reason = "no topic named as ground truth".into();
                    return Ok(Vec::new());
                }
            },
        };
        if picked.odometry.as_deref() == Some(topic.as_str()) {
            return Err(format!(
                "{topic} cannot be both the odometry and the ground truth"
            ));
        }
        picked.truth_topic = Some(topic.clone());
        Ok(sorted(self.poses[&topic].samples.clone())
            .into_iter()
            .map(|s| (s.stamp_ns as f64 * 1e-9, s.pose))
            .collect())
    }
}

/// A scan's ranges as the SLAM reads them: below `range_min`, NaN or −∞
/// become NaN (no reading: neither a wall nor free space); above
/// `range_max` or +∞ become +∞ (nothing within range).
fn ranges_of(m: &LaserScanMsg) -> Arc<[f32]> {
    m.ranges
        .iter()
        .map(|&r| {
            if r.is_nan() || r < m.range_min || r == f32::NEG_INFINITY {
                f32::NAN
            } else if r > m.range_max {
                f32::INFINITY
            } else {
                r
            }
        })
        .collect()
}

/// Scan `k` of a topic as the SLAM's scan, before its canonical rounding
/// (its ranges shared with the bag's contents).
fn log_scan(k: usize, s: &ScanSample, odometry: Pose2, offset: Pose2) -> LogScan {
    LogScan {
        index: k,
        line: k + 1,
        time: s.stamp_ns as f64 * 1e-9,
        start_angle: s.angle_min as f64,
        angle_step: s.angle_increment as f64,
        max_range: s.range_max as f64,
        ranges: Arc::clone(&s.ranges),
        odometry,
        logged_pose: None,
        laser_offset: offset,
    }
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
