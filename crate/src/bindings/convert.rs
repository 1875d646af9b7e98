//! # The conversions every binding shares
//!
//! One error conversion, one JSON serialisation and one pixel copy, so each
//! `#[wasm_bindgen]` block (and any new one) converts the same way.

use wasm_bindgen::prelude::*;
use wasm_bindgen::Clamped;

/// Any error message as the `JsError` JavaScript receives (an exception
/// with that message).
pub(crate) fn js_err(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// A value as a JSON string (the form views cross the boundary in).
pub(crate) fn to_json<T: serde::Serialize>(v: &T) -> Result<String, JsError> {
    serde_json::to_string(v).map_err(js_err)
}

/// Copies straight RGBA pixels (`w × h × 4` bytes) into a canvas context
/// at (0, 0).
pub(crate) fn put_rgba(
    ctx: &web_sys::CanvasRenderingContext2d,
    rgba: &[u8],
    w: u32,
    h: u32,
) -> Result<(), JsError> {
    let img = web_sys::ImageData::new_with_u8_clamped_array_and_sh(Clamped(rgba), w, h)
        .map_err(|_| JsError::new("could not make ImageData"))?;
    ctx.put_image_data(&img, 0.0, 0.0)
        .map_err(|_| JsError::new("could not draw into the canvas"))
}
