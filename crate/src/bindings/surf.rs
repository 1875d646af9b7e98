//! # JavaScript boundary of the image sessions ([`crate::lab::images`])
//!
//! `features` and `match` JSON of PNG/JPEG bytes or canvas RGBA, and the
//! benchmark sessions `SurfBench` / `SurfMatchBench`. Converts only.

use wasm_bindgen::prelude::*;

use super::convert::js_err;
use crate::lab::images::{self, ImageBench, MatchBench};

/// SURF keypoints and descriptors of a PNG/JPEG, as the `features` JSON.
#[wasm_bindgen]
pub fn surf_features(bytes: &[u8]) -> Result<String, JsError> {
    images::features_json(bytes).map_err(js_err)
}

/// SURF keypoints of straight RGBA pixels (a canvas `ImageData`), as the
/// `features` JSON.
#[wasm_bindgen]
pub fn surf_features_rgba(rgba: &[u8], width: u32, height: u32) -> Result<String, JsError> {
    images::features_rgba_json(rgba, width, height).map_err(js_err)
}

/// Matches of two PNG/JPEG images with MSAC, as the `match` JSON.
#[wasm_bindgen]
pub fn surf_match(bytes1: &[u8], bytes2: &[u8]) -> Result<String, JsError> {
    images::match_json(bytes1, bytes2).map_err(js_err)
}

/// True when this wasm build uses the SIMD128 kernels.
#[wasm_bindgen]
pub fn surf_simd() -> bool {
    images::simd()
}

/// A decoded image held in wasm memory, so that a benchmark times SURF
/// alone: `run()` is one detect + describe with the default settings.
#[wasm_bindgen]
pub struct SurfBench {
    inner: ImageBench,
}

#[wasm_bindgen]
impl SurfBench {
    /// Decodes a PNG/JPEG.
    #[wasm_bindgen(constructor)]
    pub fn new(bytes: &[u8]) -> Result<SurfBench, JsError> {
        Ok(SurfBench {
            inner: ImageBench::new(bytes).map_err(js_err)?,
        })
    }

    /// Detect + describe once; returns the number of keypoints.
    pub fn run(&self) -> u32 {
        self.inner.run()
    }

    /// Stage 1 alone: builds (and keeps) the integral image.
    pub fn stage_integral(&mut self) -> u32 {
        self.inner.stage_integral()
    }

    /// Stage 2 alone: Fast-Hessian on the kept integral image.
    pub fn stage_detect(&mut self) -> u32 {
        self.inner.stage_detect()
    }

    /// Stage 3 alone: orientations of the kept keypoints.
    pub fn stage_orientation(&mut self) -> u32 {
        self.inner.stage_orientation()
    }

    /// Stage 4 alone: descriptors of the kept keypoints.
    pub fn stage_describe(&mut self) -> u32 {
        self.inner.stage_describe()
    }

    pub fn width(&self) -> u32 {
        self.inner.width()
    }

    pub fn height(&self) -> u32 {
        self.inner.height()
    }
}

/// Two images already described, so that a benchmark times matching +
/// MSAC alone: `run()` matches, fits and returns the inlier count.
#[wasm_bindgen]
pub struct SurfMatchBench {
    inner: MatchBench,
}

#[wasm_bindgen]
impl SurfMatchBench {
    /// Decodes and describes both PNG/JPEG images.
    #[wasm_bindgen(constructor)]
    pub fn new(bytes1: &[u8], bytes2: &[u8]) -> Result<SurfMatchBench, JsError> {
        Ok(SurfMatchBench {
            inner: MatchBench::new(bytes1, bytes2).map_err(js_err)?,
        })
    }

    /// Match + MSAC once; returns the number of inliers (0 without a model).
    pub fn run(&self) -> u32 {
        self.inner.run()
    }
}
