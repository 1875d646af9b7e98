//! Test support for the SURF tests: loading the shipped photographs,
//! warping them by known homographies (bilinear resampling, written here so
//! the tests do not trust the code under test), and the repeatability and
//! matching-precision measures.
#![allow(dead_code)]

use slamlab::surf::{
    fit_homography, match_features, Features, GrayImage, Homography, Match, MatchConfig, MsacConfig,
};

pub const ASTRONAUT: &[u8] = include_bytes!("../data/astronaut.png");
pub const COFFEE: &[u8] = include_bytes!("../data/coffee.png");
pub const CHELSEA: &[u8] = include_bytes!("../data/chelsea.png");
pub const COFFEE_COLOR_JPG: &[u8] = include_bytes!("../data/coffee_color.jpg");
pub const COFFEE_ROT12_S085: &[u8] = include_bytes!("../data/coffee_rot12_s085.png");

pub fn load(bytes: &[u8]) -> GrayImage {
    GrayImage::decode(bytes).expect("test image decodes")
}

/// Rotation by `deg` (from +x towards +y, image axes) and scale `s` about
/// (cx, cy), followed by a shift (tx, ty).
pub fn rot_scale(deg: f64, s: f64, cx: f64, cy: f64, tx: f64, ty: f64) -> Homography {
    let (sn, c) = deg.to_radians().sin_cos();
    let (a, b) = (s * c, s * sn);
    Homography([
        [a, -b, cx - (a * cx - b * cy) + tx],
        [b, a, cy - (b * cx + a * cy) + ty],
        [0.0, 0.0, 1.0],
    ])
}

/// The warps the quality tests use: the 12°/0.85 view first, then
/// harder ones. Each with the largest overlap error (px) `surf_quality`
/// accepts for it.
pub fn views() -> [(&'static str, Homography, f64); 6] {
    [
        (
            "rot12 s0.85",
            rot_scale(12.0, 0.85, 319.5, 239.5, 0.0, 0.0),
            1.0,
        ),
        ("rot30", rot_scale(30.0, 1.0, 319.5, 239.5, 0.0, 0.0), 1.0),
        ("scale0.5", rot_scale(0.0, 0.5, 319.5, 239.5, 0.0, 0.0), 1.0),
        ("scale2", rot_scale(0.0, 2.0, 319.5, 239.5, 0.0, 0.0), 2.0),
        (
            "rot-20 s1.4",
            rot_scale(-20.0, 1.4, 319.5, 239.5, 10.0, -5.0),
            2.0,
        ),
        (
            "perspective",
            Homography([
                [0.9, 0.05, 30.0],
                [-0.03, 0.95, 20.0],
                [0.0002, -0.0001, 1.0],
            ]),
            1.0,
        ),
    ]
}

/// `src` seen through `h` (src pixels → dst pixels) in a `w × h` image,
/// bilinear; outside the source is black.
pub fn warp(src: &GrayImage, hm: &Homography, w: usize, h: usize) -> GrayImage {
    let inv = hm.inverse().expect("invertible");
    let (sw, sh) = (src.width() as isize, src.height() as isize);
    let px = src.pixels();
    let mut out = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let Some([u, v]) = inv.apply([x as f64, y as f64]) else {
                continue;
            };
            let (x0, y0) = (u.floor(), v.floor());
            let (fx, fy) = (u - x0, v - y0);
            let (x0, y0) = (x0 as isize, y0 as isize);
            if x0 < 0 || y0 < 0 || x0 + 1 >= sw || y0 + 1 >= sh {
                continue;
            }
            let at = |xx: isize, yy: isize| px[(yy * sw + xx) as usize] as f64;
            let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
            let bot = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
            out[y * w + x] = (top * (1.0 - fy) + bot * fy).round().clamp(0.0, 255.0) as u8;
        }
    }
    GrayImage::new(w, h, out).expect("valid")
}

fn inside(p: [f64; 2], w: usize, h: usize, margin: f64) -> bool {
    p[0] >= margin
        && p[1] >= margin
        && p[0] <= w as f64 - 1.0 - margin
        && p[1] <= h as f64 - 1.0 - margin
}

/// Repeatability in the sense of Mikolajczyk et al. (2005), with point
/// distances: of the keypoints of image 1 that land inside image 2 (and vice
/// versa), the share that have a keypoint of the other image within
/// `tol_px` pixels and within a factor 1.5 of the expected scale, over the
/// smaller of the two visible counts.
pub fn repeatability(
    f1: &Features,
    f2: &Features,
    hm: &Homography,
    size1: (usize, usize),
    size2: (usize, usize),
    tol_px: f64,
) -> f64 {
    let inv = hm.inverse().expect("invertible");
    let zoom = (hm.0[0][0] * hm.0[1][1] - hm.0[0][1] * hm.0[1][0])
        .abs()
        .sqrt();
    let vis1: Vec<_> = f1
        .keypoints
        .iter()
        .filter_map(|k| {
            hm.apply([k.x as f64, k.y as f64])
                .filter(|p| inside(*p, size2.0, size2.1, 0.0))
                .map(|p| (p, k.scale as f64 * zoom))
        })
        .collect();
    let vis2 = f2
        .keypoints
        .iter()
        .filter(|k| {
            inv.apply([k.x as f64, k.y as f64])
                .is_some_and(|p| inside(p, size1.0, size1.1, 0.0))
        })
        .count();
    let found = vis1
        .iter()
        .filter(|(p, s)| {
            f2.keypoints.iter().any(|k| {
                let d = (k.x as f64 - p[0]).hypot(k.y as f64 - p[1]);
                let r = k.scale as f64 / s;
                d <= tol_px && r < 1.5 && r > 1.0 / 1.5
            })
        })
        .count();
    let denom = vis1.len().min(vis2);
    if denom == 0 {
        0.0
    } else {
        found as f64 / denom as f64
    }
}

/// Share of `matches` whose keypoint in image 2 lies within `tol_px` of
/// where `hm` sends its keypoint of image 1.
pub fn precision(
    f1: &Features,
    f2: &Features,
    matches: &[Match],
    hm: &Homography,
    tol_px: f64,
) -> f64 {
    if matches.is_empty() {
        return 0.0;
    }
    let good = matches
        .iter()
        .filter(|m| correct(f1, f2, m, hm, tol_px))
        .count();
    good as f64 / matches.len() as f64
}

pub fn correct(f1: &Features, f2: &Features, m: &Match, hm: &Homography, tol_px: f64) -> bool {
    let (a, b) = (&f1.keypoints[m.query], &f2.keypoints[m.train]);
    hm.apply([a.x as f64, a.y as f64])
        .is_some_and(|p| (p[0] - b.x as f64).hypot(p[1] - b.y as f64) <= tol_px)
}

/// The region-overlap criterion of the standard descriptor evaluation
/// (Mikolajczyk and Schmid, PAMI 2005, §4.1; Mikolajczyk et al., IJCV 2005,
/// the protocol Bay et al. 2008 evaluate SURF with): a match is correct
/// when the overlap error `1 − |A ∩ B| / |A ∪ B|` of the two keypoints'
/// regions, compared in image 2, is below `max_error` (0.5 there). Region
/// A is image 1's circle of radius proportional to its scale, carried into
/// image 2 by the homography's local affine map at its centre (an
/// ellipse); B is image 2's circle. As in that protocol, the sizes (not the
/// positions) are normalised so that A's equivalent radius is 30 px: the
/// criterion then allows a fixed fraction of a 30 px region in position
/// (about 12 px for equal scales) and about 1.4× in scale, at every scale.
/// The overlap is integrated on a 120 × 120 grid over the two regions.
pub fn overlap_correct(
    f1: &Features,
    f2: &Features,
    m: &Match,
    hm: &Homography,
    max_error: f64,
) -> bool {
    let (a, b) = (&f1.keypoints[m.query], &f2.keypoints[m.train]);
    let pa = [a.x as f64, a.y as f64];
    let (Some(ca), Some(px), Some(py)) = (
        hm.apply(pa),
        hm.apply([pa[0] + 1.0, pa[1]]),
        hm.apply([pa[0], pa[1] + 1.0]),
    ) else {
        return false;
    };
    // Local affine map J (columns: images of the unit steps).
    let j = [
        [px[0] - ca[0], py[0] - ca[0]],
        [px[1] - ca[1], py[1] - ca[1]],
    ];
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    if det.abs() < 1e-12 {
        return false;
    }
    // A = { ca + J u : |u| ≤ ra }, equivalent radius ra·sqrt|det J| → 30.
    let ra_img2 = a.scale as f64 * det.abs().sqrt();
    let f = 30.0 / ra_img2;
    let ra = a.scale as f64 * f;
    let rb = b.scale as f64 * f;
    let cb = [b.x as f64, b.y as f64];
    let inv = [
        [j[1][1] / det, -j[0][1] / det],
        [-j[1][0] / det, j[0][0] / det],
    ];
    let in_a = |p: [f64; 2]| {
        let d = [p[0] - ca[0], p[1] - ca[1]];
        let u = [
            inv[0][0] * d[0] + inv[0][1] * d[1],
            inv[1][0] * d[0] + inv[1][1] * d[1],
        ];
        u[0] * u[0] + u[1] * u[1] <= ra * ra
    };
    let in_b = |p: [f64; 2]| (p[0] - cb[0]).powi(2) + (p[1] - cb[1]).powi(2) <= rb * rb;
    // Bounding box of both: A's extent along each axis is ra·|row of J|.
    let ex = [ra * j[0][0].hypot(j[0][1]), ra * j[1][0].hypot(j[1][1])];
    let lo = [
        (ca[0] - ex[0]).min(cb[0] - rb),
        (ca[1] - ex[1]).min(cb[1] - rb),
    ];
    let hi = [
        (ca[0] + ex[0]).max(cb[0] + rb),
        (ca[1] + ex[1]).max(cb[1] + rb),
    ];
    const N: usize = 120;
    let (mut both, mut either) = (0usize, 0usize);
    for iy in 0..N {
        for ix in 0..N {
            let p = [
                lo[0] + (ix as f64 + 0.5) * (hi[0] - lo[0]) / N as f64,
                lo[1] + (iy as f64 + 0.5) * (hi[1] - lo[1]) / N as f64,
            ];
            let (ia, ib) = (in_a(p), in_b(p));
            both += usize::from(ia && ib);
            either += usize::from(ia || ib);
        }
    }
    either > 0 && 1.0 - (both as f64) / (either as f64) < max_error
}

/// Largest distance between the images of image 1's corners under two homographies.
pub fn corner_error(a: &Homography, b: &Homography, w: usize, h: usize) -> f64 {
    let (w, h) = (w as f64, h as f64);
    [
        [-0.5, -0.5],
        [w - 0.5, -0.5],
        [w - 0.5, h - 0.5],
        [-0.5, h - 0.5],
    ]
    .iter()
    .map(|&c| {
        let (p, q) = (a.apply(c).expect("finite"), b.apply(c).expect("finite"));
        (p[0] - q[0]).hypot(p[1] - q[1])
    })
    .fold(0.0, f64::max)
}

pub fn pairs(f1: &Features, f2: &Features, matches: &[Match]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let p1 = matches
        .iter()
        .map(|m| {
            [
                f1.keypoints[m.query].x as f64,
                f1.keypoints[m.query].y as f64,
            ]
        })
        .collect();
    let p2 = matches
        .iter()
        .map(|m| {
            [
                f2.keypoints[m.train].x as f64,
                f2.keypoints[m.train].y as f64,
            ]
        })
        .collect();
    (p1, p2)
}

/// A deterministic pseudo-random byte image (SplitMix64 of the index).
pub fn noise_image(w: usize, h: usize, seed: u64) -> GrayImage {
    let mut rng = slamlab::surf::prng::SplitMix64::new(seed);
    GrayImage::new(
        w,
        h,
        (0..w * h).map(|_| (rng.next_u64() >> 56) as u8).collect(),
    )
    .expect("valid")
}

/// Table header matching [`Outcome::row`].
pub const HEADER: &str = "| view | keypoints | repeatability | matches | precision@3px | precision@σ | precision (overlap) | inliers | inlier precision | overlap error px | corner error px |";

/// Every quality figure of one pair of feature sets (see `surf_quality`'s
/// module doc for the definitions).
pub struct Outcome {
    pub keypoints: (usize, usize),
    pub repeatability: f64,
    pub matches: usize,
    pub precision_3px: f64,
    pub precision_scale: f64,
    /// Share of matches correct by [`overlap_correct`] (error < 50 %).
    pub precision_overlap: f64,
    pub inliers: usize,
    pub inlier_precision: f64,
    pub overlap_error_px: f64,
    pub corner_error_px: f64,
}

impl Outcome {
    /// One Markdown table row, as in BENCHMARKS.md.
    pub fn row(&self, name: &str) -> String {
        format!(
            "| {name} | {} / {} | {:.3} | {} | {:.3} | {:.3} | {:.3} | {} | {:.3} | {:.2} | {:.2} |",
            self.keypoints.0,
            self.keypoints.1,
            self.repeatability,
            self.matches,
            self.precision_3px,
            self.precision_scale,
            self.precision_overlap,
            self.inliers,
            self.inlier_precision,
            self.overlap_error_px,
            self.corner_error_px
        )
    }
}

/// Largest distance, over a grid of image-1 points that land inside image 2
/// (`w × h`), between where `fit` and `truth` send them.
pub fn overlap_error(fit: &Homography, truth: &Homography, w: usize, h: usize) -> f64 {
    let mut worst: f64 = 0.0;
    for gy in 0..=24 {
        for gx in 0..=32 {
            let p = [
                gx as f64 * (w as f64 - 1.0) / 32.0,
                gy as f64 * (h as f64 - 1.0) / 24.0,
            ];
            let (Some(a), Some(b)) = (fit.apply(p), truth.apply(p)) else {
                return f64::INFINITY;
            };
            if b[0] >= 0.0 && b[1] >= 0.0 && b[0] <= w as f64 - 1.0 && b[1] <= h as f64 - 1.0 {
                worst = worst.max((a[0] - b[0]).hypot(a[1] - b[1]));
            }
        }
    }
    worst
}

/// Scores features `f1` of an image and `f2` of the same image warped by
/// `hm` (both `size`): default ratio matching with Laplacian gating, then
/// the default MSAC homography.
pub fn score(f1: &Features, f2: &Features, hm: &Homography, size: (usize, usize)) -> Outcome {
    let (w, h) = size;
    let repeatability = repeatability(f1, f2, hm, size, size, 2.5);
    let matches = match_features(f1, f2, &MatchConfig::default());
    let precision_3px = precision(f1, f2, &matches, hm, 3.0);
    let scale_ok = matches
        .iter()
        .filter(|m| {
            let tol = (f2.keypoints[m.train].scale as f64).max(3.0);
            correct(f1, f2, m, hm, tol)
        })
        .count();
    let precision_scale = scale_ok as f64 / matches.len().max(1) as f64;
    let overlap_ok = matches
        .iter()
        .filter(|m| overlap_correct(f1, f2, m, hm, 0.5))
        .count();
    let precision_overlap = overlap_ok as f64 / matches.len().max(1) as f64;
    let (p1, p2) = pairs(f1, f2, &matches);
    let fit = fit_homography(&p1, &p2, &MsacConfig::default());
    let (inliers, inlier_precision, overlap_error_px, corner_error_px) = match &fit {
        Some(f) => {
            let good = f
                .inliers
                .iter()
                .filter(|&&i| correct(f1, f2, &matches[i], hm, 3.0))
                .count();
            (
                f.inliers.len(),
                good as f64 / f.inliers.len() as f64,
                overlap_error(&f.model, hm, w, h),
                corner_error(&f.model, hm, w, h),
            )
        }
        None => (0, 0.0, f64::INFINITY, f64::INFINITY),
    };
    Outcome {
        keypoints: (f1.len(), f2.len()),
        repeatability,
        matches: matches.len(),
        precision_3px,
        precision_scale,
        precision_overlap,
        inliers,
        inlier_precision,
        overlap_error_px,
        corner_error_px,
    }
}
