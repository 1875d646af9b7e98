//! SURF detection, orientation, MSAC and the boundary, on synthetic images
//! whose answers are known, and on bad input.

mod surf_support;

use slamlab::surf::orientation::{dominant_orientation, grid_weights, haar_responses, GRID_LEN};
use slamlab::surf::prng::SplitMix64;
use slamlab::surf::{
    extract, fit_homography, fit_similarity, GrayImage, Homography, IntegralImage, Keypoint,
    MatchedRegion, MsacConfig, SurfConfig, SurfError,
};
use surf_support::*;
use wasm_bindgen_test::wasm_bindgen_test;

fn blob_image(w: usize, h: usize, blobs: &[(f64, f64, f64, f64)]) -> GrayImage {
    let mut px = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut v = 128.0;
            for &(cx, cy, sigma, amp) in blobs {
                let d2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
                v += amp * (-d2 / (2.0 * sigma * sigma)).exp();
            }
            px[y * w + x] = v.round().clamp(0.0, 255.0) as u8;
        }
    }
    GrayImage::new(w, h, px).expect("valid")
}

/// The box-filter det(H) of a Gaussian blob of σ_b peaks at SURF scale
/// s ≈ 0.72 σ_b (measured over σ_b = 3..16: 0.68-0.78; the 9 × 9 filter's
/// "σ = 1.2" is nominal), so the reported scale follows the blob size.
const BLOB_SCALE_RATIO: f64 = 0.72;

#[wasm_bindgen_test(unsupported = test)]
fn gaussian_blobs_are_found_at_their_centre_and_scale() {
    // A bright and a dark blob at sub-pixel positions.
    let blobs = [(70.3, 64.6, 5.0, 100.0), (190.7, 121.2, 9.0, -100.0)];
    let img = blob_image(280, 200, &blobs);
    let f = extract(
        &img,
        &SurfConfig {
            threshold: 5.0,
            ..SurfConfig::default()
        },
    );
    for &(cx, cy, sigma, amp) in &blobs {
        let k = f
            .keypoints
            .iter()
            .min_by(|a, b| {
                let da = (a.x as f64 - cx).hypot(a.y as f64 - cy);
                let db = (b.x as f64 - cx).hypot(b.y as f64 - cy);
                da.total_cmp(&db)
            })
            .expect("a keypoint");
        let err = (k.x as f64 - cx).hypot(k.y as f64 - cy);
        let ratio = k.scale as f64 / sigma;
        assert!(
            err < 0.5,
            "blob at ({cx},{cy}) found at ({},{}), {err:.2} px off",
            k.x,
            k.y
        );
        assert!(
            (ratio / BLOB_SCALE_RATIO - 1.0).abs() < 0.12,
            "scale {} for sigma {sigma}",
            k.scale
        );
        assert_eq!(
            k.laplacian,
            if amp > 0.0 { -1 } else { 1 },
            "sign of the Laplacian"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn blob_scale_follows_blob_size() {
    for sigma in [4.0, 6.0, 8.0, 12.0] {
        let img = blob_image(240, 240, &[(120.4, 119.7, sigma, 110.0)]);
        let f = extract(
            &img,
            &SurfConfig {
                threshold: 5.0,
                ..SurfConfig::default()
            },
        );
        let k = f
            .keypoints
            .iter()
            .max_by(|a, b| a.response.total_cmp(&b.response))
            .expect("a keypoint");
        let ratio = k.scale as f64 / sigma;
        assert!(
            (ratio / BLOB_SCALE_RATIO - 1.0).abs() < 0.12,
            "sigma {sigma}: scale {}",
            k.scale
        );
        assert!(
            (k.x as f64 - 120.4).hypot(k.y as f64 - 119.7) < 0.1 * sigma + 0.5,
            "sigma {sigma}: at ({}, {})",
            k.x,
            k.y
        );
    }
}

/// Orientation rotates with the image: keypoints of a photograph, moved by a
/// known rotation, get orientations that differ by the rotation angle.
#[wasm_bindgen_test(unsupported = test)]
fn orientation_turns_with_the_image() {
    let img = load(ASTRONAUT);
    let ii1 = IntegralImage::new(&img);
    let weights = grid_weights();
    let (mut dx, mut dy) = ([0f32; GRID_LEN], [0f32; GRID_LEN]);
    let keypoints = slamlab::surf::FastHessian::new(&SurfConfig::default()).detect(&ii1);
    for deg in [30.0f64, 90.0, -45.0] {
        let hm = rot_scale(deg, 1.0, 319.5, 239.5, 0.0, 0.0);
        let ii2 = IntegralImage::new(&warp(&img, &hm, 640, 480));
        let mut errs = Vec::new();
        for k in keypoints
            .iter()
            .filter(|k| (k.x - 319.5).hypot(k.y - 239.5) < 150.0)
        {
            haar_responses(&ii1, k, &mut dx, &mut dy);
            let o1 = dominant_orientation(&weights, &dx, &dy) as f64;
            let p = hm.apply([k.x as f64, k.y as f64]).expect("finite");
            let k2 = Keypoint {
                x: p[0] as f32,
                y: p[1] as f32,
                ..*k
            };
            haar_responses(&ii2, &k2, &mut dx, &mut dy);
            let o2 = dominant_orientation(&weights, &dx, &dy) as f64;
            let d = o2 - o1 - deg.to_radians();
            errs.push(d.sin().atan2(d.cos()).abs().to_degrees());
        }
        errs.sort_by(f64::total_cmp);
        let median = errs[errs.len() / 2];
        let within10 = errs.iter().filter(|e| **e <= 10.0).count() as f64 / errs.len() as f64;
        println!("rotation {deg}°: {} keypoints, median orientation error {median:.2}°, {:.1}% within 10°", errs.len(), 100.0 * within10);
        assert!(errs.len() > 100);
        assert!(median < 5.0, "median orientation error {median}°");
        assert!(within10 > 0.8, "only {within10} within 10°");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn msac_recovers_a_homography_through_half_outliers() {
    let truth = Homography([
        [0.9, 0.12, 30.0],
        [-0.08, 1.05, 12.0],
        [0.0002, -0.0001, 1.0],
    ]);
    let mut rng = SplitMix64::new(1);
    let mut uniform =
        |lo: f64, hi: f64| lo + (hi - lo) * ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64);
    let (mut p1, mut p2) = (Vec::new(), Vec::new());
    for i in 0..200 {
        let p = [uniform(0.0, 640.0), uniform(0.0, 480.0)];
        let q = if i % 2 == 0 {
            let q = truth.apply(p).expect("finite");
            [q[0] + uniform(-0.5, 0.5), q[1] + uniform(-0.5, 0.5)]
        } else {
            [uniform(0.0, 640.0), uniform(0.0, 480.0)]
        };
        p1.push(p);
        p2.push(q);
    }
    let fit = fit_homography(&p1, &p2, &MsacConfig::default()).expect("a model");
    assert!(fit.inliers.iter().all(|i| i % 2 == 0
        || truth
            .apply(p1[*i])
            .is_some_and(|q| (q[0] - p2[*i][0]).hypot(q[1] - p2[*i][1]) < 3.0)));
    assert!(fit.inliers.len() >= 100, "{} inliers", fit.inliers.len());
    let err = corner_error(&fit.model, &truth, 640, 480);
    assert!(err < 0.5, "corner error {err}");
    // Deterministic: same inputs and seed, same answer.
    assert_eq!(
        fit,
        fit_homography(&p1, &p2, &MsacConfig::default()).expect("a model")
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn msac_recovers_a_similarity_and_the_region_reads_it_back() {
    let truth = rot_scale(12.0, 0.85, 319.5, 239.5, 20.0, -10.0);
    let p1: Vec<[f64; 2]> = (0..60)
        .map(|i| [(i * 37 % 640) as f64, (i * 53 % 480) as f64])
        .collect();
    let mut p2: Vec<[f64; 2]> = p1
        .iter()
        .map(|p| truth.apply(*p).expect("finite"))
        .collect();
    for q in p2.iter_mut().step_by(4) {
        q[0] += 150.0; // a quarter are outliers
    }
    let fit = fit_similarity(&p1, &p2, &MsacConfig::default()).expect("a model");
    assert_eq!(fit.inliers.len(), 45);
    assert!((fit.model.scale() - 0.85).abs() < 1e-9);
    assert!((fit.model.angle_rad().to_degrees() - 12.0).abs() < 1e-7);
    let region =
        MatchedRegion::new(&fit.model.to_homography(), (640, 480), (640, 480)).expect("finite");
    assert!(
        (region.shrinkage - 0.85).abs() < 1e-9,
        "shrinkage {}",
        region.shrinkage
    );
    assert!(
        (region.shift[0] - 20.0).abs() < 1e-6 && (region.shift[1] + 10.0).abs() < 1e-6,
        "shift {:?}",
        region.shift
    );
    assert!((region.left_right_ratio - 1.0).abs() < 1e-9);
}

#[wasm_bindgen_test(unsupported = test)]
fn msac_declines_too_few_or_degenerate_points() {
    let cfg = MsacConfig::default();
    assert!(fit_homography(&[], &[], &cfg).is_none());
    assert!(fit_homography(&[[0.0, 0.0]; 3], &[[0.0, 0.0]; 3], &cfg).is_none());
    let line: Vec<[f64; 2]> = (0..30).map(|i| [i as f64, 2.0 * i as f64]).collect();
    assert!(
        fit_homography(&line, &line, &cfg).is_none(),
        "collinear points define no homography"
    );
    let same = vec![[5.0, 5.0]; 30];
    assert!(fit_similarity(&same, &same, &cfg).is_none());
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_images_give_errors_or_no_keypoints() {
    assert_eq!(GrayImage::decode(&[]), Err(SurfError::Empty));
    assert!(matches!(
        GrayImage::decode(b"definitely not a picture"),
        Err(SurfError::NotAnImage(_))
    ));
    let truncated = &COFFEE[..COFFEE.len() / 3];
    assert!(
        GrayImage::decode(truncated).is_err(),
        "a truncated PNG is an error"
    );
    assert!(matches!(
        GrayImage::new(0, 5, vec![]),
        Err(SurfError::BadDimensions { .. })
    ));
    assert!(matches!(
        GrayImage::new(3, 3, vec![0; 8]),
        Err(SurfError::BadDimensions { .. })
    ));
    assert!(matches!(
        GrayImage::new(100_000, 100_000, vec![]),
        Err(SurfError::TooLarge { .. })
    ));
    assert!(matches!(
        GrayImage::decode(&huge_png_header()),
        Err(SurfError::TooLarge { .. })
    ));
    let cfg = SurfConfig::default();
    for (w, h) in [(1, 1), (8, 8), (9, 9), (1, 500), (500, 1), (30, 30)] {
        let img = noise_image(w, h, 3);
        let f = extract(&img, &cfg);
        assert_eq!(f.keypoints.len(), f.descriptors.len());
        for k in &f.keypoints {
            assert!(k.x >= -1.0 && k.y >= -1.0 && k.x <= w as f32 && k.y <= h as f32);
        }
    }
    for v in [0u8, 77, 255] {
        let flat = GrayImage::new(640, 480, vec![v; 640 * 480]).expect("valid");
        assert!(
            extract(&flat, &cfg).is_empty(),
            "a constant image has no keypoints"
        );
        assert!(extract(
            &flat,
            &SurfConfig {
                threshold: -1.0,
                ..cfg
            }
        )
        .is_empty());
    }
    let img = load(ASTRONAUT);
    for odd in [
        SurfConfig { octaves: 0, ..cfg },
        SurfConfig {
            intervals: 2,
            ..cfg
        },
        SurfConfig {
            intervals: 100,
            octaves: 100,
            ..cfg
        },
        SurfConfig {
            initial_step: 0,
            ..cfg
        },
        SurfConfig {
            threshold: f32::NAN,
            ..cfg
        },
    ] {
        let f = extract(&img, &odd);
        assert!(f
            .descriptors
            .iter()
            .all(|d| d.0.iter().all(|v| v.is_finite())));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn colour_jpeg_and_grey_png_decode_to_the_same_size() {
    let c = load(COFFEE_COLOR_JPG);
    let g = load(COFFEE);
    assert_eq!((c.width(), c.height()), (g.width(), g.height()));
    let mean_diff = c
        .pixels()
        .iter()
        .zip(g.pixels())
        .map(|(a, b)| (*a as f64 - *b as f64).abs())
        .sum::<f64>()
        / (640.0 * 480.0);
    // The PNG was made with Rec. 601 luma, the decoder uses Rec. 709, and the
    // JPEG is lossy: a few grey levels apart on average.
    assert!(
        mean_diff < 8.0,
        "luma of the JPEG is close to the PNG: {mean_diff}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn features_json_has_the_interface_fields() {
    let json = slamlab::lab::images::features_json(ASTRONAUT).expect("decodes");
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(v["width"], 640);
    assert_eq!(v["height"], 480);
    let kps = v["keypoints"].as_array().expect("array");
    assert!(kps.len() > 300);
    for k in kps {
        for field in ["x", "y", "scale", "orientation"] {
            assert!(k[field].is_f64(), "{field}");
        }
        assert!(k["laplacian"] == 1 || k["laplacian"] == -1);
        let d = k["descriptor"].as_array().expect("descriptor");
        assert_eq!(d.len(), 64);
        let norm: f64 = d.iter().map(|x| x.as_f64().expect("number").powi(2)).sum();
        assert!((norm - 1.0).abs() < 1e-4);
    }
    assert!(matches!(
        slamlab::lab::images::features_json(b"nope"),
        Err(SurfError::NotAnImage(_))
    ));
}

#[wasm_bindgen_test(unsupported = test)]
fn match_json_recovers_the_shipped_warped_pair() {
    let json = slamlab::lab::images::match_json(COFFEE, COFFEE_ROT12_S085).expect("decodes");
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert!(v["matches"].as_u64().expect("n") >= 50);
    assert!(v["inliers"].as_u64().expect("n") >= 40);
    let h: Vec<Vec<f64>> = serde_json::from_value(v["homography"].clone()).expect("3x3");
    let fitted = Homography([
        [h[0][0], h[0][1], h[0][2]],
        [h[1][0], h[1][1], h[1][2]],
        [h[2][0], h[2][1], h[2][2]],
    ]);
    let truth = rot_scale(12.0, 0.85, 319.5, 239.5, 0.0, 0.0);
    let err = corner_error(&fitted, &truth, 640, 480);
    assert!(err < 1.0, "corner error {err} px");
    assert_eq!(v["quad"].as_array().expect("quad").len(), 4);
    assert!((v["shrinkage"].as_f64().expect("shrinkage") - 0.85).abs() < 0.01);
    // No overlap: a photo against a constant image has no homography.
    let flat = png_of(&GrayImage::new(64, 64, vec![9; 64 * 64]).expect("valid"));
    let v: serde_json::Value =
        serde_json::from_str(&slamlab::lab::images::match_json(COFFEE, &flat).expect("ok"))
            .expect("json");
    assert_eq!(v["matches"], 0);
    assert!(v["homography"].is_null() && v["quad"].is_null());
}

fn png_of(img: &GrayImage) -> Vec<u8> {
    let mut out = Vec::new();
    let buf = image::GrayImage::from_raw(
        img.width() as u32,
        img.height() as u32,
        img.pixels().to_vec(),
    )
    .expect("size");
    buf.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .expect("encode");
    out
}

/// A PNG claiming 100000 × 100000 pixels, with a tiny (bogus) data chunk.
fn huge_png_header() -> Vec<u8> {
    fn chunk(png: &mut Vec<u8>, kind: &[u8], data: &[u8]) {
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        let mut crc = 0xFFFF_FFFFu32;
        for &b in &body {
            crc ^= b as u32;
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        png.extend_from_slice(&(data.len() as u32).to_be_bytes());
        png.extend_from_slice(&body);
        png.extend_from_slice(&(!crc).to_be_bytes());
    }
    let mut png = vec![0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];
    let mut ihdr = 100_000u32.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
    chunk(&mut png, b"IHDR", &ihdr);
    chunk(
        &mut png,
        b"IDAT",
        &[0x78, 0x9C, 0x63, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01],
    );
    chunk(&mut png, b"IEND", &[]);
    png
}

#[wasm_bindgen_test(unsupported = test)]
fn matching_gates_on_laplacian_sign_and_mutual_check_is_reciprocal() {
    use slamlab::surf::{match_features, MatchConfig};
    let img = load(CHELSEA);
    let warped = warp(
        &img,
        &rot_scale(12.0, 0.85, 319.5, 239.5, 0.0, 0.0),
        640,
        480,
    );
    let cfg = SurfConfig::default();
    let (f1, f2) = (extract(&img, &cfg), extract(&warped, &cfg));
    let plain = match_features(&f1, &f2, &MatchConfig::default());
    assert!(plain
        .iter()
        .all(|m| f1.keypoints[m.query].laplacian == f2.keypoints[m.train].laplacian));
    assert!(plain.iter().all(|m| m.distance >= 0.0 && m.distance <= 2.0));
    let mutual = match_features(
        &f1,
        &f2,
        &MatchConfig {
            mutual: true,
            ..MatchConfig::default()
        },
    );
    assert!(!mutual.is_empty() && mutual.len() <= plain.len());
    assert!(
        mutual.iter().all(|m| plain.contains(m)),
        "mutual matches are a subset"
    );
    // Reciprocal: matching back from image 2 finds the same pairs.
    let back = match_features(
        &f2,
        &f1,
        &MatchConfig {
            mutual: true,
            ratio: 1.0,
            ..MatchConfig::default()
        },
    );
    for m in &mutual {
        assert!(
            back.iter()
                .any(|b| b.query == m.train && b.train == m.query),
            "{m:?} is reciprocal"
        );
    }
    // A stricter ratio keeps fewer matches; no gating considers more pairs.
    let strict = match_features(
        &f1,
        &f2,
        &MatchConfig {
            ratio: 0.6,
            ..MatchConfig::default()
        },
    );
    assert!(strict.len() < plain.len());
    let ungated = match_features(
        &f1,
        &f2,
        &MatchConfig {
            laplacian_gating: false,
            ..MatchConfig::default()
        },
    );
    assert!(!ungated.is_empty());
}
