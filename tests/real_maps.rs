//! Real-data suite: the saved-maps merge on real laser maps and the Halmstad
//! maps (`../shared/data/maps`, or `$SLAMLAB_DATA/maps`). Fails when the
//! data is missing. Run: `./build.sh test-real` (or
//! `cargo test --release -p slamlab --features real-data --test real_maps -- --nocapture`
//! to see the per-pair tables).

use glam::DVec2;
use slamlab::formats::rosmap::{self, MapYaml, RosMap};
use slamlab::geom::{wrap_angle, Pose2};
use slamlab::merge::saved::wallmap::WallMap;
use slamlab::merge::saved::{merge_pair, PairResult, SavedMergeConfig};
use slamlab::merge::MergeStatus;
use std::path::{Path, PathBuf};

#[path = "real_support/npy.rs"]
mod npy;

#[path = "merge_support/guess.rs"]
mod guess;
use guess::{middle, nudged, refined};

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
    merge_pair((0, a, &wa), (1, b, &wb), &SavedMergeConfig::default())
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

/// A laser pair of expect.json: its two maps and B's true frame in A's.
fn laser_case(dir: &Path, case: &serde_json::Value) -> (RosMap, RosMap, Pose2) {
    let a = load(&dir.join(case["a"].as_str().unwrap()));
    let b = load(&dir.join(case["b"].as_str().unwrap()));
    let t: Vec<f64> = case["pose_b_in_a"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    (a, b, Pose2::new(t[0], t[1], t[2]))
}

#[test]
fn laser_pairs_merge_within_tolerance() {
    let dir = data_dir().join("maps/laser-pairs");
    let cases = expect();
    let mut failures = Vec::new();
    println!("| pair | verdict | error (m) | error (deg) | agree (m) | index | support (m) | rival (m) |");
    for (name, case) in cases.as_object().unwrap() {
        let (a, b, truth) = laser_case(&dir, case);
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

/// Least-squares rigid fit `pa ≈ R pb + t` (Kabsch in 2-D): (θ, t).
fn kabsch(pa: &[DVec2], pb: &[DVec2]) -> (f64, DVec2) {
    let n = pa.len() as f64;
    let (ca, cb) = (pa.iter().sum::<DVec2>() / n, pb.iter().sum::<DVec2>() / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (a, b) in pa.iter().zip(pb) {
        let (qa, qb) = (*a - ca, *b - cb);
        sxx += qa.dot(qb);
        sxy += qb.x * qa.y - qb.y * qa.x;
    }
    let th = sxy.atan2(sxx);
    let (s, c) = th.sin_cos();
    (
        th,
        ca - DVec2::new(c * cb.x - s * cb.y, s * cb.x + c * cb.y),
    )
}

fn apply(th: f64, t: DVec2, p: DVec2) -> DVec2 {
    let (s, c) = th.sin_cos();
    t + DVec2::new(c * p.x - s * p.y, s * p.x + c * p.y)
}

/// The reference of fit_reference.py: B's frame in A's (metres, y up,
/// origin the image's lower-left corner), its RMS residual (m), and the
/// associated keypoints in metres.
struct Reference {
    pose: Pose2,
    rms_m: f64,
    pa: Vec<DVec2>,
    pb: Vec<DVec2>,
}

fn reference(dir: &Path, a: &str, b: &str) -> Option<Reference> {
    let ann = dir.join("annotations");
    let rows =
        |p: PathBuf| -> Vec<[f64; 2]> { npy::read_pairs(&p).into_iter().flatten().collect() };
    let ka = rows(ann.join(format!("keypoints_{a}.npy")));
    let kb = rows(ann.join(format!("keypoints_{b}.npy")));
    // An association file in the other direction serves, swapped; rows
    // holding a None (a keypoint left unmatched) are dropped.
    let forward = ann.join(format!("association_{a}_{b}.npy"));
    let (assoc, swap) = if forward.is_file() {
        (rows(forward), false)
    } else {
        let backward = ann.join(format!("association_{b}_{a}.npy"));
        if !backward.is_file() {
            return None;
        }
        (rows(backward), true)
    };
    let res = 0.05;
    // Keypoint (x, y_up) in pixels -> metres at the pixel-centre convention
    // of fit_reference.py: p = res (kp + (0.5, -0.5)).
    let m = |k: [f64; 2]| DVec2::new(k[0] + 0.5, k[1] - 0.5) * res;
    let mut pa = Vec::new();
    let mut pb = Vec::new();
    for r in &assoc {
        let (i, j) = if swap { (r[1], r[0]) } else { (r[0], r[1]) };
        pa.push(m(ka[i as usize]));
        pb.push(m(kb[j as usize]));
    }
    if pa.len() < 3 {
        return None;
    }
    let (mut th, mut t) = kabsch(&pa, &pb);
    let resid = |th: f64, t: DVec2, pa: &[DVec2], pb: &[DVec2]| -> Vec<f64> {
        pa.iter()
            .zip(pb)
            .map(|(a, b)| (*a - apply(th, t, *b)).length())
            .collect()
    };
    let r = resid(th, t, &pa, &pb);
    let mut sorted = r.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let keep: Vec<bool> = r
        .iter()
        .map(|&e| !(e > 4.0 * median && e > 40.0 * res))
        .collect();
    if keep.iter().any(|k| !k) && keep.iter().filter(|k| **k).count() >= 3 {
        let f = |v: &[DVec2]| {
            v.iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(p, _)| *p)
                .collect::<Vec<_>>()
        };
        (pa, pb) = (f(&pa), f(&pb));
        (th, t) = kabsch(&pa, &pb);
    }
    let r = resid(th, t, &pa, &pb);
    let rms_m = (r.iter().map(|e| e * e).sum::<f64>() / r.len() as f64).sqrt();
    Some(Reference {
        pose: Pose2::new(t.x, t.y, th),
        rms_m,
        pa,
        pb,
    })
}

/// RMS distance (m) between the hand-picked points of A and B's points
/// moved by `pose`.
fn rms_on_keypoints(r: &Reference, pose: &Pose2) -> f64 {
    let e: f64 =
        r.pa.iter()
            .zip(&r.pb)
            .map(|(a, b)| (*a - pose.transform_point(*b)).length_squared())
            .sum();
    (e / r.pa.len() as f64).sqrt()
}

/// Largest distance (m) between B's keypoints moved by `pose` and by the reference.
fn spread_from_reference(r: &Reference, pose: &Pose2) -> f64 {
    r.pb.iter()
        .map(|b| (pose.transform_point(*b) - r.pose.transform_point(*b)).length())
        .fold(0.0, f64::max)
}

/// Runs every pair of `maps` in Halmstad folder `floor`, printing a table;
/// returns (name, verdict, error figures) per pair.
fn halmstad(floor: &str, maps: &[&str]) -> Vec<(String, MergeStatus, f64, f64, f64, f64)> {
    let dir = data_dir().join("maps/halmstad");
    let loaded: Vec<RosMap> = maps
        .iter()
        .map(|m| load_png(&dir.join(floor).join(format!("{m}.png"))))
        .collect();
    let prepared: Vec<WallMap> = loaded.iter().map(WallMap::new).collect();
    let mut out = Vec::new();
    println!("| pair | verdict | ref rms (m) | ours rms (m) | off ref (m) | off ref (deg) | agree (m) | index | support (m) | rival (m) |");
    for i in 0..maps.len() {
        for j in i + 1..maps.len() {
            let Some(reference) = reference(&dir, maps[i], maps[j]) else {
                println!("| {} {} | (no readable annotation) |", maps[i], maps[j]);
                continue;
            };
            let r = merge_pair(
                (0, &loaded[i], &prepared[i]),
                (1, &loaded[j], &prepared[j]),
                &SavedMergeConfig::default(),
            );
            let e = r.evidence.unwrap_or_default();
            let (ours, off, deg) = r.pose.map_or((f64::NAN, f64::NAN, f64::NAN), |p| {
                (
                    rms_on_keypoints(&reference, &p),
                    spread_from_reference(&reference, &p),
                    wrap_angle(p.theta - reference.pose.theta)
                        .abs()
                        .to_degrees(),
                )
            });
            println!(
                "| {} {} | {:?} | {:.3} | {ours:.3} | {off:.2} | {deg:.2} | {:.1} | {:.2} | {:.1} | {:.1} |",
                maps[i], maps[j], r.status, reference.rms_m, e.agree_m, e.index, e.support_m, r.rival_support_m
            );
            out.push((
                format!("{} {}", maps[i], maps[j]),
                r.status,
                reference.rms_m,
                ours,
                off,
                deg,
            ));
        }
    }
    out
}

#[test]
fn halmstad_apartment_pairs() {
    let results = halmstad("KPT4A", &["KPT4A_01", "KPT4A_02", "KPT4A_03", "KPT4A_04"]);
    assert_eq!(
        results.len(),
        6,
        "every KPT4A pair has a readable annotation"
    );
    for (name, status, rms_ref, ours, off, deg) in &results {
        if *status == MergeStatus::Merged {
            assert!(
                *off <= 2.0 + 2.0 * rms_ref && *deg <= 5.0,
                "{name}: WRONG merge ({off:.2} m, {deg:.2} deg from the reference)"
            );
        }
        // Done when: every KPT4A pair lands within twice its reference
        // residual (our transform's RMS on the hand-picked points).
        assert_eq!(*status, MergeStatus::Merged, "{name}");
        assert!(
            *ours <= 2.0 * rms_ref,
            "{name}: RMS {ours:.3} m on the keypoints, reference {rms_ref:.3} m"
        );
    }
}

#[test]
fn halmstad_office_pairs() {
    let maps: Vec<String> = (1..=14).map(|k| format!("F5_{k:02}")).collect();
    let names: Vec<&str> = maps.iter().map(|s| s.as_str()).collect();
    let results = halmstad("F5", &names);
    let merged = results
        .iter()
        .filter(|r| r.1 == MergeStatus::Merged)
        .count();
    println!("F5: {merged} of {} annotated pairs merged", results.len());
    // All 91 pairs of the 14 maps carry an association file, numeric or
    // pickled (`real_support/npy.rs` reads both).
    assert_eq!(results.len(), 91, "every F5 pair has a readable annotation");
    for (name, status, rms_ref, _, off, deg) in &results {
        if *status == MergeStatus::Merged {
            assert!(
                *off <= 2.0 + 2.0 * rms_ref && *deg <= 5.0,
                "{name}: WRONG merge ({off:.2} m, {deg:.2} deg from the reference)"
            );
        }
    }
}

#[test]
fn refine_from_a_rough_guess_on_laser_pairs() {
    let dir = data_dir().join("maps/laser-pairs");
    let mut failures = Vec::new();
    println!("| pair | verdict | error (m) | error (deg) | agree (m) | index | support (m) | rival (m) |");
    for (name, case) in expect().as_object().unwrap() {
        let (a, b, truth) = laser_case(&dir, case);
        // 1 m and 8° off, about B's middle.
        let guess = nudged(&truth, middle(&b), 8f64.to_radians(), DVec2::new(0.8, -0.6));
        let r = refined(&a, &b, guess);
        let e = r.evidence.unwrap_or_default();
        let (dm, dd) = r.pose.map_or((f64::NAN, f64::NAN), |p| error(&p, &truth));
        println!(
            "| {name} | {:?} | {dm:.3} | {dd:.2} | {:.1} | {:.2} | {:.1} | {:.1} |",
            r.status, e.agree_m, e.index, e.support_m, r.rival_support_m
        );
        if r.status != MergeStatus::Merged || dm > 0.15 || dd > 1.0 {
            failures.push(format!(
                "{name}: {:?} off by {dm:.3} m {dd:.2} deg: {}",
                r.status, r.reason
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn refine_refuses_cross_building_guesses() {
    let dir = data_dir().join("maps/laser-pairs");
    let buildings = ["intel", "aces", "csail", "freiburg-079"];
    let mut wrong = Vec::new();
    for (i, ba) in buildings.iter().enumerate() {
        let bb = buildings[(i + 1) % buildings.len()];
        let a = load(&dir.join(format!("{ba}-half-a.yaml")));
        let b = load(&dir.join(format!("{bb}-half-b.yaml")));
        // B's middle on A's middle, at four headings.
        for k in 0..4 {
            let theta = k as f64 * std::f64::consts::FRAC_PI_2;
            let turned = Pose2::new(0.0, 0.0, theta).transform_point(middle(&b));
            let at = middle(&a) - turned;
            let r = refined(&a, &b, Pose2::new(at.x, at.y, theta));
            println!(
                "{ba}-half-a + {bb}-half-b at {}°: {:?}: {}",
                90 * k,
                r.status,
                r.reason
            );
            if r.status == MergeStatus::Merged {
                wrong.push(format!("{ba} + {bb} at {}°", 90 * k));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "different buildings merged by refine: {wrong:?}"
    );
}
