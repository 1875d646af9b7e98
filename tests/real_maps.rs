//! Real-data suite: the offline merge on real laser maps and the Halmstad
//! maps (`../shared/data/maps`, or `$SLAMLAB_DATA/maps`). Fails when the
//! data is missing. Run: `./build.sh test-real` (or
//! `cargo test --release -p slamlab --features real-data --test real_maps -- --nocapture`
//! to see the per-pair tables).

use slamlab::geom::{wrap_angle, Pose2};
use slamlab::merge::offline::{merge_pair, OfflineConfig, PairResult};
use slamlab::merge::wallmap::WallMap;
use slamlab::merge::MergeStatus;
use slamlab::rosmap::{self, MapYaml, RosMap};
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    let dir = std::env::var_os("SLAMLAB_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"));
    assert!(
        dir.join("maps").is_dir(),
        "the real-data suite needs ../shared/data/maps (or $SLAMLAB_DATA/maps); not found under {}",
        dir.display()
    );
    dir
}

fn load(yaml: &Path) -> RosMap {
    let text = std::fs::read_to_string(yaml).unwrap_or_else(|e| panic!("{}: {e}", yaml.display()));
    let y = MapYaml::parse(&yaml.display().to_string(), &text).unwrap();
    let image = yaml.parent().unwrap().join(&y.image);
    let bytes = std::fs::read(&image).unwrap_or_else(|e| panic!("{}: {e}", image.display()));
    let name = yaml.file_name().unwrap().to_string_lossy().to_string();
    rosmap::load(&name, &text, &y.image, &bytes).unwrap()
}

/// A Halmstad PNG with the README's assumed 0.05 m a pixel, origin 0.
fn load_png(png: &Path) -> RosMap {
    let yaml = format!(
        "image: {}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        png.file_name().unwrap().to_string_lossy()
    );
    let bytes = std::fs::read(png).unwrap();
    let name = png.file_stem().unwrap().to_string_lossy().to_string();
    rosmap::load(&name, &yaml, &name, &bytes).unwrap()
}

fn pair(a: &RosMap, b: &RosMap) -> PairResult {
    let (wa, wb) = (WallMap::new(a), WallMap::new(b));
    merge_pair((0, a, &wa), (1, b, &wb), &OfflineConfig::default())
}

fn error(est: &Pose2, truth: &Pose2) -> (f64, f64) {
    (
        (est.position() - truth.position()).length(),
        wrap_angle(est.theta - truth.theta).abs().to_degrees(),
    )
}

fn expect() -> serde_json::Value {
    let p = data_dir().join("maps/laser-pairs/expect.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn laser_pairs_merge_within_tolerance() {
    let dir = data_dir().join("maps/laser-pairs");
    let cases = expect();
    let mut failures = Vec::new();
    println!("| pair | verdict | error (m) | error (deg) | agree (m) | index | support (m) | rival (m) |");
    for (name, case) in cases.as_object().unwrap() {
        let a = load(&dir.join(case["a"].as_str().unwrap()));
        let b = load(&dir.join(case["b"].as_str().unwrap()));
        let t: Vec<f64> = case["pose_b_in_a"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let truth = Pose2::new(t[0], t[1], t[2]);
        let r = pair(&a, &b);
        let e = r.evidence.unwrap_or_default();
        let (dm, dd) = r.pose.map_or((f64::NAN, f64::NAN), |p| error(&p, &truth));
        println!(
            "| {name} | {:?} | {dm:.3} | {dd:.2} | {:.1} | {:.2} | {:.1} | {:.1} |",
            r.status, e.agree_m, e.index, e.support_m, r.rival_support_m
        );
        if r.status == MergeStatus::Merged && (dm > 0.5 || dd > 3.0) {
            failures.push(format!(
                "{name}: WRONG merge, off by {dm:.2} m, {dd:.2} deg"
            ));
        } else if r.status != MergeStatus::Merged || dm > 0.15 || dd > 1.0 {
            failures.push(format!(
                "{name}: {:?} off by {dm:.3} m {dd:.2} deg: {}",
                r.status, r.reason
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn cross_building_pairs_are_refused() {
    let dir = data_dir().join("maps/laser-pairs");
    let buildings = ["intel", "aces", "csail", "freiburg-079"];
    let mut wrong = Vec::new();
    println!("| A | B | verdict | agree (m) | index | support (m) | rival (m) | reason |");
    for (i, ba) in buildings.iter().enumerate() {
        for (j, bb) in buildings.iter().enumerate() {
            if i == j {
                continue;
            }
            let a = load(&dir.join(format!("{ba}-half-a.yaml")));
            let b = load(&dir.join(format!("{bb}-half-b.yaml")));
            let r = pair(&a, &b);
            let e = r.evidence.unwrap_or_default();
            println!(
                "| {ba}-half-a | {bb}-half-b | {:?} | {:.1} | {:.2} | {:.1} | {:.1} | {} |",
                r.status, e.agree_m, e.index, e.support_m, r.rival_support_m, r.reason
            );
            if r.status == MergeStatus::Merged {
                wrong.push(format!("{ba} + {bb}"));
            }
        }
    }
    assert!(wrong.is_empty(), "different buildings merged: {wrong:?}");
}
