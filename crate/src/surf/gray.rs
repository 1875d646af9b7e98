//! # The grey image SURF reads
//!
//! SURF works on intensities only (paper §2: the integral image is built
//! from the grey values). Colour photographs are reduced to 8-bit luma with
//! the `image` crate's Rec. 709 weights. Decoding happens here, in Rust, so
//! that the browser, node and the tests all see the same pixels; the size
//! limits below keep a hostile or broken file from exhausting memory.

use std::fmt;
use std::io::Cursor;

/// Largest accepted side, in pixels.
pub const MAX_SIDE: u32 = 8192;
/// Largest accepted pixel count (16 Mpx, about 4096 × 4096).
pub const MAX_PIXELS: u64 = 1 << 24;
/// Largest accepted encoded file, in bytes.
pub const MAX_ENCODED_BYTES: usize = 64 << 20;

/// Why an image could not be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SurfError {
    /// No bytes at all.
    Empty,
    /// The bytes are not a PNG or JPEG the decoder understands.
    NotAnImage(String),
    /// Width or height zero, or the buffer does not hold width × height bytes.
    BadDimensions { width: u32, height: u32, len: usize },
    /// Larger than [`MAX_SIDE`] / [`MAX_PIXELS`] / [`MAX_ENCODED_BYTES`].
    TooLarge { width: u64, height: u64 },
}

impl fmt::Display for SurfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SurfError::Empty => write!(f, "image is empty (0 bytes)"),
            SurfError::NotAnImage(why) => write!(f, "not a PNG or JPEG image: {why}"),
            SurfError::BadDimensions { width, height, len } => write!(
                f,
                "bad image dimensions {width} x {height} for a buffer of {len} bytes"
            ),
            SurfError::TooLarge { width: 0, height: 0 } => write!(
                f,
                "image is too large (a file over {} MiB, or more pixels than the decoder may allocate)",
                MAX_ENCODED_BYTES >> 20
            ),
            SurfError::TooLarge { width, height } => write!(
                f,
                "image {width} x {height} is too large (at most {MAX_SIDE} pixels a side and {MAX_PIXELS} pixels)"
            ),
        }
    }
}

impl std::error::Error for SurfError {}

/// Decoder errors: a limit hit (the header announced more than we accept,
/// or more than this platform can address) is `TooLarge`, the rest
/// `NotAnImage`.
fn decode_error(e: image::ImageError) -> SurfError {
    match e {
        image::ImageError::Limits(_) => SurfError::TooLarge {
            width: 0,
            height: 0,
        },
        other => SurfError::NotAnImage(other.to_string()),
    }
}

/// An 8-bit grey image, row-major, top row first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GrayImage {
    width: usize,
    height: usize,
    pixels: Vec<u8>,
}

impl GrayImage {
    /// Wraps `pixels` (row-major, `width * height` bytes).
    ///
    /// Fails when a side is zero, the length does not match, or the image is
    /// larger than [`MAX_SIDE`] / [`MAX_PIXELS`].
    pub fn new(width: usize, height: usize, pixels: Vec<u8>) -> Result<Self, SurfError> {
        if width as u64 > MAX_SIDE as u64
            || height as u64 > MAX_SIDE as u64
            || (width as u64) * (height as u64) > MAX_PIXELS
        {
            return Err(SurfError::TooLarge {
                width: width as u64,
                height: height as u64,
            });
        }
        if width == 0 || height == 0 || pixels.len() != width * height {
            return Err(SurfError::BadDimensions {
                width: width as u32,
                height: height as u32,
                len: pixels.len(),
            });
        }
        Ok(GrayImage {
            width,
            height,
            pixels,
        })
    }

    /// Decodes a PNG or JPEG (grey or colour) and converts it to luma.
    pub fn decode(bytes: &[u8]) -> Result<Self, SurfError> {
        if bytes.is_empty() {
            return Err(SurfError::Empty);
        }
        if bytes.len() > MAX_ENCODED_BYTES {
            return Err(SurfError::TooLarge {
                width: 0,
                height: 0,
            });
        }
        let reader = image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| SurfError::NotAnImage(e.to_string()))?;
        if reader.format().is_none() {
            return Err(SurfError::NotAnImage("unrecognised file signature".into()));
        }
        let (w, h) = reader.into_dimensions().map_err(decode_error)?;
        if w > MAX_SIDE || h > MAX_SIDE || (w as u64) * (h as u64) > MAX_PIXELS {
            return Err(SurfError::TooLarge {
                width: w as u64,
                height: h as u64,
            });
        }
        let mut reader = image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| SurfError::NotAnImage(e.to_string()))?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        limits.max_alloc = Some(MAX_PIXELS * 8 + (64 << 20));
        reader.limits(limits);
        let decoded = reader
            .decode()
            .map_err(|e| SurfError::NotAnImage(e.to_string()))?;
        let luma = decoded.to_luma8();
        let (w, h) = luma.dimensions();
        GrayImage::new(w as usize, h as usize, luma.into_raw())
    }

    /// Converts straight RGBA (canvas `ImageData`) to luma with the same
    /// Rec. 709 weights as [`GrayImage::decode`]; alpha is ignored.
    pub fn from_rgba(width: usize, height: usize, rgba: &[u8]) -> Result<Self, SurfError> {
        if width.checked_mul(height).and_then(|n| n.checked_mul(4)) != Some(rgba.len()) {
            return Err(SurfError::BadDimensions {
                width: width as u32,
                height: height as u32,
                len: rgba.len(),
            });
        }
        let pixels = rgba
            .chunks_exact(4)
            .map(|p| {
                let l = 2126 * p[0] as u32 + 7152 * p[1] as u32 + 722 * p[2] as u32;
                ((l + 5000) / 10000) as u8
            })
            .collect();
        GrayImage::new(width, height, pixels)
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    /// Row-major pixels, `width * height` bytes.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }
    /// Pixel at column `x`, row `y` (panics when outside, like slice indexing).
    pub fn get(&self, x: usize, y: usize) -> u8 {
        self.pixels[y * self.width + x]
    }
}
