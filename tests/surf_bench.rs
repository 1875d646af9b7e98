//! Native timing of the SURF pipeline (not part of the normal run):
//! `cargo test --release -p slamlab --test surf_bench -- --ignored --nocapture`.

mod surf_support;

use slamlab::surf::{
    descriptor, extract, fit_homography, match_features, orientation, FastHessian, IntegralImage,
    MatchConfig, MsacConfig, SurfConfig,
};
use std::time::Instant;
use surf_support::*;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, f64) {
    let mut t = Vec::new();
    for _ in 0..runs {
        let s = Instant::now();
        std::hint::black_box(f());
        t.push(s.elapsed().as_secs_f64() * 1e3);
    }
    let min = t.iter().copied().fold(f64::INFINITY, f64::min);
    (median(t), min)
}

#[test]
#[ignore = "benchmark: run with --release -- --ignored --nocapture"]
fn bench_native() {
    let runs = 30;
    for (name, bytes) in [
        ("astronaut", ASTRONAUT),
        ("coffee", COFFEE),
        ("chelsea", CHELSEA),
    ] {
        let img = load(bytes);
        for (label, cfg) in [
            ("default", SurfConfig::default()),
            (
                "step1",
                SurfConfig {
                    initial_step: 1,
                    ..SurfConfig::default()
                },
            ),
            (
                "upright",
                SurfConfig {
                    upright: true,
                    ..SurfConfig::default()
                },
            ),
        ] {
            let n = extract(&img, &cfg).len();
            let (med, min) = time(runs, || extract(&img, &cfg));
            let ii = IntegralImage::new(&img);
            let (t_int, _) = time(runs, || IntegralImage::new(&img));
            let (t_det, _) = time(runs, || FastHessian::new(&cfg).detect(&ii));
            let kps = FastHessian::new(&cfg).detect(&ii);
            let (t_ori, _) = time(runs, || {
                let mut k = kps.clone();
                orientation::assign_orientations(&ii, &mut k);
                k
            });
            let (t_desc, _) = time(runs, || descriptor::describe_all(&ii, &kps));
            println!(
                "{name} {label}: {n} keypoints, extract median {med:.2} ms (min {min:.2}); \
                 integral {t_int:.2}, detect {t_det:.2}, orientation {t_ori:.2}, descriptors {t_desc:.2} ms"
            );
        }
    }
    let img = load(COFFEE);
    let other = load(COFFEE_ROT12_S085);
    let cfg = SurfConfig::default();
    let (f1, f2) = (extract(&img, &cfg), extract(&other, &cfg));
    let (t_match, _) = time(runs, || match_features(&f1, &f2, &MatchConfig::default()));
    let m = match_features(&f1, &f2, &MatchConfig::default());
    let (p1, p2) = pairs(&f1, &f2, &m);
    let (t_msac, _) = time(runs, || fit_homography(&p1, &p2, &MsacConfig::default()));
    let (med, min) = time(runs, || {
        let m = match_features(&f1, &f2, &MatchConfig::default());
        let (p1, p2) = pairs(&f1, &f2, &m);
        fit_homography(&p1, &p2, &MsacConfig::default()).map(|f| f.inliers.len())
    });
    let inl = fit_homography(&p1, &p2, &MsacConfig::default()).map_or(0, |f| f.inliers.len());
    println!(
        "match+msac coffee vs coffee_rot12_s085: {} x {} keypoints, {} matches, {inl} inliers, \
         median {med:.2} ms (min {min:.2}); match {t_match:.2}, msac {t_msac:.2} ms",
        f1.len(),
        f2.len(),
        m.len()
    );
}
