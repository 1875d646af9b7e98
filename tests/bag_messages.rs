//! The ROS message decoders on messages built by hand: every type in ROS 1
//! serialisation and in little- and big-endian CDR, decoded to the exact
//! values written; one CDR message written out byte by byte to pin the
//! alignment rule; truncated and lying messages refused with the field and
//! the byte at fault.

use slamlab::formats::bag::messages::{
    header, laser_scan, occupancy_grid, stamped_pose, tf_message, Header, Pose3,
};
use slamlab::formats::bag::Encoding;
use wasm_bindgen_test::wasm_bindgen_test;

/// The three encodings a message is written in.
#[derive(Clone, Copy, Debug)]
enum Enc {
    Ros1,
    CdrLe,
    CdrBe,
}

const ALL: [Enc; 3] = [Enc::Ros1, Enc::CdrLe, Enc::CdrBe];

impl Enc {
    fn encoding(self) -> Encoding {
        match self {
            Enc::Ros1 => Encoding::Ros1,
            _ => Encoding::Cdr,
        }
    }
}

/// A minimal serialiser: ROS 1 packs little-endian; CDR writes the
/// encapsulation header, then aligns each primitive to its size counted
/// from the byte after that header.
struct W {
    buf: Vec<u8>,
    enc: Enc,
}

impl W {
    fn new(enc: Enc) -> W {
        let buf = match enc {
            Enc::Ros1 => Vec::new(),
            Enc::CdrLe => vec![0, 1, 0, 0],
            Enc::CdrBe => vec![0, 0, 0, 0],
        };
        W { buf, enc }
    }

    fn align(&mut self, n: usize) {
        if !matches!(self.enc, Enc::Ros1) {
            while !(self.buf.len() - 4).is_multiple_of(n) {
                self.buf.push(0);
            }
        }
    }

    fn raw<const N: usize>(&mut self, le: [u8; N]) -> &mut W {
        self.align(N);
        let mut b = le;
        if matches!(self.enc, Enc::CdrBe) {
            b.reverse();
        }
        self.buf.extend_from_slice(&b);
        self
    }

    fn u32(&mut self, v: u32) -> &mut W {
        self.raw(v.to_le_bytes())
    }

    fn i32(&mut self, v: i32) -> &mut W {
        self.raw(v.to_le_bytes())
    }

    fn f32(&mut self, v: f32) -> &mut W {
        self.raw(v.to_le_bytes())
    }

    fn f64(&mut self, v: f64) -> &mut W {
        self.raw(v.to_le_bytes())
    }

    fn string(&mut self, s: &str) -> &mut W {
        match self.enc {
            Enc::Ros1 => {
                self.u32(s.len() as u32);
                self.buf.extend_from_slice(s.as_bytes());
            }
            _ => {
                self.u32(s.len() as u32 + 1);
                self.buf.extend_from_slice(s.as_bytes());
                self.buf.push(0);
            }
        }
        self
    }

    fn time(&mut self, sec: i32, nsec: u32) -> &mut W {
        match self.enc {
            Enc::Ros1 => self.u32(sec as u32).u32(nsec),
            _ => self.i32(sec).u32(nsec),
        }
    }

    fn header(&mut self, sec: i32, nsec: u32, frame: &str) -> &mut W {
        if matches!(self.enc, Enc::Ros1) {
            self.u32(4711);
        }
        self.time(sec, nsec).string(frame)
    }

    fn f32s(&mut self, v: &[f32]) -> &mut W {
        self.u32(v.len() as u32);
        for &x in v {
            self.f32(x);
        }
        self
    }

    fn f64s(&mut self, v: &[f64]) -> &mut W {
        for &x in v {
            self.f64(x);
        }
        self
    }

    fn pose(&mut self, p: &Pose3) -> &mut W {
        self.f64s(&p.position).f64s(&p.orientation)
    }
}

const POSE: Pose3 = Pose3 {
    position: [1.25, -2.5, 0.125],
    orientation: [0.0, 0.0, 0.6, 0.8],
};

fn stamp(sec: i64, nsec: i64) -> i64 {
    sec * 1_000_000_000 + nsec
}

fn scan_bytes(enc: Enc, ranges: &[f32]) -> Vec<u8> {
    let mut w = W::new(enc);
    w.header(1_700_000_000, 123_456_789, "laser")
        .f32(-1.5)
        .f32(1.5)
        .f32(0.75)
        .f32(0.001)
        .f32(0.1)
        .f32(0.02)
        .f32(30.0)
        .f32s(ranges)
        .f32s(&[7.0, 8.0, 9.0, 10.0, 11.0]);
    w.buf
}

#[wasm_bindgen_test(unsupported = test)]
fn laser_scan_decodes_exactly_in_every_encoding() {
    let ranges = [1.0, 2.5, 0.0, f32::INFINITY, 29.875];
    for enc in ALL {
        let s = laser_scan(&scan_bytes(enc, &ranges), &enc.encoding())
            .unwrap_or_else(|e| panic!("{enc:?}: {e}"));
        assert_eq!(
            s.header,
            Header {
                stamp_ns: stamp(1_700_000_000, 123_456_789),
                frame_id: "laser".into()
            },
            "{enc:?}"
        );
        assert_eq!(
            [
                s.angle_min,
                s.angle_max,
                s.angle_increment,
                s.time_increment,
                s.scan_time,
                s.range_min,
                s.range_max
            ],
            [-1.5, 1.5, 0.75, 0.001, 0.1, 0.02, 30.0],
            "{enc:?}"
        );
        assert_eq!(s.ranges, ranges, "{enc:?}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn ros2_stamp_may_be_negative_ros1_stamp_is_unsigned() {
    let mut w = W::new(Enc::CdrLe);
    w.header(-2, 500_000_000, "map");
    assert_eq!(
        header(&w.buf, &Encoding::Cdr).unwrap().stamp_ns,
        -1_500_000_000
    );
    // The same four bytes are 2^32 - 2 seconds in ROS 1.
    let mut w = W::new(Enc::Ros1);
    w.header(-2, 0, "map");
    assert_eq!(
        header(&w.buf, &Encoding::Ros1).unwrap().stamp_ns,
        (u32::MAX as i64 - 1) * 1_000_000_000
    );
}

/// A `geometry_msgs/PoseStamped` in little-endian CDR, byte by byte: the
/// frame id "ab" ends 15 bytes after the encapsulation header, so one pad
/// byte brings the first float64 to 16 (counted from the header's end, not
/// from the buffer's start, which would give 24).
#[wasm_bindgen_test(unsupported = test)]
fn cdr_alignment_counts_from_after_the_encapsulation_header() {
    let mut b: Vec<u8> = vec![
        0x00, 0x01, 0x00, 0x00, // encapsulation: CDR, little-endian
        0x05, 0x00, 0x00, 0x00, // stamp.sec = 5
        0x40, 0x42, 0x0f, 0x00, // stamp.nanosec = 1,000,000
        0x03, 0x00, 0x00, 0x00, // frame_id length 3 ("ab" and NUL)
        b'a', b'b', 0x00, // frame_id
        0x00, // padding to 16 after the header
    ];
    for v in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    assert_eq!(b.len(), 4 + 16 + 56);
    let p = stamped_pose(&b, "geometry_msgs/msg/PoseStamped", &Encoding::Cdr).unwrap();
    assert_eq!(p.header.stamp_ns, 5_001_000_000);
    assert_eq!(p.header.frame_id, "ab");
    assert_eq!(p.child_frame_id, "");
    assert_eq!(p.pose.position, [1.0, 2.0, 3.0]);
    assert_eq!(p.pose.orientation, [0.0, 0.0, 0.0, 1.0]);
}

fn odometry_bytes(enc: Enc) -> Vec<u8> {
    let mut w = W::new(enc);
    w.header(100, 7, "odom")
        .string("base_link")
        .pose(&POSE)
        .f64s(&[0.5; 36])
        .f64s(&[9.0; 6])
        .f64s(&[0.25; 36]);
    w.buf
}

#[wasm_bindgen_test(unsupported = test)]
fn odometry_pose_stamped_and_transforms_decode_in_every_encoding() {
    for enc in ALL {
        let e = enc.encoding();
        let o = stamped_pose(&odometry_bytes(enc), "nav_msgs/Odometry", &e)
            .unwrap_or_else(|err| panic!("{enc:?}: {err}"));
        assert_eq!(o.header.stamp_ns, stamp(100, 7));
        assert_eq!(o.header.frame_id, "odom");
        assert_eq!(o.child_frame_id, "base_link");
        assert_eq!(o.pose, POSE, "{enc:?}");

        let mut w = W::new(enc);
        w.header(3, 4, "map").pose(&POSE);
        let p = stamped_pose(&w.buf, "geometry_msgs/PoseStamped", &e).unwrap();
        assert_eq!((p.header.stamp_ns, p.pose), (stamp(3, 4), POSE), "{enc:?}");

        let mut w = W::new(enc);
        w.header(5, 6, "map").pose(&POSE).f64s(&[1.0; 36]);
        let p = stamped_pose(&w.buf, "geometry_msgs/PoseWithCovarianceStamped", &e).unwrap();
        assert_eq!((p.header.frame_id.as_str(), p.pose), ("map", POSE));

        let mut w = W::new(enc);
        w.header(7, 8, "odom").string("base_footprint").pose(&POSE);
        let t = stamped_pose(&w.buf, "geometry_msgs/msg/TransformStamped", &e).unwrap();
        assert_eq!(t.child_frame_id, "base_footprint");
        assert_eq!((t.header.stamp_ns, t.pose), (stamp(7, 8), POSE));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn tf_message_holds_each_transform() {
    let second = Pose3 {
        position: [0.04, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
    };
    for enc in ALL {
        let mut w = W::new(enc);
        w.u32(2);
        w.header(10, 1, "odom").string("base_link").pose(&POSE);
        w.header(10, 2, "base_link").string("laser").pose(&second);
        let tf = tf_message(&w.buf, &enc.encoding()).unwrap_or_else(|e| panic!("{enc:?}: {e}"));
        assert_eq!(tf.len(), 2);
        assert_eq!(tf[0].header.frame_id, "odom");
        assert_eq!(tf[0].child_frame_id, "base_link");
        assert_eq!(tf[0].pose, POSE);
        assert_eq!(tf[1].header.stamp_ns, stamp(10, 2));
        assert_eq!(tf[1].child_frame_id, "laser");
        assert_eq!(tf[1].pose, second, "{enc:?}");
    }
}

fn grid_bytes(enc: Enc, width: u32, height: u32, cells: &[i8]) -> Vec<u8> {
    let mut w = W::new(enc);
    w.header(42, 0, "map")
        .time(41, 5)
        .f32(0.05)
        .u32(width)
        .u32(height)
        .pose(&POSE)
        .u32(cells.len() as u32);
    w.buf.extend(cells.iter().map(|&c| c as u8));
    w.buf
}

#[wasm_bindgen_test(unsupported = test)]
fn occupancy_grid_decodes_and_checks_its_size() {
    let cells = [-1i8, 0, 100, 50, 0, -1];
    for enc in ALL {
        let e = enc.encoding();
        let g = occupancy_grid(&grid_bytes(enc, 3, 2, &cells), &e)
            .unwrap_or_else(|err| panic!("{enc:?}: {err}"));
        assert_eq!(g.header.stamp_ns, stamp(42, 0));
        assert_eq!((g.resolution, g.width, g.height), (0.05, 3, 2));
        assert_eq!(g.origin, POSE);
        assert_eq!(g.data, cells, "{enc:?}");
        let err = occupancy_grid(&grid_bytes(enc, 4, 2, &cells), &e).unwrap_err();
        assert!(err.contains("6 cells") && err.contains("4 × 2"), "{err}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_truncated_scan_names_the_field_and_the_byte() {
    let ranges = vec![2.0f32; 361];
    // CDR: header 8 + frame "laser" (4 + 6) = 18, padded to 20; seven
    // floats to 48; the count at byte 4 + 48 = 52.
    let full = scan_bytes(Enc::CdrLe, &ranges);
    let cut = &full[..56 + 1200];
    let err = laser_scan(cut, &Encoding::Cdr).unwrap_err();
    assert_eq!(
        err,
        "ranges: 361 floats claimed at byte 52, only 1200 bytes left"
    );
    // ROS 1: seq 4 + time 8 + frame 4 + 5 = 21, seven floats to 49.
    let full = scan_bytes(Enc::Ros1, &ranges);
    let err = laser_scan(&full[..60], &Encoding::Ros1).unwrap_err();
    assert_eq!(
        err,
        "ranges: 361 floats claimed at byte 49, only 7 bytes left"
    );
    // Cut in the intensities (five floats after the ranges).
    let err = laser_scan(&full[..full.len() - 4], &Encoding::Ros1).unwrap_err();
    assert!(err.starts_with("intensities: 5 floats claimed"), "{err}");
    // Cut inside a scalar.
    let err = laser_scan(&full[..30], &Encoding::Ros1).unwrap_err();
    assert_eq!(
        err,
        "angle_increment: 4 bytes needed at byte 29, only 1 left"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn lying_counts_are_refused_before_allocating() {
    // A TFMessage claiming four billion transforms in 8 bytes.
    let mut w = W::new(Enc::CdrLe);
    w.u32(u32::MAX).u32(0);
    let err = tf_message(&w.buf, &Encoding::Cdr).unwrap_err();
    assert_eq!(
        err,
        "transforms: 4294967295 transforms claimed at byte 4, only 4 bytes left"
    );
    // A frame_id longer than the message.
    let mut w = W::new(Enc::Ros1);
    w.u32(1).u32(2).u32(3).u32(1000).u32(0);
    let err = header(&w.buf, &Encoding::Ros1).unwrap_err();
    assert_eq!(
        err,
        "header.frame_id: 1000 string bytes claimed at byte 12, only 4 bytes left"
    );
    // An odometry cut inside its twist.
    let full = odometry_bytes(Enc::CdrBe);
    let err = stamped_pose(
        &full[..full.len() - 300],
        "nav_msgs/Odometry",
        &Encoding::Cdr,
    )
    .unwrap_err();
    assert!(
        err.starts_with("twist.twist: 48 bytes needed at byte"),
        "{err}"
    );
    // A frame_id that is not UTF-8.
    let mut w = W::new(Enc::Ros1);
    w.u32(1).u32(2).u32(3).u32(2);
    w.buf.extend_from_slice(&[0xff, 0xfe]);
    let err = header(&w.buf, &Encoding::Ros1).unwrap_err();
    assert_eq!(err, "header.frame_id: the string at byte 16 is not UTF-8");
}

#[wasm_bindgen_test(unsupported = test)]
fn unknown_encapsulations_and_types_are_refused() {
    let mut b = scan_bytes(Enc::CdrLe, &[1.0]);
    b[1] = 0x03;
    let err = laser_scan(&b, &Encoding::Cdr).unwrap_err();
    assert!(err.contains("0x0003 (PL_CDR_LE)"), "{err}");
    b[1] = 0x07;
    assert!(laser_scan(&b, &Encoding::Cdr)
        .unwrap_err()
        .contains("CDR2_LE"));
    assert!(laser_scan(&[0, 1], &Encoding::Cdr)
        .unwrap_err()
        .contains("needs 4 bytes"));
    let err = laser_scan(&b, &Encoding::Other("json".into())).unwrap_err();
    assert!(err.contains("json"), "{err}");
    let err = stamped_pose(&b, "sensor_msgs/Imu", &Encoding::Cdr).unwrap_err();
    assert_eq!(err, "sensor_msgs/Imu is not a stamped pose type");
}

#[wasm_bindgen_test(unsupported = test)]
fn big_and_little_endian_cdr_differ_in_bytes_not_in_values() {
    let le = odometry_bytes(Enc::CdrLe);
    let be = odometry_bytes(Enc::CdrBe);
    assert_eq!(le.len(), be.len());
    assert_ne!(le, be);
    // Read with the wrong byte order, the same bytes give other values.
    let mut swapped = be.clone();
    swapped[1] = 1;
    let wrong = stamped_pose(&swapped, "nav_msgs/Odometry", &Encoding::Cdr);
    assert!(wrong.map_or(true, |p| p.pose != POSE));
    assert_eq!(
        stamped_pose(&le, "nav_msgs/Odometry", &Encoding::Cdr).unwrap(),
        stamped_pose(&be, "nav_msgs/Odometry", &Encoding::Cdr).unwrap()
    );
}
