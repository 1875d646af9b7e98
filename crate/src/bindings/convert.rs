//! # The conversions every binding shares
//!
//! One error conversion, one JSON serialisation and one pixel copy, so each
//! `#[wasm_bindgen]` block (and any new one) converts the same way.

use wasm_bindgen::prelude::*;
use wasm_bindgen::Clamped;
use wasm_bindgen::JsCast;

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

/// The message of a thrown JavaScript value (an `Error`'s message, a
/// string as it is, anything else as JavaScript would print it).
pub(crate) fn message_of(thrown: &JsValue) -> String {
    if let Some(e) = thrown.dyn_ref::<js_sys::Error>() {
        return String::from(e.message());
    }
    thrown.as_string().unwrap_or_else(|| format!("{thrown:?}"))
}

/// Bytes written to a JavaScript function in chunks of [`Self::CHUNK`]
/// bytes (each a fresh `Uint8Array`), so that a large document (a run
/// report of tens of megabytes) is never held whole in wasm memory, whose
/// linear memory only ever grows.
pub(crate) struct ChunkSink<'a> {
    write: &'a js_sys::Function,
    buf: Vec<u8>,
    /// What the function threw, if it did.
    pub(crate) thrown: Option<JsValue>,
}

impl<'a> ChunkSink<'a> {
    const CHUNK: usize = 1 << 20;

    pub(crate) fn new(write: &'a js_sys::Function) -> ChunkSink<'a> {
        ChunkSink {
            write,
            buf: Vec::with_capacity(Self::CHUNK),
            thrown: None,
        }
    }

    fn send(&mut self) -> std::io::Result<()> {
        if self.buf.is_empty() {
            return Ok(());
        }
        let chunk = js_sys::Uint8Array::from(&self.buf[..]);
        self.buf.clear();
        self.write
            .call1(&JsValue::NULL, &chunk)
            .map(|_| ())
            .map_err(|e| {
                self.thrown = Some(e);
                std::io::Error::other("the write function threw")
            })
    }
}

impl std::io::Write for ChunkSink<'_> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let mut rest = bytes;
        while !rest.is_empty() {
            let take = rest.len().min(Self::CHUNK - self.buf.len());
            self.buf.extend_from_slice(&rest[..take]);
            rest = &rest[take..];
            if self.buf.len() == Self::CHUNK {
                self.send()?;
            }
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.send()
    }
}
