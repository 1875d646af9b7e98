//! Our SURF against a reference implementation, on the same warped
//! photographs and with the same matcher and scores as `surf_quality`.
//!
//! The reference is dlib's `get_surf_points` (dlib 19.24, Debian's
//! `libdlib-dev`), driven through the small C++ program
//! `tests/bench/dlib_surf.cpp`. OpenCV's SURF is in its non-free contrib
//! module, which no installable package ships, so dlib is the native SURF
//! library this machine can run. Not part of the normal run (it needs
//! libdlib-dev and g++):
//!
//! ```sh
//! apt-get install libdlib-dev
//! cargo test --release -p slamlab --test surf_reference -- --ignored --nocapture --test-threads 1
//! ```
//!
//! dlib is given the same number of keypoints as ours (its strongest, at
//! a threshold low enough to have them) and its 64-d descriptors are
//! matched by our matcher, so the comparison is of detector and
//! descriptor only.

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

/// dlib's keypoints and descriptors for `img`, at most `max` of them.
fn dlib_features(img: &GrayImage, name: &str, max: usize) -> Features {
    let pgm = out_dir().join(format!("{name}.pgm"));
    write_pgm(img, &pgm);
    let out = Command::new(dlib_binary())
        .arg(&pgm)
        .arg(max.to_string())
        .arg("1")
        .output()
        .expect("run dlib_surf");
    assert!(
        out.status.success(),
        "dlib_surf: {}",
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
        assert_eq!(v.len(), 69, "dlib_surf line: {line}");
        f.keypoints.push(Keypoint {
            x: v[0],
            y: v[1],
            scale: v[2],
            orientation: v[3],
            laplacian: if v[4] < 0.0 { -1 } else { 1 },
            response: 0.0,
        });
        let mut d = Descriptor::default();
        d.0.copy_from_slice(&v[5..69]);
        f.descriptors.push(d);
    }
    f
}

#[test]
#[ignore = "needs libdlib-dev and g++: run with --release -- --ignored --nocapture"]
fn ours_against_dlib() {
    println!("{HEADER}");
    let mut sums = [[0.0f64; 3]; 2];
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
        let dlib1 = dlib_features(&img, iname, ours1.len());
        for (vname, hm, _) in views() {
            let warped = warp(&img, &hm, w, h);
            let ours2 = extract(&warped, &cfg);
            let dlib2 = dlib_features(&warped, &format!("{iname}-{vname}"), ours2.len());
            let a = score(&ours1, &ours2, &hm, (w, h));
            let b = score(&dlib1, &dlib2, &hm, (w, h));
            println!("{}", a.row(&format!("{iname} {vname}, ours")));
            println!("{}", b.row(&format!("{iname} {vname}, dlib")));
            for (s, o) in sums.iter_mut().zip([&a, &b]) {
                s[0] += o.repeatability;
                s[1] += o.precision_3px;
                s[2] += o.matches as f64;
            }
            n += 1.0;
        }
    }
    for (who, s) in ["ours", "dlib"].iter().zip(sums) {
        println!(
            "{who}: mean repeatability {:.3}, mean precision@3px {:.3}, mean matches {:.0}",
            s[0] / n,
            s[1] / n,
            s[2] / n
        );
    }
}
