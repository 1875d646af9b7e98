//! # The ROS messages the lab reads, whatever their encoding
//!
//! Plain structs for the few message types a 2-D laser SLAM needs. Only the
//! fields the lab uses are kept (no covariances, no twist, no intensities).
//! Times are `header.stamp` in nanoseconds (ROS 1's `time` is unsigned
//! seconds and nanoseconds, ROS 2's `builtin_interfaces/Time` signed
//! seconds and unsigned nanoseconds; both fit an `i64` of nanoseconds).
//!
//! ## Decoding: two serialisations of the same fields
//!
//! A message is its fields in the order of its `.msg` definition, nested
//! messages inline, in one of two encodings ([`Encoding`]):
//!
//! * **ROS 1** (<http://wiki.ros.org/msg#Serialization>, "Message
//!   serialization and msg MD5 sums"): little-endian, packed with no
//!   padding; a string is a `u32` byte count and the bytes; a variable
//!   array a `u32` element count and the elements; a fixed array
//!   (`float64[36]`) just the elements. `std_msgs/Header` is
//!   `uint32 seq`, `time stamp` (`u32` seconds, `u32` nanoseconds),
//!   `string frame_id`.
//! * **CDR**, as ROS 2 middlewares write it (OMG DDS-XTypes 1.3, §7.4.3,
//!   "XCDR version 1"): a 4-byte encapsulation header first, `00 01` for
//!   little-endian data and `00 00` for big-endian (two option bytes
//!   follow); then each primitive starts at a multiple of its own size (1,
//!   2, 4 or 8 bytes), counted from the byte after the encapsulation
//!   header, with zero padding before it. A string is a `u32` length that
//!   counts a trailing NUL, then the bytes and the NUL; a sequence a `u32`
//!   count and the elements. ROS 2's `std_msgs/Header` has no `seq`: it is
//!   `builtin_interfaces/Time` (`i32 sec`, `u32 nanosec`) and `frame_id`.
//!   Other encapsulations (parameter lists, XCDR2) are refused by name.
//!
//! The decoders ([`laser_scan`], [`stamped_pose`], [`tf_message`],
//! [`occupancy_grid`], [`header`]) walk the bytes once with a cursor that
//! checks every read against the bytes left, and every count before it
//! allocates anything, so a cut or lying message is an error naming the
//! field and the byte ("ranges: 361 floats claimed at byte 52, only 1200
//! bytes left"), never a panic or a huge allocation. The only allocations
//! are the strings and the arrays kept (`ranges`, the grid's cells).

use super::Encoding;

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

/// Reads a message's fields in order, in ROS 1 serialisation or CDR.
///
/// ROS 1: packed little-endian, no padding, `u32` lengths. CDR: after the
/// 4-byte encapsulation header, each primitive starts at a multiple of its
/// own size counted from the byte after that header, in the byte order
/// the header names. Every read checks the bytes left first; an error
/// names the field and the byte it starts at.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Where alignment is counted from (4 in CDR).
    origin: usize,
    /// CDR aligns; ROS 1 does not.
    aligned: bool,
    big_endian: bool,
    /// ROS 1's `Header` has a `seq` and an unsigned `time`.
    ros1: bool,
}

/// The name of a CDR encapsulation kind (OMG XTypes 1.3, 7.6.3.1.2).
fn encapsulation_name(kind: u16) -> &'static str {
    match kind {
        0x0002 => "PL_CDR_BE",
        0x0003 => "PL_CDR_LE",
        0x0006 => "CDR2_BE",
        0x0007 => "CDR2_LE",
        0x0008 => "D_CDR2_BE",
        0x0009 => "D_CDR2_LE",
        0x000a => "PL_CDR2_BE",
        0x000b => "PL_CDR2_LE",
        _ => "unknown",
    }
}

impl<'a> Cursor<'a> {
    fn new(data: &'a [u8], enc: &Encoding) -> Result<Cursor<'a>, String> {
        match enc {
            Encoding::Ros1 => Ok(Cursor {
                data,
                pos: 0,
                origin: 0,
                aligned: false,
                big_endian: false,
                ros1: true,
            }),
            Encoding::Cdr => {
                let head = data.get(..4).ok_or_else(|| {
                    format!(
                        "the CDR encapsulation header needs 4 bytes, the message has {}",
                        data.len()
                    )
                })?;
                let big_endian = match (head[0], head[1]) {
                    (0, 1) => false,
                    (0, 0) => true,
                    (a, b) => {
                        let kind = u16::from_be_bytes([a, b]);
                        return Err(format!(
                            "CDR encapsulation {kind:#06x} ({}) is not read: only plain CDR, \
                             00 01 (little-endian) or 00 00 (big-endian)",
                            encapsulation_name(kind)
                        ));
                    }
                };
                Ok(Cursor {
                    data,
                    pos: 4,
                    origin: 4,
                    aligned: true,
                    big_endian,
                    ros1: false,
                })
            }
            Encoding::Other(e) => Err(format!("messages encoded as {e:?} are not decoded")),
        }
    }

    fn left(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// Skips CDR padding to a multiple of `size` from the origin.
    fn align(&mut self, size: usize) {
        if self.aligned {
            let rel = self.pos - self.origin;
            self.pos += (size - rel % size) % size;
        }
    }

    /// `n` bytes of `field`.
    fn take(&mut self, n: usize, field: &str) -> Result<&'a [u8], String> {
        let bytes = self
            .pos
            .checked_add(n)
            .and_then(|end| self.data.get(self.pos..end))
            .ok_or_else(|| {
                format!(
                    "{field}: {n} bytes needed at byte {}, only {} left",
                    self.pos,
                    self.left()
                )
            })?;
        self.pos += n;
        Ok(bytes)
    }

    fn word<const N: usize>(&mut self, field: &str) -> Result<[u8; N], String> {
        self.align(N);
        let b = self.take(N, field)?;
        let mut w = [0u8; N];
        w.copy_from_slice(b);
        if self.big_endian {
            w.reverse();
        }
        // Little-endian from here on.
        Ok(w)
    }

    fn u32(&mut self, field: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.word::<4>(field)?))
    }

    fn i32(&mut self, field: &str) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.word::<4>(field)?))
    }

    fn f32(&mut self, field: &str) -> Result<f32, String> {
        Ok(f32::from_le_bytes(self.word::<4>(field)?))
    }

    fn f64(&mut self, field: &str) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.word::<8>(field)?))
    }

    /// A sequence's (or string's) length, checked against the bytes left
    /// at (at least) `size` bytes an element, before anything is allocated.
    fn count(&mut self, field: &str, size: usize, what: &str) -> Result<usize, String> {
        self.align(4);
        let at = self.pos;
        let n = self.u32(field)? as usize;
        if n.checked_mul(size).is_none_or(|need| need > self.left()) {
            return Err(format!(
                "{field}: {n} {what} claimed at byte {at}, only {} bytes left",
                self.left()
            ));
        }
        Ok(n)
    }

    /// A string: ROS 1 without a terminator, CDR with its length counting
    /// a trailing NUL.
    fn string(&mut self, field: &str) -> Result<String, String> {
        let n = self.count(field, 1, "string bytes")?;
        let at = self.pos;
        let mut bytes = self.take(n, field)?;
        if !self.ros1 {
            if let [head @ .., 0] = bytes {
                bytes = head;
            }
        }
        std::str::from_utf8(bytes)
            .map(str::to_string)
            .map_err(|_| format!("{field}: the string at byte {at} is not UTF-8"))
    }

    /// Skips `n` elements of `size` bytes (aligned to `size`).
    fn skip(&mut self, n: usize, size: usize, field: &str) -> Result<(), String> {
        self.align(size.min(8));
        self.take(n * size, field).map(|_| ())
    }

    /// A `float32[]`.
    fn f32_seq(&mut self, field: &str) -> Result<Vec<f32>, String> {
        let n = self.count(field, 4, "floats")?;
        let bytes = self.take(n * 4, field)?;
        let (words, _) = bytes.as_chunks::<4>();
        Ok(if self.big_endian {
            words.iter().map(|w| f32::from_be_bytes(*w)).collect()
        } else {
            words.iter().map(|w| f32::from_le_bytes(*w)).collect()
        })
    }

    /// `std_msgs/Header`: ROS 1 `seq`, `time` (u32 sec, u32 nsec); ROS 2
    /// `builtin_interfaces/Time` (i32 sec, u32 nanosec); `frame_id`.
    fn header(&mut self) -> Result<Header, String> {
        if self.ros1 {
            self.u32("header.seq")?;
        }
        let stamp_ns = self.time("header.stamp")?;
        let frame_id = self.string("header.frame_id")?;
        Ok(Header { stamp_ns, frame_id })
    }

    /// A `time` in nanoseconds.
    fn time(&mut self, field: &str) -> Result<i64, String> {
        let sec = if self.ros1 {
            self.u32(field)? as i64
        } else {
            self.i32(field)? as i64
        };
        let nsec = self.u32(field)? as i64;
        Ok(sec * 1_000_000_000 + nsec)
    }

    /// `geometry_msgs/Pose` (or a `Transform`: a `Vector3` and a
    /// `Quaternion`, the same seven `float64`s).
    fn pose(&mut self, field: &str) -> Result<Pose3, String> {
        let mut p = Pose3::default();
        for v in p.position.iter_mut() {
            *v = self.f64(field)?;
        }
        for v in p.orientation.iter_mut() {
            *v = self.f64(field)?;
        }
        Ok(p)
    }

    /// `geometry_msgs/TransformStamped`.
    fn transform_stamped(&mut self) -> Result<StampedPose, String> {
        let header = self.header()?;
        let child_frame_id = self.string("child_frame_id")?;
        let pose = self.pose("transform")?;
        Ok(StampedPose {
            header,
            child_frame_id,
            pose,
        })
    }
}

/// `sensor_msgs/LaserScan`: header, seven `float32`s (angle_min,
/// angle_max, angle_increment, time_increment, scan_time, range_min,
/// range_max), `float32[] ranges`, `float32[] intensities` (checked for
/// length, not kept).
pub fn laser_scan(data: &[u8], enc: &Encoding) -> Result<LaserScanMsg, String> {
    let mut c = Cursor::new(data, enc)?;
    let header = c.header()?;
    let mut scan = LaserScanMsg {
        header,
        angle_min: c.f32("angle_min")?,
        angle_max: c.f32("angle_max")?,
        angle_increment: c.f32("angle_increment")?,
        time_increment: c.f32("time_increment")?,
        scan_time: c.f32("scan_time")?,
        range_min: c.f32("range_min")?,
        range_max: c.f32("range_max")?,
        ranges: Vec::new(),
    };
    scan.ranges = c.f32_seq("ranges")?;
    let n = c.count("intensities", 4, "floats")?;
    c.skip(n, 4, "intensities")?;
    Ok(scan)
}

/// The type name without ROS 2's `/msg/`.
fn plain_type(msg_type: &str) -> String {
    msg_type.replacen("/msg/", "/", 1)
}

/// A stamped pose from `nav_msgs/Odometry` (header, child_frame_id,
/// pose.pose; the pose's covariance and the twist are checked for length,
/// not kept), `geometry_msgs/PoseStamped`,
/// `geometry_msgs/PoseWithCovarianceStamped` or
/// `geometry_msgs/TransformStamped`. `msg_type` may carry ROS 2's `/msg/`.
pub fn stamped_pose(data: &[u8], msg_type: &str, enc: &Encoding) -> Result<StampedPose, String> {
    let kind = plain_type(msg_type);
    const KNOWN: [&str; 4] = [
        "nav_msgs/Odometry",
        "geometry_msgs/PoseStamped",
        "geometry_msgs/PoseWithCovarianceStamped",
        "geometry_msgs/TransformStamped",
    ];
    if !KNOWN.contains(&kind.as_str()) {
        return Err(format!("{kind} is not a stamped pose type"));
    }
    let mut c = Cursor::new(data, enc)?;
    match kind.as_str() {
        "nav_msgs/Odometry" => {
            let header = c.header()?;
            let child_frame_id = c.string("child_frame_id")?;
            let pose = c.pose("pose.pose")?;
            c.skip(36, 8, "pose.covariance")?;
            c.skip(6, 8, "twist.twist")?;
            c.skip(36, 8, "twist.covariance")?;
            Ok(StampedPose {
                header,
                child_frame_id,
                pose,
            })
        }
        "geometry_msgs/PoseStamped" => Ok(StampedPose {
            header: c.header()?,
            child_frame_id: String::new(),
            pose: c.pose("pose")?,
        }),
        "geometry_msgs/PoseWithCovarianceStamped" => {
            let header = c.header()?;
            let pose = c.pose("pose.pose")?;
            c.skip(36, 8, "pose.covariance")?;
            Ok(StampedPose {
                header,
                child_frame_id: String::new(),
                pose,
            })
        }
        _ => c.transform_stamped(),
    }
}

/// `tf2_msgs/TFMessage` (ROS 1's `tf/tfMessage` is the same): its
/// `TransformStamped`s.
pub fn tf_message(data: &[u8], enc: &Encoding) -> Result<Vec<StampedPose>, String> {
    let mut c = Cursor::new(data, enc)?;
    // The least a TransformStamped takes: ROS 1 seq, time and two empty
    // strings' lengths (20 bytes), CDR time and two lengths (16), then
    // seven float64s.
    let least = if c.ros1 { 20 + 56 } else { 16 + 56 };
    let n = c.count("transforms", least, "transforms")?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(c.transform_stamped()?);
    }
    Ok(out)
}

/// `nav_msgs/OccupancyGrid`: header, `MapMetaData` (map_load_time,
/// resolution `float32`, width and height `uint32`, origin `Pose`) and
/// `int8[] data` (width × height cells, checked).
pub fn occupancy_grid(data: &[u8], enc: &Encoding) -> Result<OccupancyGridMsg, String> {
    let mut c = Cursor::new(data, enc)?;
    let header = c.header()?;
    c.time("info.map_load_time")?;
    let resolution = c.f32("info.resolution")?;
    let width = c.u32("info.width")?;
    let height = c.u32("info.height")?;
    let origin = c.pose("info.origin")?;
    let at = c.pos;
    let n = c.count("data", 1, "cells")?;
    if n as u64 != width as u64 * height as u64 {
        return Err(format!(
            "data: {n} cells at byte {at} for a {width} × {height} map"
        ));
    }
    let cells = c.take(n, "data")?;
    Ok(OccupancyGridMsg {
        header,
        resolution,
        width,
        height,
        origin,
        data: cells.iter().map(|&b| b as i8).collect(),
    })
}

/// The `std_msgs/Header` a stamped message begins with.
pub fn header(data: &[u8], enc: &Encoding) -> Result<Header, String> {
    Cursor::new(data, enc)?.header()
}
