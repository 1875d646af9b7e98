//! # Reading a PNG map image
//!
//! PNG decoding is the `image` crate's (already the lab's codec). What is
//! ours is how a pixel of any colour type becomes one grey value, which is
//! `map_server`'s rule (`image_loader.cpp`): the mean of the channels, where
//! in `trinary` mode an alpha channel is averaged in with the colours (kept
//! that way in ROS "to preserve existing behaviour"), and in the other modes
//! it is left out of the mean and a fully transparent pixel is unknown.
//! 16-bit samples are scaled to 0..255 (`v / 257`).

use super::pgm::Grey;
use image::{DynamicImage, ImageDecoder};
use std::io::Cursor;

/// Whether `bytes` start with the PNG signature.
pub fn is_png(bytes: &[u8]) -> bool {
    bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a])
}

/// Width and height from the header, before decoding anything.
pub fn dimensions(bytes: &[u8]) -> Result<(usize, usize), String> {
    let d = image::codecs::png::PngDecoder::new(Cursor::new(bytes))
        .map_err(|e| format!("not a readable PNG ({e})"))?;
    let (w, h) = d.dimensions();
    Ok((w as usize, h as usize))
}

/// The grey values (0..255, top row first) and, when the image has alpha
/// and `alpha_in_mean` is false, which pixels are fully transparent.
pub fn decode(bytes: &[u8], alpha_in_mean: bool) -> Result<(Grey, Option<Vec<bool>>), String> {
    let decoder = image::codecs::png::PngDecoder::new(Cursor::new(bytes))
        .map_err(|e| format!("not a readable PNG ({e})"))?;
    let img =
        DynamicImage::from_decoder(decoder).map_err(|e| format!("PNG data is damaged ({e})"))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    if let DynamicImage::ImageLuma8(grey) = &img {
        // The common case, without a 16-bit copy of the image.
        let samples = grey.as_raw().iter().map(|&v| v as f32).collect();
        return Ok((
            Grey {
                width,
                height,
                samples,
            },
            None,
        ));
    }
    let has_alpha = img.color().has_alpha();
    let channels = img.color().channel_count() as usize;
    // Everything as 16-bit samples, then one rule for all colour types.
    let wide = img.into_rgba16();
    let colours = if channels >= 3 { 3 } else { 1 };
    let mut samples = Vec::with_capacity(width * height);
    let mut transparent = (has_alpha && !alpha_in_mean).then(|| Vec::with_capacity(width * height));
    for p in wide.pixels() {
        let c = p.0;
        let mut sum: f32 = c[..colours].iter().map(|&v| v as f32 / 257.0).sum();
        let mut count = colours as f32;
        let alpha = c[3] as f32 / 257.0;
        if has_alpha && alpha_in_mean {
            sum += alpha;
            count += 1.0;
        }
        samples.push(sum / count);
        if let Some(t) = transparent.as_mut() {
            t.push(c[3] == 0);
        }
    }
    Ok((
        Grey {
            width,
            height,
            samples,
        },
        transparent,
    ))
}
