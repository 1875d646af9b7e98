//! # The image sessions behind `features`, `match` and `bench-surf`
//!
//! Images cross as encoded PNG/JPEG bytes (decoded with size limits, see
//! [`crate::surf::gray`]) or as canvas RGBA; results are the `features` and
//! `match` JSON of `docs/interfaces.md`. [`ImageBench`] and [`MatchBench`]
//! hold a decoded image (or two described ones) so a benchmark times SURF
//! alone, stage by stage.

use serde_json::{json, Value};

use crate::surf::{
    extract, fit_homography, match_features, Features, GrayImage, MatchConfig, MatchedRegion,
    MsacConfig, SurfConfig, SurfError,
};

fn features_value(image: &GrayImage, features: &Features) -> Value {
    let keypoints: Vec<Value> = features
        .keypoints
        .iter()
        .zip(&features.descriptors)
        .map(|(kp, d)| {
            json!({
                "x": kp.x, "y": kp.y, "scale": kp.scale, "orientation": kp.orientation,
                "laplacian": kp.laplacian, "response": kp.response, "descriptor": d.0.to_vec(),
            })
        })
        .collect();
    json!({ "width": image.width(), "height": image.height(), "keypoints": keypoints })
}

/// `features` JSON of an encoded image with the default settings.
pub fn features_json(bytes: &[u8]) -> Result<String, SurfError> {
    let image = GrayImage::decode(bytes)?;
    let features = extract(&image, &SurfConfig::default());
    Ok(features_value(&image, &features).to_string())
}

/// `match` JSON of two encoded images: ratio-test matches, MSAC
/// homography (image 1 pixels to image 2 pixels) and the matched region.
pub fn match_json(bytes1: &[u8], bytes2: &[u8]) -> Result<String, SurfError> {
    let image1 = GrayImage::decode(bytes1)?;
    let image2 = GrayImage::decode(bytes2)?;
    let config = SurfConfig::default();
    let (f1, f2) = (extract(&image1, &config), extract(&image2, &config));
    Ok(match_value(&image1, &f1, &image2, &f2).to_string())
}

fn match_value(image1: &GrayImage, f1: &Features, image2: &GrayImage, f2: &Features) -> Value {
    let matches = match_features(f1, f2, &MatchConfig::default());
    let p1: Vec<[f64; 2]> = matches.iter().map(|m| pt(f1, m.query)).collect();
    let p2: Vec<[f64; 2]> = matches.iter().map(|m| pt(f2, m.train)).collect();
    let fit = fit_homography(&p1, &p2, &MsacConfig::default());
    let region = fit.as_ref().and_then(|f| {
        MatchedRegion::new(
            &f.model,
            (image1.width(), image1.height()),
            (image2.width(), image2.height()),
        )
    });
    json!({
        "matches": matches.len(),
        "inliers": fit.as_ref().map_or(0, |f| f.inliers.len()),
        "homography": fit.as_ref().map(|f| f.model.0.to_vec()),
        "quad": region.map(|r| r.quad.to_vec()),
        "shrinkage": region.map(|r| r.shrinkage),
        "shift": region.map(|r| r.shift.to_vec()),
        "left_right_ratio": region.map(|r| r.left_right_ratio),
        "keypoints": [f1.len(), f2.len()],
    })
}

fn pt(f: &Features, i: usize) -> [f64; 2] {
    let k = &f.keypoints[i];
    [k.x as f64, k.y as f64]
}
/// `features` JSON of straight RGBA pixels (a canvas `ImageData`).
pub fn features_rgba_json(rgba: &[u8], width: u32, height: u32) -> Result<String, SurfError> {
    let image = GrayImage::from_rgba(width as usize, height as usize, rgba)?;
    let features = extract(&image, &SurfConfig::default());
    Ok(features_value(&image, &features).to_string())
}

/// True when this build uses the SIMD128 kernels.
pub fn simd() -> bool {
    crate::surf::simd::SIMD128
}

/// A decoded image held in wasm memory, so that a benchmark times SURF
/// alone: `run()` is one detect + describe with the default settings.
pub struct ImageBench {
    image: GrayImage,
    /// Intermediate results for the per-stage timings.
    integral: Option<crate::surf::IntegralImage>,
    keypoints: Vec<crate::surf::Keypoint>,
}

impl ImageBench {
    /// Decodes a PNG/JPEG.
    pub fn new(bytes: &[u8]) -> Result<ImageBench, SurfError> {
        let image = GrayImage::decode(bytes)?;
        Ok(ImageBench {
            image,
            integral: None,
            keypoints: Vec::new(),
        })
    }
    /// Detect + describe once; returns the number of keypoints.
    pub fn run(&self) -> u32 {
        extract(&self.image, &SurfConfig::default()).len() as u32
    }
    /// Stage 1 alone: builds (and keeps) the integral image.
    pub fn stage_integral(&mut self) -> u32 {
        self.integral = Some(crate::surf::IntegralImage::new(&self.image));
        1
    }
    /// Stage 2 alone: Fast-Hessian on the kept integral image; keeps the keypoints.
    pub fn stage_detect(&mut self) -> u32 {
        let ii = self
            .integral
            .get_or_insert_with(|| crate::surf::IntegralImage::new(&self.image));
        self.keypoints = crate::surf::FastHessian::new(&SurfConfig::default()).detect(ii);
        self.keypoints.len() as u32
    }
    /// Stage 3 alone: orientations of the kept keypoints.
    pub fn stage_orientation(&mut self) -> u32 {
        let ii = self
            .integral
            .get_or_insert_with(|| crate::surf::IntegralImage::new(&self.image));
        crate::surf::orientation::assign_orientations(ii, &mut self.keypoints);
        self.keypoints.len() as u32
    }
    /// Stage 4 alone: descriptors of the kept keypoints.
    pub fn stage_describe(&mut self) -> u32 {
        let ii = self
            .integral
            .get_or_insert_with(|| crate::surf::IntegralImage::new(&self.image));
        crate::surf::descriptor::describe_all(ii, &self.keypoints).len() as u32
    }
    pub fn width(&self) -> u32 {
        self.image.width() as u32
    }
    pub fn height(&self) -> u32 {
        self.image.height() as u32
    }
}

/// Two images already described, so that a benchmark times matching +
/// MSAC alone: `run()` matches, fits and returns the inlier count.
pub struct MatchBench {
    f1: Features,
    f2: Features,
}

impl MatchBench {
    /// Decodes and describes both PNG/JPEG images.
    pub fn new(bytes1: &[u8], bytes2: &[u8]) -> Result<MatchBench, SurfError> {
        let config = SurfConfig::default();
        let f1 = extract(&GrayImage::decode(bytes1)?, &config);
        let f2 = extract(&GrayImage::decode(bytes2)?, &config);
        Ok(MatchBench { f1, f2 })
    }
    /// Match + MSAC once; returns the number of inliers (0 without a model).
    pub fn run(&self) -> u32 {
        let matches = match_features(&self.f1, &self.f2, &MatchConfig::default());
        let p1: Vec<[f64; 2]> = matches.iter().map(|m| pt(&self.f1, m.query)).collect();
        let p2: Vec<[f64; 2]> = matches.iter().map(|m| pt(&self.f2, m.train)).collect();
        fit_homography(&p1, &p2, &MsacConfig::default()).map_or(0, |f| f.inliers.len() as u32)
    }
}
