//! # Reading a PGM image (Netpbm "portable graymap")
//!
//! `map_server` maps are most often PGM files: a short text header and the
//! grey values (<https://netpbm.sourceforge.net/doc/pgm.html>):
//!
//! ```text
//! P5            magic: P5 binary raster, P2 plain (decimal text) raster
//! # comment     lines from '#' to the end are comments, anywhere in the header
//! 1243 1215     width height
//! 255           maxval: 1..65535; above 255 each binary sample is 2 bytes, big-endian
//! <raster>      after exactly one whitespace byte: height rows of width samples, top row first
//! ```
//!
//! This reader hands back the samples scaled to 0..255 (`v · 255 / maxval`,
//! so a 16-bit map reads the same as its 8-bit twin), top row first, and
//! refuses a file whose header lies about its size before allocating
//! anything for it.

/// A grey image: `width × height` samples scaled to 0..255, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    pub width: usize,
    pub height: usize,
    pub samples: Vec<f32>,
}

/// The header of a PGM: magic, width, height, maxval, and where the
/// raster starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PgmHeader {
    pub binary: bool,
    pub width: usize,
    pub height: usize,
    pub maxval: u32,
    pub raster_at: usize,
}

/// Skips whitespace and comments; returns the next token's bounds.
fn token(bytes: &[u8], mut at: usize) -> Option<(usize, usize)> {
    loop {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if at < bytes.len() && bytes[at] == b'#' {
            while at < bytes.len() && bytes[at] != b'\n' && bytes[at] != b'\r' {
                at += 1;
            }
            continue;
        }
        break;
    }
    let start = at;
    while at < bytes.len() && !bytes[at].is_ascii_whitespace() && bytes[at] != b'#' {
        at += 1;
    }
    (at > start).then_some((start, at))
}

fn header_number(bytes: &[u8], at: usize, what: &str) -> Result<(u64, usize), String> {
    let (s, e) = token(bytes, at).ok_or_else(|| format!("PGM header ends before its {what}"))?;
    let text = std::str::from_utf8(&bytes[s..e]).unwrap_or("?");
    let v = text
        .parse::<u64>()
        .map_err(|_| format!("PGM header: {what} '{text}' is not a whole number"))?;
    Ok((v, e))
}

/// Whether `bytes` start like a PGM file.
pub fn is_pgm(bytes: &[u8]) -> bool {
    bytes.len() >= 2 && bytes[0] == b'P' && (bytes[1] == b'5' || bytes[1] == b'2')
}

/// Reads the header (errors are messages for the `image` field).
pub fn read_header(bytes: &[u8]) -> Result<PgmHeader, String> {
    if !is_pgm(bytes) {
        return Err("not a PGM file (no P5 or P2 magic)".into());
    }
    let binary = bytes[1] == b'5';
    let (width, at) = header_number(bytes, 2, "width")?;
    let (height, at) = header_number(bytes, at, "height")?;
    let (maxval, at) = header_number(bytes, at, "maxval")?;
    if width == 0 || height == 0 {
        return Err(format!("PGM image is {width} x {height} pixels (empty)"));
    }
    if maxval == 0 || maxval > 65535 {
        return Err(format!("PGM maxval {maxval} is not in 1..65535"));
    }
    // Exactly one whitespace byte separates the header from a binary raster.
    if at >= bytes.len() || !bytes[at].is_ascii_whitespace() {
        return Err("PGM header is not followed by the raster".into());
    }
    let too_big = |v: u64| usize::try_from(v).map_err(|_| "PGM image is too large".to_string());
    Ok(PgmHeader {
        binary,
        width: too_big(width)?,
        height: too_big(height)?,
        maxval: maxval as u32,
        raster_at: at + 1,
    })
}

/// Reads the raster of a PGM whose header is `h` (size already checked
/// by the caller against its limit).
pub fn read_raster(bytes: &[u8], h: &PgmHeader) -> Result<Grey, String> {
    let n = h.width * h.height;
    let scale = 255.0 / h.maxval as f32;
    let mut samples = Vec::with_capacity(n);
    if h.binary {
        let wide = h.maxval > 255;
        let need = n * if wide { 2 } else { 1 };
        let raster = &bytes[h.raster_at.min(bytes.len())..];
        if raster.len() < need {
            return Err(format!(
                "PGM raster is cut short: {} bytes for {} x {} pixels, {need} expected",
                raster.len(),
                h.width,
                h.height
            ));
        }
        if wide {
            samples.extend(
                raster[..need]
                    .chunks_exact(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]).min(h.maxval as u16) as f32 * scale),
            );
        } else {
            samples.extend(
                raster[..n]
                    .iter()
                    .map(|&b| (b as u32).min(h.maxval) as f32 * scale),
            );
        }
    } else {
        let mut at = h.raster_at - 1;
        for k in 0..n {
            let (s, e) = token(bytes, at)
                .ok_or_else(|| format!("plain PGM raster ends after {k} of {n} samples"))?;
            let text = std::str::from_utf8(&bytes[s..e]).unwrap_or("?");
            let v: u32 = text
                .parse()
                .map_err(|_| format!("plain PGM sample {k} '{text}' is not a whole number"))?;
            samples.push(v.min(h.maxval) as f32 * scale);
            at = e;
        }
    }
    Ok(Grey {
        width: h.width,
        height: h.height,
        samples,
    })
}
