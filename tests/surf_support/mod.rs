//! Test support for the SURF tests: loading the shipped photographs,
//! warping them by known homographies (bilinear resampling, written here so
//! the tests do not trust the code under test), and the repeatability and
//! matching-precision measures.
#![allow(dead_code)]

use slamlab::surf::{Features, GrayImage, Homography, Match};

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
