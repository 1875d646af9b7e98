//! Real-data suite (`./build.sh test-real`): the ROS 1 bag and MCAP readers
//! on every bag of `../shared/data/bags` (or `$SLAMLAB_DATA/bags`). Fails
//! when the data is missing.
//!
//! Each bag's topics, types, message counts, payload bytes and first and
//! last log times must be what the data's README says and what the Python
//! `rosbags` package reports for the same files (`AnyReader`, counted
//! message by message; the figures are written here, the test does not run
//! Python); its compressions and chunk count what its own bag header or
//! MCAP summary says. Every file is read whole and in 64 KiB pieces, with
//! the same result. The zstd and lz4 MCAPs must give byte-identical
//! messages, and the MIT CSAIL ROS 1 bag's 1988 scans arrive in log-time
//! order, at the same times as in the MCAPs made from it.

use slamlab::formats::bag::mcap::McapReader;
use slamlab::formats::bag::ros1::Ros1Reader;
use slamlab::formats::bag::{
    BagError, BagReader, Encoding, MessageSink, RawMessage, ReadEnd, Topic,
};
use std::path::PathBuf;

/// `$SLAMLAB_DATA`, else `<repo>/../shared/data`; panics without `bags/`.
fn data_dir() -> PathBuf {
    let dir = match std::env::var_os("SLAMLAB_DATA") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"),
    };
    assert!(
        dir.join("bags").is_dir(),
        "real data not found: {} has no bags/ (set SLAMLAB_DATA to the shared data folder)",
        dir.display()
    );
    dir
}

/// Every message delivered, in order, and the topics.
#[derive(Debug, Default, PartialEq)]
struct Delivered {
    topics: Vec<Topic>,
    /// Topic id, log time, payload.
    messages: Vec<(u32, u64, Vec<u8>)>,
}

impl MessageSink for Delivered {
    fn topic(&mut self, topic: &Topic) {
        self.topics.push(topic.clone());
    }

    fn message(&mut self, m: RawMessage<'_>) -> Result<(), BagError> {
        self.messages
            .push((m.topic, m.log_time_ns, m.data.to_vec()));
        Ok(())
    }
}

impl Delivered {
    fn topic_name(&self, id: u32) -> &str {
        &self.topics.iter().find(|t| t.id == id).unwrap().name
    }

    /// The messages of topic `name` in the order they came: (time, payload).
    fn on(&self, name: &str) -> Vec<(u64, &[u8])> {
        self.messages
            .iter()
            .filter(|m| self.topic_name(m.0) == name)
            .map(|m| (m.1, m.2.as_slice()))
            .collect()
    }
}

/// Reads `bags/<rel>` whole and in 64 KiB pieces; asserts both agree.
fn read(rel: &str) -> (Delivered, ReadEnd) {
    let path = data_dir().join("bags").join(rel);
    let bytes =
        std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let new_reader = || -> Box<dyn BagReader> {
        if rel.ends_with(".mcap") {
            Box::new(McapReader::new())
        } else {
            Box::new(Ros1Reader::new())
        }
    };
    let mut outcomes = Vec::new();
    for piece in [bytes.len(), 1 << 16] {
        let mut reader = new_reader();
        let mut sink = Delivered::default();
        for part in bytes.chunks(piece) {
            reader
                .push(part, &mut sink)
                .unwrap_or_else(|e| panic!("{rel}: {e}"));
        }
        let end = reader
            .finish(&mut sink)
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        outcomes.push((sink, end));
    }
    let pieces = outcomes.pop().unwrap();
    let whole = outcomes.pop().unwrap();
    assert!(
        pieces == whole,
        "{rel}: 64 KiB pieces read differently from the whole file"
    );
    whole
}

/// One topic as `rosbags` reports it: name, type, messages, payload bytes,
/// first and last log time (ns).
type Expected = (&'static str, &'static str, usize, usize, u64, u64);

/// A bag: its path under `bags/`, compressions, chunks, topics.
struct Bag {
    file: &'static str,
    compression: &'static [&'static str],
    chunks: usize,
    topics: &'static [Expected],
}

const TF: &str = "tf2_msgs/TFMessage";
const ODOM: &str = "nav_msgs/Odometry";
const SCAN: &str = "sensor_msgs/LaserScan";

const BAGS: [Bag; 8] = [
    Bag {
        file: "freiburg/aces.bag",
        compression: &["bz2"],
        chunks: 17,
        topics: &[
            ("/tf_static", TF, 1, 94, 70_179_699_000, 70_179_699_000),
            (
                "/odom",
                ODOM,
                7375,
                5_258_375,
                70_179_699_000,
                1_435_900_000_000,
            ),
            ("/tf", TF, 7375, 685_875, 70_179_699_000, 1_435_900_000_000),
            (
                "/scan",
                SCAN,
                7374,
                5_729_598,
                70_289_900_000,
                1_435_809_999_000,
            ),
        ],
    },
    Bag {
        file: "freiburg/fr079.bag",
        compression: &["bz2"],
        chunks: 20,
        topics: &[
            (
                "/tf_static",
                TF,
                1,
                94,
                1_211_520_329_000,
                1_211_520_329_000,
            ),
            (
                "/scan",
                SCAN,
                4934,
                7_386_198,
                1_211_520_329_000,
                2_272_970_282_000,
            ),
            (
                "/odom",
                ODOM,
                8951,
                6_382_063,
                1_211_530_144_000,
                2_273_219_477_000,
            ),
            (
                "/tf",
                TF,
                8951,
                832_443,
                1_211_530_144_000,
                2_273_219_477_000,
            ),
        ],
    },
    Bag {
        file: "freiburg/intel.bag",
        compression: &["bz2"],
        chunks: 45,
        topics: &[
            (
                "/tf_static",
                TF,
                1,
                94,
                976_052_857_337_283_969,
                976_052_857_337_283_969,
            ),
            (
                "/odom",
                ODOM,
                26915,
                19_190_395,
                976_052_857_337_283_969,
                976_055_548_625_126_958,
            ),
            (
                "/tf",
                TF,
                26915,
                2_503_095,
                976_052_857_337_283_969,
                976_055_548_625_126_958,
            ),
            (
                "/scan",
                SCAN,
                13631,
                10_591_287,
                976_052_857_337_530_017,
                976_055_548_633_890_033,
            ),
        ],
    },
    Bag {
        file: "freiburg/mit-csail.bag",
        compression: &["bz2"],
        chunks: 7,
        topics: &[
            ("/tf_static", TF, 2, 188, MIT_FIRST, MIT_FIRST),
            ("/odom", ODOM, 1988, 1_417_444, MIT_FIRST, MIT_LAST),
            ("/tf", TF, 1988, 184_884, MIT_FIRST, MIT_LAST),
            ("/scan", SCAN, 1988, 2_983_988, MIT_FIRST, MIT_LAST),
        ],
    },
    Bag {
        file: "other/cupoch-Mapping1.bag",
        compression: &["bz2"],
        chunks: 4,
        topics: &[
            (
                "/base_scan",
                SCAN,
                1727,
                1_359_149,
                60_200_000_000,
                232_800_000_000,
            ),
            (
                "/base_pose_ground_truth",
                ODOM,
                1727,
                1_215_808,
                60_200_000_000,
                232_800_000_000,
            ),
        ],
    },
    Bag {
        file: "other/scan_tools-demo.bag",
        compression: &["none"],
        chunks: 2,
        topics: &[(
            "/scan",
            SCAN,
            360,
            1_001_160,
            1_282_836_370_970_876_375,
            1_282_836_406_786_728_375,
        )],
    },
    Bag {
        file: "ros2/mit-csail-lz4.mcap",
        compression: &["lz4"],
        chunks: 5,
        topics: MIT_MCAP_TOPICS,
    },
    Bag {
        file: "ros2/mit-csail-zstd.mcap",
        compression: &["zstd"],
        chunks: 5,
        topics: MIT_MCAP_TOPICS,
    },
];

const MIT_FIRST: u64 = 1_134_864_629_895_181_894;
const MIT_LAST: u64 = 1_134_865_053_892_205_954;
/// CDR is a few bytes longer than ROS 1's serialisation of the same
/// message (its encapsulation header and alignment).
const MIT_MCAP_TOPICS: &[Expected] = &[
    ("/tf_static", TF, 2, 200, MIT_FIRST, MIT_FIRST),
    ("/odom", ODOM, 1988, 1_439_312, MIT_FIRST, MIT_LAST),
    ("/tf", TF, 1988, 198_800, MIT_FIRST, MIT_LAST),
    ("/scan", SCAN, 1988, 2_989_952, MIT_FIRST, MIT_LAST),
];

/// What the reader found for one topic, in the form of [`Expected`].
fn measured(d: &Delivered, topic: &Topic) -> (String, String, usize, usize, u64, u64) {
    let mine: Vec<&(u32, u64, Vec<u8>)> = d.messages.iter().filter(|m| m.0 == topic.id).collect();
    (
        topic.name.clone(),
        topic.msg_type.clone(),
        mine.len(),
        mine.iter().map(|m| m.2.len()).sum(),
        mine.iter().map(|m| m.1).min().unwrap_or(0),
        mine.iter().map(|m| m.1).max().unwrap_or(0),
    )
}

#[test]
fn every_bag_has_the_topics_counts_and_times_rosbags_reports() {
    let dir = data_dir().join("bags");
    let mut on_disk = Vec::new();
    for (folder, ext) in [("freiburg", "bag"), ("other", "bag"), ("ros2", "mcap")] {
        for entry in std::fs::read_dir(dir.join(folder)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == ext) {
                let name = path.file_name().unwrap().to_string_lossy().into_owned();
                on_disk.push(format!("{folder}/{name}"));
            }
        }
    }
    on_disk.sort();
    let mut listed: Vec<String> = BAGS.iter().map(|b| b.file.to_string()).collect();
    listed.sort();
    assert_eq!(
        on_disk, listed,
        "the bags on disk and the bags this test knows"
    );

    for bag in &BAGS {
        let (got, end) = read(bag.file);
        let topics: Vec<_> = got.topics.iter().map(|t| measured(&got, t)).collect();
        let expected: Vec<_> = bag
            .topics
            .iter()
            .map(|&(name, ty, n, bytes, first, last)| {
                (name.to_string(), ty.to_string(), n, bytes, first, last)
            })
            .collect();
        assert_eq!(topics, expected, "{}", bag.file);
        let encoding = if bag.file.ends_with(".mcap") {
            Encoding::Cdr
        } else {
            Encoding::Ros1
        };
        assert!(
            got.topics.iter().all(|t| t.encoding == encoding),
            "{}: {:?}",
            bag.file,
            got.topics
        );
        assert_eq!(end.compression, bag.compression, "{}", bag.file);
        assert_eq!(end.chunks, bag.chunks, "{}", bag.file);
        assert_eq!(end.lost, None, "{}", bag.file);
    }
}

#[test]
fn intel_bag_holds_40546_scans_and_odometry_messages() {
    let (got, _) = read("freiburg/intel.bag");
    let n = got.on("/scan").len() + got.on("/odom").len();
    assert_eq!(n, 40_546);
}

#[test]
fn zstd_and_lz4_mcaps_give_identical_messages() {
    let (zstd, zstd_end) = read("ros2/mit-csail-zstd.mcap");
    let (lz4, lz4_end) = read("ros2/mit-csail-lz4.mcap");
    assert_eq!(zstd.topics, lz4.topics);
    assert_eq!(zstd.messages.len(), 5966);
    assert!(zstd.messages == lz4.messages, "the payloads differ");
    assert_eq!((zstd_end.chunks, lz4_end.chunks), (5, 5));
}

#[test]
fn mit_csail_scans_arrive_in_log_time_order_as_in_the_mcaps() {
    let (ros1, _) = read("freiburg/mit-csail.bag");
    let scans: Vec<u64> = ros1.on("/scan").iter().map(|m| m.0).collect();
    assert_eq!(scans.len(), 1988);
    let backwards = scans.windows(2).filter(|w| w[1] < w[0]).count();
    assert_eq!(backwards, 0, "scans delivered out of log-time order");
    let (mcap, _) = read("ros2/mit-csail-zstd.mcap");
    let mcap_scans: Vec<u64> = mcap.on("/scan").iter().map(|m| m.0).collect();
    assert_eq!(scans, mcap_scans);
}
