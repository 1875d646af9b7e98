//! # The integral image (paper §2)
//!
//! SURF is fast because every filter it uses is a sum of upright boxes, and
//! the integral image turns any box sum into four look-ups, whatever the box
//! size (Viola and Jones 2001; Bay et al. 2008, §2 and Fig. 1):
//!
//! ```text
//!   I(X, Y) = Σ_{y < Y} Σ_{x < X} image(x, y)
//!   Σ box rows y0..y1, cols x0..x1 (inclusive)
//!        = I(x1+1, y1+1) - I(x1+1, y0) - I(x0, y1+1) + I(x0, y0)
//! ```
//!
//! We keep one leading row and column of zeros, so `I` is
//! `(width + 1) × (height + 1)` and no look-up needs a border test. The sums
//! are exact integers (`u32`). They may wrap around 2³² on very large bright
//! images, but a box sum is a difference of such values, and modular
//! arithmetic gives it exactly as long as the box itself sums to less than
//! 2³¹: a 195-pixel SURF filter on white pixels sums to about 10⁷.

use super::gray::GrayImage;
use super::simd;

/// The integral image of a [`GrayImage`], with a zero first row and column.
#[derive(Clone, Debug)]
pub struct IntegralImage {
    width: usize,
    height: usize,
    data: Vec<u32>,
}

impl IntegralImage {
    /// Builds the integral image (one pass, [`simd::integral_image`]).
    pub fn new(image: &GrayImage) -> Self {
        Self::from_pixels(image.pixels(), image.width(), image.height())
    }

    /// Builds the integral image of raw row-major grey pixels.
    ///
    /// # Panics
    /// If `pixels` holds fewer than `width * height` bytes.
    pub fn from_pixels(pixels: &[u8], width: usize, height: usize) -> Self {
        let len = (width + 1) * (height + 1) + simd::INTEGRAL_PAD;
        let mut data = vec![0u32; len];
        simd::integral_image(pixels, width, height, &mut data);
        IntegralImage {
            width,
            height,
            data,
        }
    }

    /// Width of the underlying image in pixels.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height of the underlying image in pixels.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Elements per row of [`data`](Self::data): `width + 1`.
    pub fn stride(&self) -> usize {
        self.width + 1
    }
    /// The flat table, `stride() * (height + 1)` values plus a few padding zeros.
    pub fn data(&self) -> &[u32] {
        &self.data
    }
    /// I(X, Y): the sum of pixels with x < X and y < Y (X ≤ width, Y ≤ height).
    pub fn at(&self, x: usize, y: usize) -> u32 {
        self.data[y * self.stride() + x]
    }

    /// Sum of the pixels in columns `x0..x1`, rows `y0..y1` (half-open),
    /// with the rectangle first clipped to the image: pixels outside count
    /// as zero. Used near the border, where wavelets stick out.
    pub fn box_sum_clipped(&self, x0: i64, y0: i64, x1: i64, y1: i64) -> i64 {
        let cx = |x: i64| x.clamp(0, self.width as i64) as usize;
        let cy = |y: i64| y.clamp(0, self.height as i64) as usize;
        let (x0, x1, y0, y1) = (cx(x0), cx(x1), cy(y0), cy(y1));
        if x1 <= x0 || y1 <= y0 {
            return 0;
        }
        let s = self
            .at(x1, y1)
            .wrapping_sub(self.at(x1, y0))
            .wrapping_sub(self.at(x0, y1))
            .wrapping_add(self.at(x0, y0));
        s as i64
    }

    /// Haar wavelet responses of side `2 * half` centred on the integral
    /// corner (cx, cy), clipped at the border: (right - left, bottom - top).
    pub fn haar_clipped(&self, cx: i64, cy: i64, half: i64) -> (f32, f32) {
        let (x0, x1, y0, y1) = (cx - half, cx + half, cy - half, cy + half);
        let dx = self.box_sum_clipped(cx, y0, x1, y1) - self.box_sum_clipped(x0, y0, cx, y1);
        let dy = self.box_sum_clipped(x0, cy, x1, y1) - self.box_sum_clipped(x0, y0, x1, cy);
        (dx as f32, dy as f32)
    }
}
