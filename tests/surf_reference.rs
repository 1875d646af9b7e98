//! Our SURF against reference implementations, on the same warped
//! photographs and with the same matcher and scores as `surf_quality`.
//!
//! Two references, each driven through a small C++ program that prints
//! keypoints and descriptors:
//! - **OpenCV's** `cv::xfeatures2d::SURF` (4.10, `tests/bench/opencv_surf.cpp`).
//!   It is in the non-free contrib module, which no installable package
//!   ships, so it is built from source: the `opencv-contrib-python` source
//!   distribution on PyPI carries both trees (the cmake line is in
//!   docs/history/issue-4-surf.md). Point `OPENCV_PREFIX` at the install.
//! - **dlib's** `get_surf_points` (dlib 19.24, Debian's `libdlib-dev`,
//!   `tests/bench/dlib_surf.cpp`).
//!
//! Not part of the normal run (they need those libraries and g++):
//!
//! ```sh
//! OPENCV_PREFIX=/opt/opencv cargo test --release -p slamlab --test surf_reference -- --ignored --nocapture --test-threads 1
//! ```
//!
//! Each reference is given the same number of keypoints as ours (its
//! strongest, at a threshold low enough to have them) and its 64-d
//! descriptors are matched by our matcher, so the comparison is of
//! detector and descriptor only.

mod surf_support;

use slamlab::surf::{extract, Descriptor, Features, GrayImage, Keypoint, SurfConfig};
use std::path::{Path, PathBuf};
use std::process::Command;
use surf_support::*;

fn out_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/surf-reference");
    std::fs::create_dir_all(&dir).expect("create target/surf-reference");
    dir
}

/// The dlib driver: `$DLIB_SURF`, or built from `tests/bench/dlib_surf.cpp`.
fn dlib_binary() -> PathBuf {
    if let Ok(p) = std::env::var("DLIB_SURF") {
        return PathBuf::from(p);
    }
    let bin = out_dir().join("dlib_surf");
    if !bin.exists() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/bench/dlib_surf.cpp");
        // Debian's libdlib.so needs BLAS; libblas-dev may be absent, so
        // link the runtime library by path.
        let status = Command::new("g++")
            .args(["-O2", "-o"])
            .arg(&bin)
            .arg(&src)
            .args([
                "-ldlib",
                "-lpthread",
                "/usr/lib/x86_64-linux-gnu/libblas.so.3",
            ])
            .status()
            .expect("run g++ (needs g++ and libdlib-dev)");
        assert!(status.success(), "building {} failed", src.display());
    }
    bin
}

fn write_pgm(img: &GrayImage, path: &Path) {
    let mut bytes = format!("P5\n{} {}\n255\n", img.width(), img.height()).into_bytes();
    bytes.extend_from_slice(img.pixels());
    std::fs::write(path, bytes).expect("write PGM");
}

/// How a reference driver's raw line maps to our keypoint: its scale field
/// to our σ, and its angle field to radians.
struct Reference {
    name: &'static str,
    binary: fn() -> PathBuf,
    /// dlib's `scale` is σ already; OpenCV's `size` is the box filter's side
    /// L, and σ = 1.2 L / 9 (Bay et al. §3.3; OpenCV's `s = size*1.2f/9.0f`).
    scale_of: f32,
    /// dlib's angle is in radians; OpenCV's in degrees.
    angle_of: f32,
    /// Extra arguments after `IMAGE MAX`.
    args: &'static [&'static str],
}

const DLIB: Reference = Reference {
    name: "dlib",
    binary: dlib_binary,
    scale_of: 1.0,
    angle_of: 1.0,
    args: &["1"],
};

const OPENCV: Reference = Reference {
    name: "OpenCV",
    binary: opencv_binary,
    scale_of: 1.2 / 9.0,
    angle_of: std::f32::consts::PI / 180.0,
    args: &[],
};

/// A reference's keypoints and descriptors for `img`, at most `max` of them.
fn reference_features(r: &Reference, img: &GrayImage, name: &str, max: usize) -> Features {
    let pgm = out_dir().join(format!("{name}.pgm"));
    write_pgm(img, &pgm);
    let out = Command::new((r.binary)())
        .arg(&pgm)
        .arg(max.to_string())
        .args(r.args)
        .output()
        .unwrap_or_else(|e| panic!("run the {} driver: {e}", r.name));
    assert!(
        out.status.success(),
        "{}: {}",
        r.name,
        String::from_utf8_lossy(&out.stderr)
    );
    let mut f = Features {
        keypoints: Vec::new(),
        descriptors: Vec::new(),
    };
    for line in String::from_utf8(out.stdout).expect("utf8").lines() {
        let v: Vec<f32> = line
            .split_whitespace()
            .map(|t| t.parse().expect("number"))
            .collect();
        assert_eq!(v.len(), 69, "{} line: {line}", r.name);
        f.keypoints.push(Keypoint {
            x: v[0],
            y: v[1],
            scale: v[2] * r.scale_of,
            orientation: v[3] * r.angle_of,
            laplacian: if v[4] < 0.0 { -1 } else { 1 },
            response: 0.0,
        });
        let mut d = Descriptor::default();
        d.0.copy_from_slice(&v[5..69]);
        f.descriptors.push(d);
    }
    f
}

/// The OpenCV driver: `$OPENCV_SURF`, or built from
/// `tests/bench/opencv_surf.cpp` against the OpenCV installed under
/// `$OPENCV_PREFIX` (built from source with the contrib modules and
/// `-DOPENCV_ENABLE_NONFREE=ON`; see docs/history/issue-4-surf.md).
fn opencv_binary() -> PathBuf {
    if let Ok(p) = std::env::var("OPENCV_SURF") {
        return PathBuf::from(p);
    }
    let prefix =
        PathBuf::from(std::env::var("OPENCV_PREFIX").expect("set OPENCV_PREFIX (or OPENCV_SURF)"));
    let bin = out_dir().join("opencv_surf");
    if !bin.exists() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/bench/opencv_surf.cpp");
        let lib = prefix.join("lib");
        let status = Command::new("g++")
            .args(["-O2", "-std=c++17", "-o"])
            .arg(&bin)
            .arg(&src)
            .arg(format!("-I{}", prefix.join("include/opencv4").display()))
            .arg(format!("-L{}", lib.display()))
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .args([
                "-lopencv_xfeatures2d",
                "-lopencv_features2d",
                "-lopencv_imgcodecs",
                "-lopencv_core",
            ])
            .status()
            .expect("run g++");
        assert!(status.success(), "building {} failed", src.display());
    }
    bin
}

/// Ours and `r` on the same 18 views, scored alike; prints the rows and
/// the means.
fn compare(r: &Reference) {
    println!("{HEADER}");
    let mut sums = [[0.0f64; 4]; 2];
    let mut n = 0.0;
    for (iname, bytes) in [
        ("astronaut", ASTRONAUT),
        ("coffee", COFFEE),
        ("chelsea", CHELSEA),
    ] {
        let img = load(bytes);
        let (w, h) = (img.width(), img.height());
        let cfg = SurfConfig::default();
        let ours1 = extract(&img, &cfg);
        let ref1 = reference_features(r, &img, iname, ours1.len());
        for (vname, hm, _) in views() {
            let warped = warp(&img, &hm, w, h);
            let ours2 = extract(&warped, &cfg);
            let ref2 = reference_features(r, &warped, &format!("{iname}-{vname}"), ours2.len());
            let a = score(&ours1, &ours2, &hm, (w, h));
            let b = score(&ref1, &ref2, &hm, (w, h));
            println!("{}", a.row(&format!("{iname} {vname}, ours")));
            println!("{}", b.row(&format!("{iname} {vname}, {}", r.name)));
            for (s, o) in sums.iter_mut().zip([&a, &b]) {
                s[0] += o.repeatability;
                s[1] += o.precision_3px;
                s[2] += o.precision_overlap;
                s[3] += o.matches as f64;
            }
            n += 1.0;
        }
    }
    for (who, s) in ["ours", r.name].iter().zip(sums) {
        println!(
            "{who}: mean repeatability {:.3}, mean precision@3px {:.3}, mean precision (overlap) {:.3}, mean matches {:.0}",
            s[0] / n,
            s[1] / n,
            s[2] / n,
            s[3] / n
        );
    }
}

#[test]
#[ignore = "needs libdlib-dev and g++: run with --release -- --ignored --nocapture"]
fn ours_against_dlib() {
    compare(&DLIB);
}

#[test]
#[ignore = "needs OpenCV with the non-free contrib SURF under $OPENCV_PREFIX: run with --release -- --ignored --nocapture"]
fn ours_against_opencv() {
    compare(&OPENCV);
}
