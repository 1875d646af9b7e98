//! The SURF hot-loop kernels (`slamlab::surf::simd`): each portable kernel
//! against a brute-force reference, and, in wasm builds (with or without
//! `+simd128` — the SIMD twins carry their own `#[target_feature]`), each
//! SIMD128 kernel against its scalar twin: bit-exact for the integer stages
//! and, because both twins do the same float operations in the same order,
//! bit-exact for the float kernels too.

mod surf_support;

use slamlab::surf::hessian::{filter_size, ResponseLayer};
use slamlab::surf::prng::SplitMix64;
use slamlab::surf::simd;
use slamlab::surf::IntegralImage;
use surf_support::noise_image;
use wasm_bindgen_test::wasm_bindgen_test;

fn random_f32(n: usize, seed: u64) -> Vec<f32> {
    let mut r = SplitMix64::new(seed);
    (0..n)
        .map(|_| ((r.next_u64() >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0)
        .collect()
}

#[wasm_bindgen_test(unsupported = test)]
fn integral_image_equals_brute_force_sums() {
    for (w, h) in [
        (1, 1),
        (1, 7),
        (7, 1),
        (15, 3),
        (16, 16),
        (17, 5),
        (33, 21),
        (64, 48),
    ] {
        let img = noise_image(w, h, (w * 131 + h) as u64);
        let ii = IntegralImage::new(&img);
        for y in 0..=h {
            for x in 0..=w {
                let mut s = 0u32;
                for yy in 0..y {
                    for xx in 0..x {
                        s += img.get(xx, yy) as u32;
                    }
                }
                assert_eq!(ii.at(x, y), s, "{w}x{h} at ({x},{y})");
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn integral_box_sums_stay_exact_when_the_table_wraps() {
    // 4200 x 4000 white pixels sum to 4.28e9, past 2^32 at the far corner;
    // box sums near there are still exact.
    let (w, h) = (4200, 4000);
    let ii = IntegralImage::from_pixels(&vec![255u8; w * h], w, h);
    let s = ii.box_sum_clipped(w as i64 - 100, h as i64 - 50, w as i64, h as i64);
    assert_eq!(s, 100 * 50 * 255);
}

/// Brute-force Dxx, Dyy, Dxy of the filter of side L at pixel (x, y), from
/// the lobe geometry of Bay et al. Fig. 1 (not from the taps).
fn brute_hessian(img: &slamlab::surf::GrayImage, l: usize, x: usize, y: usize) -> f32 {
    let lobe = (l / 3) as i64;
    let half = (l / 2) as i64;
    let p = |dx: i64, dy: i64| img.get((x as i64 + dx) as usize, (y as i64 + dy) as usize) as i64;
    let (mut dxx, mut dyy, mut dxy) = (0i64, 0i64, 0i64);
    for dy in -half..=half {
        for dx in -half..=half {
            // Dxx: three lobes along x, each `lobe` wide, 2·lobe-1 tall; weights 1, -2, 1.
            if dy.abs() < lobe {
                let w = if dx.abs() <= (lobe - 1) / 2 { -2 } else { 1 };
                dxx += w * p(dx, dy);
            }
            if dx.abs() < lobe {
                let w = if dy.abs() <= (lobe - 1) / 2 { -2 } else { 1 };
                dyy += w * p(dx, dy);
            }
            if (1..=lobe).contains(&dx.abs()) && (1..=lobe).contains(&dy.abs()) {
                dxy += if (dx > 0) == (dy > 0) {
                    p(dx, dy)
                } else {
                    -p(dx, dy)
                };
            }
        }
    }
    let inv = 1.0 / (l * l) as f32;
    let (dxx, dyy, dxy) = (dxx as f32 * inv, dyy as f32 * inv, dxy as f32 * inv);
    dxx * dyy - 0.81 * (dxy * dxy)
}

#[wasm_bindgen_test(unsupported = test)]
fn box_filter_responses_equal_brute_force_at_every_step() {
    let img = noise_image(83, 77, 9);
    let ii = IntegralImage::new(&img);
    for (o, i) in [(0, 0), (0, 1), (0, 3), (1, 2), (2, 0)] {
        let l = filter_size(o, i);
        for step in [1, 2, 3, 4, 8] {
            let layer = ResponseLayer::compute(&ii, l, step);
            let (c0, c1, r0, r1) = layer.valid.expect("filter fits");
            assert!(c0 * step >= l / 2 && c1 * step + l / 2 < 83, "valid window");
            for r in r0..=r1 {
                for c in c0..=c1 {
                    let want = brute_hessian(&img, l, c * step, r * step);
                    assert_eq!(layer.at(c, r), want, "L {l} step {step} at ({c},{r})");
                }
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn phase_split_puts_every_column_in_its_plane() {
    let img = noise_image(37, 11, 21);
    let ii = IntegralImage::new(&img);
    let (cols, rows) = (38usize, 12usize);
    for step in [1, 2, 3, 4] {
        let pstride = cols.div_ceil(step);
        let plane_len = pstride * rows;
        let mut out = vec![0u32; plane_len * step];
        simd::phase_split(ii.data(), cols, rows, step, &mut out);
        for y in 0..rows {
            for x in 0..cols {
                assert_eq!(
                    out[(x % step) * plane_len + y * pstride + x / step],
                    ii.at(x, y),
                    "step {step} ({x},{y})"
                );
            }
        }
    }
}

/// The lattice wavelets equal Haar wavelets computed from box sums: with
/// lattice corners 3 pixels apart, wavelet (i, j) spans lattice columns
/// i..=i+4 and rows j..=j+4.
#[wasm_bindgen_test(unsupported = test)]
fn lattice_haar_equals_brute_force() {
    let img = noise_image(90, 80, 4);
    let ii = IntegralImage::new(&img);
    let (x0, y0, step) = (10usize, 7usize, 3usize);
    let mut table = [0u32; 340];
    for l in 0..17 {
        for k in 0..20 {
            table[l * 20 + k] = ii.at(x0 + k.min(16) * step, y0 + l * step);
        }
    }
    let (mut dx, mut dy) = ([0f32; 208], [0f32; 208]);
    simd::lattice_haar(&table, &mut dx, &mut dy);
    let b = |x: usize, y: usize, w: usize, h: usize| {
        ii.box_sum_clipped(x as i64, y as i64, (x + w) as i64, (y + h) as i64) as f32
    };
    for j in 0..13 {
        for i in 0..13 {
            let (x, y, h) = (x0 + i * step, y0 + j * step, 2 * step);
            assert_eq!(
                dx[j * 16 + i],
                b(x + h, y, h, 2 * h) - b(x, y, h, 2 * h),
                "dx ({i},{j})"
            );
            assert_eq!(
                dy[j * 16 + i],
                b(x, y + h, 2 * h, h) - b(x, y, 2 * h, h),
                "dy ({i},{j})"
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn patch_box_sums_equal_brute_force_boxes() {
    let img = noise_image(120, 100, 8);
    let ii = IntegralImage::new(&img);
    for (deg, scale, n, cx, cy) in [
        (0.0f32, 2.0f32, 2usize, 60.3f32, 49.8f32),
        (33.0, 2.3, 2, 60.3, 49.8),
        (-120.0, 1.6, 2, 60.3, 49.8),
        (75.0, 2.9, 3, 60.3, 49.8),
        (20.0, 3.1, 3, 4.0, 95.0), // partly outside: clipped boxes
    ] {
        let (sin, cos) = deg.to_radians().sin_cos();
        let edge = 0.5 - n as f32 / 2.0;
        let g = simd::PatchGeometry {
            x0: cx + edge,
            y0: cy + edge,
            cos,
            sin,
            s: scale,
            n,
        };
        let mut out = [0f32; 441];
        simd::patch_box_sums(ii.data(), 120, 100, &g, &mut out);
        for j in 0..21 {
            for i in 0..21 {
                let (u, v) = ((i as f32 - 10.0) * scale, (j as f32 - 10.0) * scale);
                let x = (g.x0 + u * cos - v * sin).round_ties_even() as i64;
                let y = (g.y0 + u * sin + v * cos).round_ties_even() as i64;
                let want = ii.box_sum_clipped(x, y, x + n as i64, y + n as i64) as f32;
                assert_eq!(out[j * 21 + i], want, "{deg}° sample ({i},{j})");
            }
        }
    }
}

/// Inside the image the fast kernel equals the clipping one.
#[wasm_bindgen_test(unsupported = test)]
fn patch_box_sums_inside_equal_the_clipped_kernel_inside() {
    let img = noise_image(160, 140, 12);
    let ii = IntegralImage::new(&img);
    for (deg, scale, n) in [(0.0f32, 2.0f32, 2usize), (41.0, 2.6, 3), (-150.0, 3.4, 3)] {
        let (sin, cos) = deg.to_radians().sin_cos();
        let g = simd::PatchGeometry {
            x0: 80.4,
            y0: 69.6,
            cos,
            sin,
            s: scale,
            n,
        };
        let (mut a, mut b) = ([0f32; 441], [0f32; 441]);
        simd::patch_box_sums(ii.data(), 160, 140, &g, &mut a);
        simd::patch_box_sums_inside(ii.data(), ii.stride(), &g, &mut b);
        assert_eq!(a, b, "{deg}°");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn orientation_bins_match_atan2() {
    let n = 109;
    let w = random_f32(n, 5)
        .iter()
        .map(|v| v.abs() + 0.1)
        .collect::<Vec<_>>();
    let mut dx = random_f32(n, 6);
    let mut dy = random_f32(n, 7);
    (dx[0], dy[0], dx[1], dy[1], dx[2], dy[2]) = (0.0, 0.0, -1.0, 0.0, 0.0, -1.0);
    let (mut gx, mut gy, mut bin) = (vec![0f32; n], vec![0f32; n], vec![0u32; n]);
    simd::orientation_bins(&w, &dx, &dy, 72, &mut gx, &mut gy, &mut bin);
    for i in 0..n {
        assert_eq!((gx[i], gy[i]), (w[i] * dx[i], w[i] * dy[i]));
        let a = (gy[i] as f64)
            .atan2(gx[i] as f64)
            .rem_euclid(std::f64::consts::TAU);
        let exact = a * 72.0 / std::f64::consts::TAU;
        // Equal to the exact bin unless the angle lies within 1e-4 rad of a bin edge.
        if (exact - exact.round()).abs() > 1e-3 {
            assert_eq!(
                bin[i],
                (exact.floor() as u32).min(71),
                "sample {i}: angle {a}"
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn float_kernels_equal_plain_formulas() {
    let patch: [f32; 441] = random_f32(441, 1).try_into().expect("441");
    let w: [f32; 400] = random_f32(400, 2).try_into().expect("400");
    let (mut du, mut dv) = ([0f32; 400], [0f32; 400]);
    simd::patch_wavelets(&patch, &w, &mut du, &mut dv);
    for j in 0..20 {
        for i in 0..20 {
            let (a, b, c, d) = (
                patch[j * 21 + i],
                patch[j * 21 + i + 1],
                patch[j * 21 + 21 + i],
                patch[j * 21 + 22 + i],
            );
            assert!((du[j * 20 + i] - w[j * 20 + i] * (b - a + d - c)).abs() < 1e-5);
            assert!((dv[j * 20 + i] - w[j * 20 + i] * (c - a + d - b)).abs() < 1e-5);
        }
    }
    let mut sums = [0f32; 64];
    simd::descriptor_sums(&du, &dv, &mut sums);
    for sj in 0..4 {
        for si in 0..4 {
            let mut want = [0f64; 4];
            for j in sj * 5..sj * 5 + 5 {
                for i in si * 5..si * 5 + 5 {
                    let (u, v) = (du[j * 20 + i] as f64, dv[j * 20 + i] as f64);
                    want = [
                        want[0] + u,
                        want[1] + v,
                        want[2] + u.abs(),
                        want[3] + v.abs(),
                    ];
                }
            }
            for q in 0..4 {
                assert!((sums[(sj * 4 + si) * 4 + q] as f64 - want[q]).abs() < 1e-4);
            }
        }
    }
    let q: [f32; 64] = random_f32(64, 3).try_into().expect("64");
    let cands: Vec<[f32; 64]> = (0..9)
        .map(|k| random_f32(64, 10 + k).try_into().expect("64"))
        .collect();
    let mut dots = vec![0f32; 9];
    simd::dot64_many(&q, &cands, &mut dots);
    for (c, d) in cands.iter().zip(&dots) {
        let want: f64 = q.iter().zip(c).map(|(a, b)| *a as f64 * *b as f64).sum();
        assert!((*d as f64 - want).abs() < 1e-5);
    }
}

/// In wasm builds: every SIMD128 kernel equals its scalar twin bit for bit.
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen_test]
fn simd128_kernels_equal_their_scalar_twins() {
    use slamlab::surf::hessian::hessian_taps;
    use slamlab::surf::simd::{scalar, simd128, INTEGRAL_PAD};
    // Integral image, several widths around the 16-pixel blocks.
    for (w, h) in [(1, 3), (15, 4), (16, 4), (17, 9), (40, 33), (641, 3)] {
        let img = noise_image(w, h, w as u64);
        let n = (w + 1) * (h + 1) + INTEGRAL_PAD;
        let (mut a, mut b) = (vec![7u32; n], vec![7u32; n]);
        scalar::integral_image(img.pixels(), w, h, &mut a);
        unsafe { simd128::integral_image(img.pixels(), w, h, &mut b) };
        assert_eq!(a, b, "integral {w}x{h}");
    }
    // Hessian rows at steps 1 (contiguous), 2 (shuffle), 3, 4, 8 (gathers).
    let img = noise_image(200, 120, 5);
    let ii = IntegralImage::new(&img);
    for l in [9, 15, 27, 51] {
        let taps = hessian_taps(l, ii.stride());
        for step in [1, 2, 3, 4, 8] {
            let y = 60;
            let x0 = l / 2;
            let n = (200 - 1 - l / 2 - x0) / step + 1;
            let p0 = y * ii.stride() + x0;
            let (mut a, mut b) = (vec![0f32; n], vec![0f32; n]);
            scalar::hessian_row(ii.data(), &taps, p0, step, &mut a);
            unsafe { simd128::hessian_row(ii.data(), &taps, p0, step, &mut b) };
            assert_eq!(a, b, "hessian L {l} step {step}");
        }
    }
    // Lattice wavelets.
    let stride = ii.stride();
    let table: [u32; 340] =
        std::array::from_fn(|k| ii.data()[(k / 20) * 7 * stride + (k % 20) * 9]);
    let (mut ax, mut ay, mut bx, mut by) = ([0f32; 208], [0f32; 208], [0f32; 208], [0f32; 208]);
    scalar::lattice_haar(&table, &mut ax, &mut ay);
    unsafe { simd128::lattice_haar(&table, &mut bx, &mut by) };
    assert_eq!((ax, ay), (bx, by), "lattice wavelets");
    // Patch resampling at several angles and scales.
    for (deg, scale, n) in [
        (0.0f32, 2.0f32, 2usize),
        (33.0, 2.3, 2),
        (-120.0, 4.6, 5),
        (75.0, 9.9, 10),
        (10.0, 3.0, 3),
    ] {
        let (sin, cos) = deg.to_radians().sin_cos();
        // Centre far inside, and (for the last) 190 px from the left: clipped.
        let g = simd::PatchGeometry {
            x0: if n == 3 { 190.2 } else { 100.3 },
            y0: 60.8,
            cos,
            sin,
            s: scale,
            n,
        };
        let (mut a, mut b) = ([0f32; 441], [0f32; 441]);
        scalar::patch_box_sums(ii.data(), 200, 120, &g, &mut a);
        unsafe { simd128::patch_box_sums(ii.data(), 200, 120, &g, &mut b) };
        assert_eq!(a, b, "patch {deg}° s {scale}");
    }
    for (deg, scale, n) in [(0.0f32, 2.0f32, 2usize), (33.0, 2.3, 2), (-120.0, 4.6, 5)] {
        let (sin, cos) = deg.to_radians().sin_cos();
        let g = simd::PatchGeometry {
            x0: 100.3,
            y0: 60.8,
            cos,
            sin,
            s: scale,
            n,
        };
        let (mut a, mut b) = ([0f32; 441], [0f32; 441]);
        scalar::patch_box_sums_inside(ii.data(), stride, &g, &mut a);
        unsafe { simd128::patch_box_sums_inside(ii.data(), stride, &g, &mut b) };
        assert_eq!(a, b, "inside patch {deg}° s {scale}");
    }
    // Phase split of integral rows of several widths, steps 2 and 4 (SIMD) and 3 (fallback).
    for (w, h) in [(7, 3), (16, 5), (33, 9), (641, 4)] {
        let img = noise_image(w, h, 77);
        let ii = IntegralImage::new(&img);
        for step in [2, 3, 4] {
            let n = (w + 1).div_ceil(step) * (h + 1) * step;
            let (mut a, mut b) = (vec![0u32; n], vec![0u32; n]);
            scalar::phase_split(ii.data(), w + 1, h + 1, step, &mut a);
            unsafe { simd128::phase_split(ii.data(), w + 1, h + 1, step, &mut b) };
            assert_eq!(a, b, "phase split {w}x{h} step {step}");
        }
    }
    // Orientation bins.
    let w = random_f32(109, 5);
    let (dx, dy) = (random_f32(109, 6), random_f32(109, 7));
    let (mut ax, mut ay, mut ab) = (vec![0f32; 109], vec![0f32; 109], vec![0u32; 109]);
    let (mut bx, mut by, mut bb) = (vec![0f32; 109], vec![0f32; 109], vec![0u32; 109]);
    scalar::orientation_bins(&w, &dx, &dy, 72, &mut ax, &mut ay, &mut ab);
    unsafe { simd128::orientation_bins(&w, &dx, &dy, 72, &mut bx, &mut by, &mut bb) };
    assert_eq!((ax, ay, ab), (bx, by, bb), "orientation bins");
    // Float kernels.
    let patch: [f32; 441] = random_f32(441, 1).try_into().expect("441");
    let w: [f32; 400] = random_f32(400, 2).try_into().expect("400");
    let (mut au, mut av, mut bu, mut bv) = ([0f32; 400], [0f32; 400], [0f32; 400], [0f32; 400]);
    scalar::patch_wavelets(&patch, &w, &mut au, &mut av);
    unsafe { simd128::patch_wavelets(&patch, &w, &mut bu, &mut bv) };
    assert_eq!((au, av), (bu, bv), "patch wavelets");
    let (mut a, mut b) = ([0f32; 64], [0f32; 64]);
    scalar::descriptor_sums(&au, &av, &mut a);
    unsafe { simd128::descriptor_sums(&au, &av, &mut b) };
    assert_eq!(a, b, "descriptor sums");
    let q: [f32; 64] = random_f32(64, 3).try_into().expect("64");
    let cands: Vec<[f32; 64]> = (0..33)
        .map(|k| random_f32(64, 10 + k).try_into().expect("64"))
        .collect();
    let (mut a, mut b) = (vec![0f32; 33], vec![0f32; 33]);
    scalar::dot64_many(&q, &cands, &mut a);
    unsafe { simd128::dot64_many(&q, &cands, &mut b) };
    assert_eq!(a, b, "dot64");
}

#[wasm_bindgen_test(unsupported = test)]
fn build_reports_its_kernels() {
    assert_eq!(
        simd::SIMD128,
        cfg!(all(target_arch = "wasm32", target_feature = "simd128"))
    );
}
