//! SURF quality on real photographs warped by known homographies (bilinear
//! resampling in `surf_support`): repeatability, matching precision, and the
//! homography MSAC recovers. The numbers are printed (`--nocapture`) and
//! pinned below what was measured, so a regression fails.
//!
//! Definitions (see `surf_support`):
//! - repeatability: share of keypoints visible in both images that have a
//!   counterpart within 2.5 px and a factor 1.5 in scale;
//! - precision@3px: share of ratio-test matches whose image-2 keypoint lies
//!   within 3 px of where the true homography sends the image-1 keypoint;
//! - precision@σ: the same with a tolerance of max(3 px, s₂), s₂ the image-2
//!   keypoint's scale (a scale-relative criterion in the spirit of
//!   Mikolajczyk and Schmid's overlap error);
//! - precision (overlap): the standard protocol's criterion itself
//!   (Mikolajczyk and Schmid 2005, as Bay et al. 2008 evaluate SURF): the
//!   two keypoints' regions, normalised to a 30 px radius, overlap with an
//!   error below 50 % ([`surf_support::overlap_correct`]);
//! - overlap error: largest distance, over a grid of image-1 points that
//!   land inside image 2, between the fitted and the true homography (for
//!   the 12°/0.85 view this is the corner error: all corners stay inside).

mod surf_support;

use slamlab::surf::{extract, GrayImage, Homography, SurfConfig};
use surf_support::*;
use wasm_bindgen_test::wasm_bindgen_test;

fn evaluate(name: &str, img: &GrayImage, hm: &Homography) -> Outcome {
    let (w, h) = (img.width(), img.height());
    let warped = warp(img, hm, w, h);
    let cfg = SurfConfig::default();
    let (f1, f2) = (extract(img, &cfg), extract(&warped, &cfg));
    let o = score(&f1, &f2, hm, (w, h));
    println!("{}", o.row(name));
    o
}

#[wasm_bindgen_test(unsupported = test)]
fn rotation_12_scale_085_recovers_the_homography_to_a_pixel() {
    println!("{HEADER}");
    for (name, bytes) in [
        ("astronaut", ASTRONAUT),
        ("coffee", COFFEE),
        ("chelsea", CHELSEA),
    ] {
        let img = load(bytes);
        let (view, hm, _) = &views()[0];
        let o = evaluate(&format!("{name} {view}"), &img, hm);
        assert!(
            o.corner_error_px <= 1.0,
            "{name}: corner error {}",
            o.corner_error_px
        );
        assert!(
            o.inlier_precision >= 0.97,
            "{name}: inlier precision {}",
            o.inlier_precision
        );
        assert!(o.matches >= 200, "{name}: matches {}", o.matches);
        assert!(
            o.repeatability >= 0.45,
            "{name}: repeatability {}",
            o.repeatability
        );
        assert!(
            o.precision_3px >= 0.65,
            "{name}: precision@3px {}",
            o.precision_3px
        );
        assert!(
            o.precision_scale >= 0.75,
            "{name}: precision@σ {}",
            o.precision_scale
        );
        // Measured 0.898-0.953; the issue asks for 0.95 (not yet met).
        assert!(
            o.precision_overlap >= 0.85,
            "{name}: precision (overlap) {}",
            o.precision_overlap
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn harder_views_still_give_a_good_homography() {
    println!("{HEADER}");
    for (iname, bytes) in [
        ("astronaut", ASTRONAUT),
        ("coffee", COFFEE),
        ("chelsea", CHELSEA),
    ] {
        let img = load(bytes);
        for (name, hm, max_err) in &views()[1..] {
            let o = evaluate(&format!("{iname} {name}"), &img, hm);
            assert!(
                o.overlap_error_px <= *max_err,
                "{iname} {name}: overlap error {}",
                o.overlap_error_px
            );
            assert!(o.inliers >= 60, "{iname} {name}: inliers {}", o.inliers);
            assert!(
                o.inlier_precision >= 0.9,
                "{iname} {name}: inlier precision {}",
                o.inlier_precision
            );
            assert!(
                o.precision_3px >= 0.45,
                "{iname} {name}: precision@3px {}",
                o.precision_3px
            );
        }
    }
}
